/**
 * How the head looks: physical materials for skin, lips, eyes, teeth, tongue and the inside of the mouth, the
 * skin's colours, and soft studio light: an environment map generated in code (three.js's RoomEnvironment through
 * PMREM: no download) plus a warm key, a cool fill and a rim light.
 */
import * as THREE from 'three';
import { RoomEnvironment } from 'three/addons/environments/RoomEnvironment.js';
import { lipMask, type FaceTemplate } from '../template/face-template';
import { eyeTexture } from './eyes';

export const BACKGROUND = 0x1d2230;
export const SKIN = new THREE.Color(0xc4927a);
const CHEEK = new THREE.Color(0xc9766a);
const LIP = new THREE.Color(0xa4504f);
const HAIR = new THREE.Color(0x2b1d16);

export function skinMaterial(): THREE.MeshPhysicalMaterial {
  // Sheen stands in for light scattered under the skin: a warm glow at grazing angles.
  return new THREE.MeshPhysicalMaterial({
    name: 'skin', vertexColors: true, roughness: 0.58, metalness: 0, sheen: 0.35, sheenRoughness: 0.75,
    sheenColor: new THREE.Color(0xff9a80), clearcoat: 0.06, clearcoatRoughness: 0.45, side: THREE.DoubleSide,
  });
}

/** The inside of the mouth: dark, wet and reddish; seen from inside (its back faces). */
export function cavityMaterial(): THREE.MeshPhysicalMaterial {
  return new THREE.MeshPhysicalMaterial({ name: 'mouth', color: 0x2e0e12, roughness: 0.8, side: THREE.DoubleSide, envMapIntensity: 0.1 });
}

export function teethMaterial(): THREE.MeshPhysicalMaterial {
  return new THREE.MeshPhysicalMaterial({ name: 'teeth', color: 0xeee6d6, roughness: 0.32, clearcoat: 0.5, clearcoatRoughness: 0.2, sheen: 0.2, sheenColor: new THREE.Color(0xfff4e0) });
}

export function tongueMaterial(): THREE.MeshPhysicalMaterial {
  return new THREE.MeshPhysicalMaterial({ name: 'tongue', color: 0xb4565a, roughness: 0.45, clearcoat: 0.3, clearcoatRoughness: 0.3, sheen: 0.4, sheenColor: new THREE.Color(0xff8080) });
}

export function clothMaterial(): THREE.MeshPhysicalMaterial {
  return new THREE.MeshPhysicalMaterial({ name: 'cloth', color: 0x37475e, roughness: 0.85, sheen: 0.6, sheenRoughness: 0.6, sheenColor: new THREE.Color(0x8898b8) });
}

export function eyeMaterials(): { sclera: THREE.MeshPhysicalMaterial; cornea: THREE.MeshPhysicalMaterial } {
  return {
    sclera: new THREE.MeshPhysicalMaterial({ name: 'sclera', map: eyeTexture(), roughness: 0.35, clearcoat: 0.6, clearcoatRoughness: 0.1 }),
    // Only the cornea's reflections are added: a black, glossy, additive shell shows highlights and nothing else.
    cornea: new THREE.MeshPhysicalMaterial({
      name: 'cornea', color: 0x000000, roughness: 0.04, metalness: 0, ior: 1.376, specularIntensity: 1, envMapIntensity: 2.5,
      transparent: true, blending: THREE.AdditiveBlending, depthWrite: false,
    }),
  };
}

/**
 * Per-vertex colours of the joined face + shell buffer: skin with warmer cheeks, lips, and hair on the shell's
 * crown and back (shell vertices above the brows, lower at the back of the head).
 */
export function headColors(t: FaceTemplate, shell: Float32Array | null, egg: { center: number[]; up: number; back: number } | null): Float32Array {
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
      const h = Math.min(1, Math.max(0, (y - line) / (0.15 * egg.up)));
      c.copy(SKIN).lerp(HAIR, h).toArray(colors, 3 * (n + i));
    }
  }
  return colors;
}

/** Soft light around a head: the generated environment, a warm key from above right, cool fill and rim. */
export function lightScene(scene: THREE.Scene, renderer: THREE.WebGLRenderer): void {
  const pmrem = new THREE.PMREMGenerator(renderer);
  const room = new RoomEnvironment();
  scene.environment = pmrem.fromScene(room, 0.04).texture;
  scene.environmentIntensity = 0.35;
  room.dispose();
  pmrem.dispose();
  scene.background = new THREE.Color(BACKGROUND);
  scene.add(new THREE.HemisphereLight(0xfff1e6, 0x3a3036, 0.35));
  const key = new THREE.DirectionalLight(0xfff0e0, 2.4);
  key.position.set(0.7, 0.9, 1.4);
  const fill = new THREE.DirectionalLight(0xc8d8ff, 0.5);
  fill.position.set(-1.2, 0.1, 0.9);
  const rim = new THREE.DirectionalLight(0xaec4ff, 1.1);
  rim.position.set(-0.6, 0.7, -1.2);
  scene.add(key, fill, rim);
  renderer.toneMapping = THREE.NeutralToneMapping;
  renderer.toneMappingExposure = 0.95;
}

/** A blue -> cyan -> green -> yellow -> red ramp at t in [0, 1], written to out[at..at+3) (painted maps). */
export function heat(t: number, out: Float32Array, at: number): void {
  const stops = [[0.12, 0.16, 0.45], [0.1, 0.65, 0.85], [0.25, 0.8, 0.3], [0.95, 0.85, 0.2], [0.85, 0.15, 0.12]];
  const x = t * (stops.length - 1);
  const k = Math.min(stops.length - 2, Math.floor(x));
  const f = x - k;
  for (let i = 0; i < 3; i++) out[at + i] = stops[k][i] * (1 - f) + stops[k + 1][i] * f;
}
