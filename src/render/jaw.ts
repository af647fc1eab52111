/**
 * The mandible's rotation, estimated each frame from the face the model made, so that what the model does not
 * draw (lower teeth, tongue, the floor of the mouth, the skin under the chin) can follow its jaw.
 *
 * The hinge is the corpus rig's (training/src/talkingface/corpus/rig.py): on the mouth's midline, 0.7 W above the
 * mouth corners and 2 W behind the inner lips (W: the inner mouth's width), the axis along x. The rig turns every
 * vertex below corner - 0.45 W rigidly about it; the lower lip turns too, plus its own lip motion. So the angle is
 * a weighted mean, over those chin vertices (weight 1) and the lower inner-lip contour (weight 1/4, since the lips
 * also move on their own), of each vertex's angle about the hinge in the y-z plane now, minus its angle in the
 * template. 0 is the template's jaw (opened a little so the lips can part); positive opens the mouth.
 */
import type { FaceTemplate } from '../template/face-template';
import type { FaceMeasures } from './head-shell';

export interface Hinge {
  /** A point on the axis (template units); the axis is +x. */
  y: number;
  z: number;
}

export function jawHinge(t: FaceTemplate, m: FaceMeasures): Hinge {
  const inner = [...t.regions.lips_inner_upper, ...t.regions.lips_inner_lower];
  const lipsZ = inner.reduce((s, v) => s + t.positions[3 * v + 2], 0) / inner.length;
  return { y: m.cornerY + 0.7 * m.mouthWidth, z: lipsZ - 2 * m.mouthWidth };
}

export class JawEstimator {
  private readonly points: Uint32Array;
  private readonly weights: Float32Array;
  private readonly rest: Float32Array;

  constructor(t: FaceTemplate, m: FaceMeasures, readonly hinge: Hinge) {
    const p = t.positions;
    const chin: number[] = [];
    for (let v = 0; v < t.vertexCount; v++) if (p[3 * v + 1] < m.cornerY - 0.45 * m.mouthWidth) chin.push(v);
    const lip = [...t.regions.lips_inner_lower].filter((v) => !t.regions.lips_inner_upper.includes(v));
    this.points = Uint32Array.from([...chin, ...lip]);
    this.weights = Float32Array.from(this.points, (_, i) => (i < chin.length ? 1 : 0.25));
    this.rest = Float32Array.from(this.points, (v) => this.angleOf(p, v));
  }

  /** The jaw's opening (radians, about +x through the hinge; positive opens) of face vertices `v` (template units). */
  angle(v: ArrayLike<number>): number {
    let s = 0, w = 0;
    for (let i = 0; i < this.points.length; i++) {
      let d = this.angleOf(v, this.points[i]) - this.rest[i];
      if (d > Math.PI) d -= 2 * Math.PI;
      else if (d < -Math.PI) d += 2 * Math.PI;
      s += this.weights[i] * d;
      w += this.weights[i];
    }
    return w ? s / w : 0;
  }

  /** Angle of a vertex about the hinge, measured so that opening the jaw (chin down and back) increases it. */
  private angleOf(p: ArrayLike<number>, v: number): number {
    return -Math.atan2(p[3 * v + 1] - this.hinge.y, p[3 * v + 2] - this.hinge.z);
  }
}

/** Turn (y, z) about the hinge by `angle` (positive opens: points in front of the hinge go down). */
export function turnAboutHinge(h: Hinge, angle: number, y: number, z: number, out: number[]): void {
  const c = Math.cos(angle), s = Math.sin(angle);
  const dy = y - h.y, dz = z - h.z;
  out[0] = h.y + dy * c - dz * s;
  out[1] = h.z + dy * s + dz * c;
}
