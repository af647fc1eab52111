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
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';
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
