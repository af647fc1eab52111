/**
 * The whole head as three.js objects, built from a face template: one skin mesh whose vertex buffer is the face's
 * N vertices (what the model animates), then the head shell's (head-shell.ts), then the mouth cavity's
 * (mouth-interior.ts), then the skirts behind the eye openings (eyes.ts), drawn with three materials (skin; the
 * inside of the mouth; the eyes' inner corners); the neck; the eyes (eyes.ts) in dark sockets (the mouth's material);
 * upper teeth fixed to the skull; lower teeth and tongue on the jaw (jaw.ts). `group` is what the head pose moves.
 *
 * `setFace(face, tongue)` poses everything that follows the face for one frame of it: the skin is kept outside the
 * eyeballs (eyes.ts), the jaw's angle is estimated from the face, the shell under the chin and the floor of the
 * mouth follow it, normals are recomputed across face, shell and cavity together. The view calls it each frame; the .glb export once per exported frame.
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';
import { headShell, faceMeasures, ovalLoop, type HeadShell, type FaceMeasures } from './head-shell';
import { JawEstimator, jawHinge, turnAboutHinge, type Hinge } from './jaw';
import { mouthBag, mouthFrame, teethGeometry, tongueGeometry, updateBag, type MouthBag } from './mouth-interior';
import { Eyes, eyeSkirts, updateSkirts, type EyeSkirts } from './eyes';
import { earGeometries, earPlace } from './ears';
import { PartialNormals } from './normals';
import { SKIN, cavityMaterial, clothMaterial, eyeCornerMaterial, headColors, skinMaterial, teethMaterial, tongueMaterial } from './materials';

const scratch = [0, 0];
/** An eye socket's radius against its ball's, and how far round the ball it reaches from the back (radians). */
const SOCKET = 1.12;
const SOCKET_SPAN = 0.76 * Math.PI;

export class Head {
  /** Moves with the head pose. */
  readonly group = new THREE.Group();
  /** Face + shell + mouth cavity in one buffer (named 'face': the face's vertices come first). */
  readonly skin: THREE.Mesh<THREE.BufferGeometry, THREE.Material[]>;
  readonly eyes: Eyes;
  /** Turns about the jaw's hinge: lower teeth and tongue. */
  readonly jaw = new THREE.Group();
  readonly tongue: THREE.Mesh<THREE.BufferGeometry, THREE.Material>;
  /** Shoulders: below the head, not moved by its pose (the view lets them breathe). */
  readonly body: THREE.Mesh;
  readonly shell: HeadShell | null;
  readonly bag: MouthBag | null;
  readonly hinge: Hinge;
  /** The face's measures (head-shell.ts): what the neck, shoulders and camera are sized from. */
  readonly measures: FaceMeasures;
  /** Skin colours of the joined buffer (face, shell; the cavity's are unused). */
  readonly colors: Float32Array;
  /** The jaw's opening at the last setFace (radians; 0 = the template's). */
  jawAngle = 0;
  private readonly estimator: JawEstimator;
  private readonly positions: THREE.BufferAttribute;
  private readonly normals: THREE.BufferAttribute;
  private readonly partialNormals: PartialNormals;
  private readonly n: number;
  /** Behind the eye openings, after the mouth's cavity in the joined buffer. */
  private readonly skirts: EyeSkirts | null;

  constructor(readonly template: FaceTemplate) {
    const t = template;
    this.n = t.vertexCount;
    this.shell = headShell(t);
    const m = this.shell?.measures ?? faceMeasures(t, ovalLoop(t) ?? Array.from(t.regions.face_boundary));
    this.measures = m;
    const S = this.shell ? this.shell.positions.length / 3 : 0;
    this.bag = mouthBag(t, this.n + S);
    const B = this.bag ? this.bag.rest.length / 3 : 0;
    this.eyes = new Eyes(t);
    this.skirts = eyeSkirts(t, this.eyes.centers, this.eyes.radii, this.n + S + B);
    const E = this.skirts ? this.skirts.rest.length / 3 : 0;
    this.hinge = jawHinge(t, m);
    this.estimator = new JawEstimator(t, m, this.hinge);

    const all = new Float32Array((this.n + S + B + E) * 3);
    all.set(t.positions);
    if (this.shell) all.set(this.shell.positions, this.n * 3);
    if (this.bag) all.set(this.bag.rest, (this.n + S) * 3);
    if (this.skirts) all.set(this.skirts.rest, (this.n + S + B) * 3);
    const geometry = new THREE.BufferGeometry();
    this.positions = new THREE.BufferAttribute(all, 3);
    this.positions.setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute('position', this.positions);
    this.colors = new Float32Array(all.length);
    this.colors.set(headColors(t, this.shell?.positions ?? null, this.shell?.egg ?? null, this.shell ? earPlace(m, this.shell.egg) : null));
    this.colors.fill(1, (this.n + S) * 3); // the cavity and the skirts: white, so a .glb viewer shows their materials' colours
    geometry.setAttribute('color', new THREE.BufferAttribute(this.colors.slice(), 3));
    const skinTris = this.shell ? [...t.triangles, ...this.shell.triangles] : [...t.triangles];
    const bagTris = this.bag ? [...this.bag.triangles] : [];
    const skirtTris = this.skirts ? [...this.skirts.triangles] : [];
    geometry.setIndex([...skinTris, ...bagTris, ...skirtTris]);
    geometry.addGroup(0, skinTris.length, 0);
    if (bagTris.length) geometry.addGroup(skinTris.length, bagTris.length, 1);
    if (skirtTris.length) geometry.addGroup(skinTris.length + bagTris.length, skirtTris.length, 2);
    // What moves per frame: the face, the shell where it turns with the jaw, the mouth's cavity, the eyes' skirts.
    const jawW = this.shell?.jawWeights;
    const moving = (v: number) => v < this.n || v >= this.n + S || (jawW !== undefined && jawW[v - this.n] > 0);
    this.partialNormals = new PartialNormals(geometry.getIndex()!.array, all, moving);
    this.normals = new THREE.BufferAttribute(new Float32Array(all.length), 3);
    this.partialNormals.init(all, this.normals.array as Float32Array);
    geometry.setAttribute('normal', this.normals);
    this.skin = new THREE.Mesh(geometry, [skinMaterial(), cavityMaterial(), eyeCornerMaterial()]);
    this.skin.name = 'face';

    const f = mouthFrame(t);
    const teeth = teethMaterial();
    const upper = new THREE.Mesh(teethGeometry(f, true), teeth);
    upper.name = 'teeth_upper';
    const lower = new THREE.Mesh(teethGeometry(f, false), teeth);
    lower.name = 'teeth_lower';
    this.tongue = new THREE.Mesh(tongueGeometry(f), tongueMaterial());
    this.tongue.name = 'tongue';
    this.tongue.updateMorphTargets();
    // The jaw group turns about the hinge; its content is placed in the head's frame (offset back by the hinge).
    this.jaw.name = 'jaw_lower';
    this.jaw.position.set(0, this.hinge.y, this.hinge.z);
    const onJaw = new THREE.Group();
    onJaw.position.set(0, -this.hinge.y, -this.hinge.z);
    onJaw.add(lower, this.tongue);
    this.jaw.add(onJaw);

    // Behind each eye a dark cup (the mouth's material: no shader program of its own), a sphere a little larger than
    // the ball from its back to 45 degrees in front of its middle: the gaps between the lids and the ball show a socket,
    // not the page behind, from the front to the side (head.spec.ts; reaching only 22 degrees in front, 7% of the
    // openings seen from 50 degrees aside showed the page at the inner corners).
    const sockets = this.eyes.centers.map((c, k) => {
      const cup = new THREE.Mesh(new THREE.SphereGeometry(SOCKET * this.eyes.radii[k], 24, 10, 0, 2 * Math.PI, 0, SOCKET_SPAN), this.skin.material[1]);
      cup.geometry.rotateX(-Math.PI / 2); // its dome towards the back of the head (-z)
      // Back a little, to keep its rim behind the temple's skin, and towards the nose, to reach behind the inner corner.
      const r = this.eyes.radii[k];
      cup.position.copy(c).add(new THREE.Vector3(Math.sign(m.centerX - c.x) * 0.2 * r, 0, -0.12 * r));
      cup.name = `eye_socket_${k ? 'right' : 'left'}`;
      return cup;
    });
    const H = m.top - m.chin;
    const neck = new THREE.Mesh(new THREE.CylinderGeometry(0.66 * m.halfWidth, 0.74 * m.halfWidth, 0.72 * H, 28, 4, true), this.skin.material[0]);
    neck.name = 'neck';
    neck.scale.z = 1.05;
    neck.geometry.setAttribute('color', new THREE.BufferAttribute(neckColors(neck.geometry, 0.1 * H, 0.3 * H), 3));
    neck.position.set(m.centerX, m.chin - 0.1 * H, m.sideZ - 0.2 * m.halfWidth);
    neck.rotation.x = 0.12;
    this.group.name = 'head';
    const ears = this.shell ? earGeometries(m, this.shell.egg, SKIN).map((g, k) => Object.assign(new THREE.Mesh(g, this.skin.material[0]), { name: k ? 'ear_left' : 'ear_right' })) : [];
    this.group.add(this.skin, this.eyes.left, this.eyes.right, ...sockets, ...ears, upper, this.jaw, neck);

    const body = new THREE.Mesh(new THREE.SphereGeometry(1, 48, 24, 0, Math.PI * 2, 0, Math.PI * 0.62), clothMaterial());
    body.geometry.setAttribute('color', new THREE.BufferAttribute(plainColors(body.geometry, WHITE), 3));
    body.name = 'shoulders';
    body.scale.set(2.3 * m.halfWidth, 0.62 * H, 1.05 * m.halfWidth);
    body.position.set(m.centerX, m.chin - 1.1 * H, m.sideZ - 0.3 * m.halfWidth);
    this.body = body;
    this.setFace(t.positions, 0);
  }

  /** Vertices of the joined buffer (face, shell, cavity) as last posed. */
  get vertices(): Float32Array {
    return this.positions.array as Float32Array;
  }

  /** The face's own vertex count N (the first N of the joined buffer). */
  get faceVertexCount(): number {
    return this.n;
  }

  /** Pose what follows the face for one frame of it (N x 3, template units) and a tongue raise 0..1. */
  setFace(face: ArrayLike<number>, tongue: number): void {
    const all = this.positions.array as Float32Array;
    for (let i = 0; i < this.n * 3; i++) all[i] = face[i];
    this.eyes.clearance.apply(all); // the lids over the balls, not through them
    if (this.skirts) updateSkirts(this.skirts, all);
    // The jaw may close past the template (the rest face) but the lower teeth stop at the upper ones.
    this.jawAngle = Math.max(-0.09, this.estimator.angle(face));
    const a = this.jawAngle;
    if (this.shell) {
      const { positions: rest, jawWeights } = this.shell;
      const base = this.n * 3;
      for (let j = 0; j < jawWeights.length; j++) {
        const w = jawWeights[j];
        let y = rest[3 * j + 1], z = rest[3 * j + 2];
        if (w > 0) {
          turnAboutHinge(this.hinge, a * w, y, z, scratch);
          [y, z] = scratch;
        }
        all[base + 3 * j] = rest[3 * j];
        all[base + 3 * j + 1] = y;
        all[base + 3 * j + 2] = z;
      }
    }
    if (this.bag) updateBag(this.bag, this.template.positions, face, this.hinge, a, all.subarray(this.bag.first * 3));
    this.jaw.rotation.x = a;
    this.tongue.morphTargetInfluences![0] = tongue;
    this.positions.needsUpdate = true;
    this.partialNormals.update(all, this.normals.array as Float32Array);
    this.normals.needsUpdate = true;
  }

  /** Paint the face's vertices with `colors` (N x 3), or restore the skin colours with null. */
  paint(colors: Float32Array | null): void {
    const attr = this.skin.geometry.getAttribute('color') as THREE.BufferAttribute;
    (attr.array as Float32Array).set(colors ?? this.colors.subarray(0, this.n * 3));
    attr.needsUpdate = true;
  }

  dispose(): void {
    const seen = new Set<THREE.Material>();
    for (const root of [this.group, this.body])
      root.traverse((o) => {
        if (!(o instanceof THREE.Mesh)) return;
        o.geometry.dispose();
        for (const mat of ([] as THREE.Material[]).concat(o.material)) {
          if (seen.has(mat)) continue;
          seen.add(mat);
          for (const v of Object.values(mat)) if (v instanceof THREE.Texture) v.dispose();
          mat.dispose();
        }
      });
  }
}

/** One colour for every vertex of `g`: the neck's skin, or white where the material gives the colour (the shoulders). */
function plainColors(g: THREE.BufferGeometry, color: THREE.Color): Float32Array {
  const n = g.getAttribute('position').count;
  const c = new Float32Array(n * 3);
  for (let i = 0; i < n; i++) color.toArray(c, 3 * i);
  return c;
}
const WHITE = new THREE.Color(1, 1, 1);

/**
 * The neck's skin, shaded darker towards the jaw it goes up into (as the chin's shadow falls on it): full colour
 * below `from` under the chin (the neck's own frame: its centre 0.1 H under the chin), `SHADE` of it `over` higher up.
 * Lit evenly, the neck met the underside of the jaw, which faces away from the light, along a hard bright edge.
 */
function neckColors(g: THREE.BufferGeometry, chin: number, over: number): Float32Array {
  const c = plainColors(g, SKIN), pos = g.getAttribute('position');
  for (let i = 0; i < pos.count; i++) {
    const u = Math.min(1, Math.max(0, (pos.getY(i) - chin + over) / over));
    const k = 1 - (1 - SHADE) * u * u * (3 - 2 * u);
    for (let j = 0; j < 3; j++) c[3 * i + j] *= k;
  }
  return c;
}
const SHADE = 0.55;
