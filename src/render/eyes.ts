/**
 * Eyeballs in the sockets behind the lids: a sclera with iris, limbus and pupil painted on it (a texture drawn in
 * code), under a clear coat that catches the lights as the cornea does (materials.ts), and gaze: each eye turns about its centre towards
 * a target in the head's frame. The lids are the face's own vertices, so the model's blinks (and the idle blinks,
 * eyelids.ts) close them over the eyes.
 *
 * Sizes come from each lid opening, so any template gets fitting eyes.
 *
 * The skin stays outside the balls (SkinClearance): the vertices in front of each ball that come within a clearance
 * of its surface (a lid corner at rest, a closing lid passing over the front) are pushed out along the ball's radius
 * to it, so the white does not show through the skin. The clearance is what a triangle of the skin there sags
 * inside a sphere through its corners, so its faces stay out too, not only its vertices.
 *
 * Behind each opening a skirt (eyeSkirts) runs from the lid edge round the ball to behind its middle, so a look into
 * the opening from any side meets the ball or the skirt, never the inside of the head or the page behind it.
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';
import { boundaryLoops } from '../template/mesh-topology';
import { eyeMaterial } from './materials';

/** Largest turn of the eyes from straight ahead (radians): people turn the head beyond about this. */
const MAX_TURN = 0.45;
/** The skin vertices kept outside a ball: in front of its centre and within this many radii of it at rest. */
const NEAR = 1.3;
const scratch = new THREE.Vector3();

/** Where the balls go in a template: centres (head frame, template units) and radii, left eye first. */
export function ballsFor(template: FaceTemplate): { centers: THREE.Vector3[]; radii: number[] } {
  const centers: THREE.Vector3[] = [], radii: number[] = [];
  for (const side of ['left', 'right'] as const) {
    const r = template.regions;
    const box = new THREE.Box3();
    for (const v of [...r[`eye_${side}_upper`], ...r[`eye_${side}_lower`]]) box.expandByPoint(scratch.fromArray(template.positions, 3 * v));
    const size = box.getSize(new THREE.Vector3());
    const center = box.getCenter(new THREE.Vector3());
    const radius = size.x * 0.62;
    // The front of the ball sits just behind the deepest lid vertex, so lids close in front of it.
    centers.push(new THREE.Vector3(center.x, center.y - size.y * 0.08, box.max.z - radius * 1.02 - size.z * 0.12));
    radii.push(radius);
  }
  return { centers, radii };
}

export class Eyes {
  readonly left: THREE.Group;
  readonly right: THREE.Group;
  /** Eye centres in the head's frame (template units). */
  readonly centers: THREE.Vector3[];
  /** The balls' radii (template units). */
  readonly radii: number[];
  /** Keeps the skin outside the balls. */
  readonly clearance: SkinClearance;

  constructor(template: FaceTemplate) {
    const material = eyeMaterial();
    ({ centers: this.centers, radii: this.radii } = ballsFor(template));
    [this.left, this.right] = (['left', 'right'] as const).map((side, k) => {
      const eye = new THREE.Group();
      eye.name = `eye_${side}`;
      eye.rotation.order = 'YXZ';
      const ballGeometry = new THREE.SphereGeometry(this.radii[k], 40, 24);
      ballGeometry.rotateX(Math.PI / 2); // the texture's pole (the iris) looks along +z
      const ball = new THREE.Mesh(ballGeometry, material);
      ball.name = `eyeball_${side}`;
      eye.add(ball);
      eye.position.copy(this.centers[k]);
      return eye;
    });
    this.clearance = new SkinClearance(template, this.centers, this.radii);
  }

  /** Turn both eyes towards `target` (head frame) offset by (yaw, pitch) radians; turns are clamped. */
  lookAt(target: THREE.Vector3, yaw: number, pitch: number): void {
    for (const eye of [this.left, this.right]) {
      scratch.subVectors(target, eye.position);
      const y = Math.atan2(scratch.x, scratch.z) + yaw;
      const p = Math.atan2(scratch.y, Math.hypot(scratch.x, scratch.z)) + pitch;
      eye.rotation.y = Math.max(-MAX_TURN, Math.min(MAX_TURN, y));
      eye.rotation.x = -Math.max(-MAX_TURN, Math.min(MAX_TURN, p));
    }
  }
}

/** Keeps a skin's vertices (the template's layout) out of balls: see the file's comment. */
export class SkinClearance {
  /** Per ball, the skin vertices that may meet it (in front of its centre, within NEAR radii of it at rest). */
  private readonly near: Uint32Array[];
  /** Per ball, how far from its centre the skin is kept (template units). */
  readonly clear: number[];

  constructor(template: FaceTemplate, private readonly centers: THREE.Vector3[], radii: number[]) {
    this.near = centers.map((c, k) => nearBall(template.positions, c, radii[k]));
    this.clear = radii.map((r, k) => r + sag(template, this.near[k], r));
  }

  /** Push the skin's vertices near the balls (the first vertices of `positions`) out to the clearance. */
  apply(positions: Float32Array): void {
    this.centers.forEach((c, k) => {
      const R = this.clear[k];
      for (const v of this.near[k]) {
        const x = positions[3 * v] - c.x, y = positions[3 * v + 1] - c.y, z = positions[3 * v + 2] - c.z;
        const d = Math.hypot(x, y, z);
        if (d >= R || d === 0) continue;
        const s = R / d;
        positions[3 * v] = c.x + x * s;
        positions[3 * v + 1] = c.y + y * s;
        positions[3 * v + 2] = c.z + z * s;
      }
    });
  }
}

/** The vertices of `p` in front of `center` and within NEAR x `radius` of it. */
function nearBall(p: Float32Array, center: THREE.Vector3, radius: number): Uint32Array {
  const out: number[] = [];
  for (let v = 0; v < p.length / 3; v++) {
    const d = Math.hypot(p[3 * v] - center.x, p[3 * v + 1] - center.y, p[3 * v + 2] - center.z);
    if (p[3 * v + 2] > center.z && d < NEAR * radius) out.push(v);
  }
  return Uint32Array.from(out);
}

/**
 * How far inside a sphere of `radius` through its corners a skin triangle among `near` sags, at most: L^2 / (6 R)
 * for the longest edge L (an equilateral triangle's centre lies (L / sqrt 3)^2 / 2R inside its circumscribed sphere).
 */
function sag(t: FaceTemplate, near: Uint32Array, radius: number): number {
  const inside = new Set(near);
  const p = t.positions, tri = t.triangles;
  let longest = 0;
  for (let f = 0; f < tri.length; f += 3) {
    if (!inside.has(tri[f]) || !inside.has(tri[f + 1]) || !inside.has(tri[f + 2])) continue;
    for (let e = 0; e < 3; e++) {
      const a = tri[f + e], b = tri[f + ((e + 1) % 3)];
      longest = Math.max(longest, Math.hypot(p[3 * a] - p[3 * b], p[3 * a + 1] - p[3 * b + 1], p[3 * a + 2] - p[3 * b + 2]));
    }
  }
  return (longest * longest) / (6 * radius);
}

/** How far round from the front the skirts reach behind the balls (radians), and their radius there (ball radii). */
const SKIRT_BACK = 0.6 * Math.PI;
const SKIRT_RADIUS = 1.1;

/**
 * The skirts behind the eye openings, in a joined buffer after `first`: per eye a front ring, a copy of the opening's
 * loop of face vertices made every frame (updateSkirts; copies, so the lids' normals stay their own), and a back ring
 * that stays, on a sphere a little larger than the ball, behind its middle, each vertex out from the ball's axis the
 * way its front vertex is.
 */
export interface EyeSkirts {
  /** Per eye, the opening's loop of face vertices. */
  rims: number[][];
  /** (2 x sum of the rims' lengths, x 3) the skirts' vertices: per eye its front ring, then its back ring. */
  rest: Float32Array;
  /** Triangles in the joined buffer's indices, facing the ball's axis (what a look into the opening sees). */
  triangles: Uint32Array;
  first: number;
}

export function eyeSkirts(t: FaceTemplate, centers: THREE.Vector3[], radii: number[], first: number): EyeSkirts | null {
  const loops = boundaryLoops(t.triangles);
  const rims = (['left', 'right'] as const).map((side) => {
    const lids = new Set([...t.regions[`eye_${side}_upper`], ...t.regions[`eye_${side}_lower`]]);
    return loops.find((l) => l.filter((v) => lids.has(v)).length >= 0.8 * lids.size);
  });
  if (rims.some((r) => !r)) return null;
  const p = t.positions;
  const rest = new Float32Array(2 * 3 * (rims[0]!.length + rims[1]!.length));
  const tris: number[] = [];
  let at = 0;
  rims.forEach((rim, k) => {
    const c = centers[k], R = SKIRT_RADIUS * radii[k], M = rim!.length;
    rim!.forEach((v, i) => {
      rest.set([p[3 * v], p[3 * v + 1], p[3 * v + 2]], 3 * (at + i));
      const dx = p[3 * v] - c.x, dy = p[3 * v + 1] - c.y, d = Math.hypot(dx, dy) || 1;
      const out = R * Math.sin(SKIRT_BACK) / d;
      rest.set([c.x + dx * out, c.y + dy * out, c.z + R * Math.cos(SKIRT_BACK)], 3 * (at + M + i));
    });
    const front = (i: number) => first + at + (i % M), back = (i: number) => first + at + M + (i % M);
    // Wound so the first quad's normal points at the ball's axis; the rest follow it round the loop.
    const a = scratch.fromArray(rest, 3 * at), b = new THREE.Vector3().fromArray(rest, 3 * (at + 1)), q = new THREE.Vector3().fromArray(rest, 3 * (at + M));
    const normal = new THREE.Vector3().subVectors(b, a).cross(q.sub(a));
    const inward = new THREE.Vector3(c.x - a.x, c.y - a.y, 0);
    const flip = normal.dot(inward) < 0;
    for (let i = 0; i < M; i++) {
      if (flip) tris.push(front(i), back(i), front(i + 1), front(i + 1), back(i), back(i + 1));
      else tris.push(front(i), front(i + 1), back(i), front(i + 1), back(i + 1), back(i));
    }
    at += 2 * M;
  });
  return { rims: rims as number[][], rest, triangles: Uint32Array.from(tris), first };
}

/** Copy each opening's loop, as `positions` (the joined buffer) holds it now, into its skirt's front ring there. */
export function updateSkirts(s: EyeSkirts, positions: Float32Array): void {
  let at = s.first;
  for (const rim of s.rims) {
    for (let i = 0; i < rim.length; i++) positions.copyWithin(3 * (at + i), 3 * rim[i], 3 * rim[i] + 3);
    at += 2 * rim.length;
  }
}
