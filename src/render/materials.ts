/**
 * How the head looks: physical materials for skin, lips, eyes, teeth, tongue and the inside of the mouth, the
 * skin's colours, and soft studio light: an environment map generated in code (environment.ts: a studio prefiltered
 * on the CPU, no download, no shader to compile) plus a warm key, a cool fill and a rim light.
 *
 * Cost: the environment map is sampled only by the small wet surfaces that show its reflections (eyes, teeth,
 * tongue); the skin, which covers most pixels, takes its soft light from a hemisphere light instead, is drawn from
 * the front only (the head is closed), and has no sheen or clearcoat layer: together they made a frame about three
 * times slower to shade (SwiftShader, npm run bench) for a difference hard to see at this size. The physical
 * material's extras (a clear coat with the cornea's index of refraction) are kept for the eyes; the other surfaces use three.js's
 * standard physically based material, whose fewer uniforms cost less main-thread time per draw.
 */
import * as THREE from 'three';
import { studioEnvironment } from './environment';
import { lipMask, type FaceTemplate } from '../template/face-template';
import type { EarPlace } from './ears';

export const BACKGROUND = 0x1d2230;
export const SKIN = new THREE.Color(0xcc9c84);
const CHEEK = new THREE.Color(0xc9766a);
const LIP = new THREE.Color(0xa65b57);
const HAIR = new THREE.Color(0x2b1d16);

export function skinMaterial(): THREE.MeshStandardMaterial {
  // A little specular (oily skin) and a warm emissive floor for light scattered under the skin.
  const skin = new THREE.MeshStandardMaterial({
    name: 'skin', vertexColors: true, roughness: 0.6, metalness: 0, emissive: 0x1c0804,
  });
  skin.onBeforeCompile = mattHair;
  return skin;
}

/**
 * Hair (the darkest vertex colours) is matt: with the skin's sheen the rim light made a pale patch on the crown. The
 * cloth has it too (its vertex colours are white, so nothing changes there) to share the skin's shader program.
 */
function mattHair(shader: { fragmentShader: string }): void {
  shader.fragmentShader = shader.fragmentShader.replace('#include <roughnessmap_fragment>',
    '#include <roughnessmap_fragment>\n\troughnessFactor = mix(0.95, roughnessFactor, smoothstep(0.03, 0.09, dot(vColor.rgb, vec3(1.0 / 3.0))));');
}

/** Give the materials under `root` that reflect (eyes, teeth, tongue) the environment map. */
function reflectEnvironment(root: THREE.Object3D, environment: THREE.Texture): void {
  root.traverse((o) => {
    if (!(o as THREE.Mesh).isMesh) return;
    for (const m of ([] as THREE.Material[]).concat((o as THREE.Mesh).material)) {
      if (m instanceof THREE.MeshStandardMaterial && REFLECTIVE.has(m.name)) {
        m.envMap = environment;
        m.needsUpdate = true;
      }
    }
  });
}
const REFLECTIVE = new Set(['eye', 'teeth', 'tongue']);

/**
 * The inside of the mouth: dark, wet and reddish; seen from inside (its back faces). Its own shader program (drawn
 * from both sides): its rim is the face's own lip vertices, whose normals turning the cavity inwards would change.
 */
export function cavityMaterial(): THREE.MeshStandardMaterial {
  return new THREE.MeshStandardMaterial({ name: 'mouth', color: 0x2e0e12, roughness: 0.8, side: THREE.DoubleSide });
}

/**
 * The skirts behind the eye openings (eyes.ts): moist pink flesh, as the inner corner's caruncle is, where the lids
 * leave a gap beside the ball. The cavity's settings but its colour, so three.js draws it with the same program.
 */
export function eyeCornerMaterial(): THREE.MeshStandardMaterial {
  return new THREE.MeshStandardMaterial({ name: 'eye_corner', color: 0xb88078, emissive: 0x6a3c38, roughness: 0.8, side: THREE.DoubleSide });
}

export function teethMaterial(): THREE.MeshStandardMaterial {
  return new THREE.MeshStandardMaterial({ name: 'teeth', color: 0xeee6d6, roughness: 0.3, envMapIntensity: 0.5 });
}

export function tongueMaterial(): THREE.MeshStandardMaterial {
  return new THREE.MeshStandardMaterial({ name: 'tongue', color: 0xa8484e, roughness: 0.6, envMapIntensity: 0.12 });
}

export function clothMaterial(): THREE.MeshStandardMaterial {
  // White vertex colours (head.ts), read like the skin's, and the skin's shader change: three.js then draws the cloth
  // with the skin's shader program, and the first draw links one program fewer (under a software GPU each costs tens of ms; issue 18).
  return Object.assign(new THREE.MeshStandardMaterial({ name: 'cloth', color: 0x37475e, roughness: 0.85, vertexColors: true }), { onBeforeCompile: mattHair });
}

/**
 * The eyeball: the painted sclera, iris and pupil under a clear coat with the cornea's index of refraction, which
 * catches the key light and the environment as the cornea's highlight (one draw per eye, not a second transparent
 * cornea mesh: at this size the highlight is what shows of the cornea).
 */
export function eyeMaterial(): THREE.MeshPhysicalMaterial {
  return new THREE.MeshPhysicalMaterial({
    name: 'eye', map: eyeTexture(), roughness: 0.4, envMapIntensity: 0.6, clearcoat: 1, clearcoatRoughness: 0.03, ior: 1.376,
  });
}

/**
 * Per-vertex colours of the joined face + shell buffer: skin with warmer cheeks, lips, and hair on the shell's
 * crown and back (shell vertices above the brows, lower at the back of the head).
 */
export function headColors(t: FaceTemplate, shell: Float32Array | null, egg: { center: number[]; ax: number; up: number; back: number } | null,
  ear: EarPlace | null = null): Float32Array {
  const n = t.vertexCount;
  const s = shell ? shell.length / 3 : 0;
  const colors = new Float32Array((n + s) * 3);
  const isLip = lipMask(t);
  const p = t.positions;
  const nose = t.regions.nose_tip?.[0] ?? 0;
  const noseY = p[3 * nose + 1], noseZ = p[3 * nose + 2];
  const c = new THREE.Color();
  // Cheeks: redder where the face is wide and at about the nose's height.
  const xs = Array.from(t.regions.face_boundary, (v) => Math.abs(p[3 * v]));
  const half = Math.max(...xs);
  for (let v = 0; v < n; v++) {
    const x = Math.abs(p[3 * v]) / half, y = p[3 * v + 1], z = p[3 * v + 2];
    const cheek = Math.exp(-(((x - 0.55) / 0.2) ** 2) - ((y - noseY) / (0.25 * half)) ** 2);
    c.copy(SKIN).lerp(CHEEK, 0.6 * cheek * (z < noseZ ? 1 : 0));
    (isLip[v] ? LIP : c).toArray(colors, 3 * v);
  }
  if (shell && egg) {
    for (let i = 0; i < s; i++) {
      const y = shell[3 * i + 1] - egg.center[1], z = shell[3 * i + 2] - egg.center[2];
      // The hairline: at the face's top in front, above the ears at the sides, down to the nape at the back.
      const back = Math.min(1, Math.max(0, -z / egg.back));
      const line = z > 0 ? egg.up * (0.1 + 0.4 * Math.min(1, z / (0.4 * egg.back))) : egg.up * (0.1 - 1.0 * back * back);
      // A transition two or three of the shell's rings wide, eased: a sharper one shows their triangles as a sawtooth.
      const f = Math.min(1, Math.max(0, (y - line) / (0.3 * egg.up) + 0.25));
      // Skin round each ear (a margin of about a third of its size), as hair grows above and behind it, not up to it.
      const e = ear && Math.abs(shell[3 * i] - egg.center[0]) > 0.5 * egg.ax
        ? Math.hypot((shell[3 * i + 1] - ear.y) / ear.height, (shell[3 * i + 2] - ear.z) / ear.width) : Infinity;
      const bare = Math.min(1, Math.max(0, (0.85 - e) / 0.3));
      const h = f * f * (3 - 2 * f) * (1 - bare * bare * (3 - 2 * bare));
      c.copy(SKIN).lerp(HAIR, h).toArray(colors, 3 * (n + i));
    }
  }
  return colors;
}

/**
 * Soft light around the head already in `scene`: the generated environment (for the reflecting materials), a warm
 * key from above right, a hemisphere's soft fill, cool fill and rim. Returns the environment texture (the caller
 * disposes of it with the renderer it was made by).
 */
export function lightScene(scene: THREE.Scene, renderer: THREE.WebGLRenderer): THREE.Texture {
  const environment = studioEnvironment();
  reflectEnvironment(scene, environment);
  scene.background = new THREE.Color(BACKGROUND);
  scene.add(new THREE.HemisphereLight(0xfff1e6, 0x4a3a3a, 0.9));
  const key = new THREE.DirectionalLight(0xfff0e0, 2.4);
  key.position.set(0.7, 0.9, 1.4);
  const fill = new THREE.DirectionalLight(0xc8d8ff, 0.5);
  fill.position.set(-1.2, 0.1, 0.9);
  const rim = new THREE.DirectionalLight(0xd8e2ff, 0.8);
  rim.position.set(-0.6, 0.7, -1.2);
  scene.add(key, fill, rim);
  renderer.toneMapping = THREE.NeutralToneMapping;
  renderer.toneMappingExposure = 0.95;
  return environment;
}

/** A blue -> cyan -> green -> yellow -> red ramp at t in [0, 1], written to out[at..at+3) (painted maps). */
export function heat(t: number, out: Float32Array, at: number): void {
  const stops = [[0.12, 0.16, 0.45], [0.1, 0.65, 0.85], [0.25, 0.8, 0.3], [0.95, 0.85, 0.2], [0.85, 0.15, 0.12]];
  const x = t * (stops.length - 1);
  const k = Math.min(stops.length - 2, Math.floor(x));
  const f = x - k;
  for (let i = 0; i < 3; i++) out[at + i] = stops[k][i] * (1 - f) + stops[k + 1][i] * f;
}

/**
 * The eye's texture: the sphere's pole (top row) is the pupil's centre, rows go back over the ball by polar angle.
 * Pupil, a radially streaked iris darkening to its limbus, and the sclera, faintly pink towards the back.
 */
/** Polar angles (degrees from the pupil's centre) of the pupil's and the iris's edges: an 11.7 mm iris on a 12 mm ball. */
const PUPIL_EDGE = 11, IRIS_EDGE = 29.2;

export function eyeTexture(): THREE.Texture {
  const w = 256, h = 128;
  const canvas = typeof document !== 'undefined' ? Object.assign(document.createElement('canvas'), { width: w, height: h }) : new OffscreenCanvas(w, h);
  const ctx = canvas.getContext('2d') as CanvasRenderingContext2D;
  const image = ctx.createImageData(w, h);
  const deg = (row: number) => ((row + 0.5) / h) * 180; // polar angle from the pupil's centre
  for (let y = 0; y < h; y++) {
    const a = deg(y);
    for (let x = 0; x < w; x++) {
      const streak = 0.5 + 0.5 * Math.sin(x * 0.9) * Math.sin(x * 0.37 + 1.3);
      let c: number[];
      if (a < PUPIL_EDGE) c = [8, 6, 6];
      else if (a < IRIS_EDGE) {
        const t = (a - PUPIL_EDGE) / (IRIS_EDGE - PUPIL_EDGE);
        const base = [70 + 48 * t, 52 + 40 * t, 34 + 20 * t]; // brown, lighter outwards
        c = base.map((v) => v * (0.7 + 0.5 * streak) * (a > IRIS_EDGE - 3.5 ? 0.55 : 1)); // the limbus
      } else {
        const t = Math.min(1, (a - IRIS_EDGE) / 70);
        c = [236 - 8 * t, 232 - 28 * t, 226 - 34 * t];
      }
      const i = 4 * (y * w + x);
      image.data.set([c[0], c[1], c[2], 255], i);
    }
  }
  ctx.putImageData(image, 0, 0);
  const texture = new THREE.CanvasTexture(canvas as HTMLCanvasElement);
  texture.colorSpace = THREE.SRGBColorSpace;
  texture.anisotropy = 4;
  return texture;
}
