/**
 * The head's own motion (training/src/talkingface/model/head_motion.py, the same numbers): the pose head predicts
 * the mean of the many head movements a sentence can be said with, a head that barely moves; this adds a residual
 * rotation, the part the speech carries read from the pose token plus a draw from the distribution learned from
 * the truth for the rest:
 *
 *   residual_t = A f_t + c + r_t                                  per axis, degrees (rotation vector components)
 *   r_t = a1 r_{t-1} + a2 r_{t-2} + g softplus(W f_t + b) z_t
 *
 * z_t is a hash of (seed, frame, axis), so one seed gives the same motion offline, in chunks and streaming; the
 * state carried between chunks is the process's last two values. The residual turns the head about the neck
 * pivot p: R' = R_r R, t' = R_r (t - p) + p.
 */
import { f32, SafetensorsError, type Tensor } from '../model/safetensors';
import type { ModelConstants } from '../model/manifest';

export interface HeadMotionParams {
  ar: Float32Array;        // (3 x 2)
  sigmaW: Float32Array;    // (3 x d)
  sigmaB: Float32Array;    // (3)
  sigmaMean: Float32Array; // (3), gain included
  pivotMm: Float32Array;   // (3)
  gain: Float32Array;      // (3)
  speechW: Float32Array;   // (3 x d) A: the part the speech carries
  speechB: Float32Array;   // (3) c
}

/** What carries from chunk to chunk: the seed, the next frame and each axis's last two values of the process. */
export interface HeadMotionState {
  seed: number;
  next: number;
  r1: Float64Array;
  r2: Float64Array;
}

/** The head-motion tensors of gava.safetensors (`head_motion.*`), or null for a model exported without them. */
export function headMotionParams(t: Map<string, Tensor>, m: ModelConstants): HeadMotionParams | null {
  if (!t.has('head_motion.ar')) return null;
  const ar = f32(t, 'head_motion.ar', [3, 2]);
  for (let k = 0; k < 3; k++) {
    const [a1, a2] = [ar[2 * k], ar[2 * k + 1]];
    // A process that does not settle starts from an infinite spread or grows without bound: NaN poses, no head.
    if (!(Math.abs(a2) < 1 && a2 + a1 < 1 && a2 - a1 < 1)) {
      throw new SafetensorsError(`head_motion.ar: axis ${k}'s AR(2) (${a1}, ${a2}) does not settle (|a2| < 1, a2 +- a1 < 1): re-fit the head's motion`);
    }
  }
  return {
    ar,
    sigmaW: f32(t, 'head_motion.sigma_w', [3, m.d_model]),
    sigmaB: f32(t, 'head_motion.sigma_b', [3]),
    sigmaMean: f32(t, 'head_motion.sigma_mean', [3]),
    pivotMm: f32(t, 'head_motion.pivot_mm', [3]),
    gain: f32(t, 'head_motion.gain', [3]),
    // A model exported before the speech read-out has none: the process alone.
    speechW: t.has('head_motion.speech_w') ? f32(t, 'head_motion.speech_w', [3, m.d_model]) : new Float32Array(3 * m.d_model),
    speechB: t.has('head_motion.speech_b') ? f32(t, 'head_motion.speech_b', [3]) : new Float32Array(3),
  };
}

/** lowbias32 (C. Wellons): the same 32-bit hash as the Python sampler. */
function hash32(x: number): number {
  x >>>= 0;
  x ^= x >>> 16;
  x = Math.imul(x, 0x7feb352d) >>> 0;
  x ^= x >>> 15;
  x = Math.imul(x, 0x846ca68b) >>> 0;
  x ^= x >>> 16;
  return x >>> 0;
}

/** The largest headMotionScale: three times the fitted motion is already far livelier than any corpus speaker. */
export const MAX_HEAD_MOTION_SCALE = 3;

/** A head-motion scale as given (undefined stays undefined: the engine's own), or a RangeError that says the range. */
export function checkedScale(scale: number | undefined): number | undefined {
  if (scale !== undefined && !(Number.isFinite(scale) && scale >= 0 && scale <= MAX_HEAD_MOTION_SCALE)) {
    throw new RangeError(`headMotionScale must be a number from 0 to ${MAX_HEAD_MOTION_SCALE}, not ${scale}`);
  }
  return scale;
}

/** A standard normal draw for (seed, frame >= -2, axis): Box-Muller on two hashed uniforms. */
export function headNormal(seed: number, frame: number, axis: number): number {
  const key = hash32(hash32((seed + 0x632be5ab) >>> 0) ^ hash32((frame + 2) * 8 + axis * 2 + 1));
  const u1 = (hash32(key) + 0.5) / 2 ** 32;
  const u2 = (hash32((key ^ 0x9e3779b9) >>> 0) + 0.5) / 2 ** 32;
  return Math.sqrt(-2 * Math.log(u1)) * Math.cos(2 * Math.PI * u2);
}

const softplus = (x: number) => Math.max(x, 0) + Math.log1p(Math.exp(-Math.abs(x)));

export class HeadMotion {
  constructor(readonly params: HeadMotionParams, private readonly d: number) {}

  /** The state before frame 0: two residuals from the process's stationary distribution at the mean step size. */
  start(seed: number): HeadMotionState {
    const { ar, sigmaMean } = this.params;
    const r1 = new Float64Array(3), r2 = new Float64Array(3);
    for (let k = 0; k < 3; k++) {
      const a1 = ar[2 * k], a2 = ar[2 * k + 1];
      const sd = Math.sqrt(Math.max(0, (1 - a2) / ((1 + a2) * ((1 - a2) ** 2 - a1 ** 2))));
      const rho = a1 / (1 - a2);
      r2[k] = sigmaMean[k] * sd * headNormal(seed, -2, k);
      r1[k] = rho * r2[k] + sigmaMean[k] * sd * Math.sqrt(Math.max(1 - rho * rho, 0)) * headNormal(seed, -1, k);
    }
    return { seed, next: 0, r1, r2 };
  }

  /**
   * Residuals of frames [state.next, state.next + count) in degrees (count x 3), from their pose tokens
   * (count x d); advances the state. Frames skipped before `first` (a live stream that fell behind) advance the
   * process at the mean step size.
   */
  residuals(state: HeadMotionState, first: number, poseToken: Float32Array, count: number): Float64Array {
    const { ar, sigmaW, sigmaB, sigmaMean, gain, speechW, speechB } = this.params;
    const { d } = this;
    const seed = state.seed;
    const step = (t: number, k: number, s: number) => {
      const r = ar[2 * k] * state.r1[k] + ar[2 * k + 1] * state.r2[k] + s * headNormal(seed, t, k);
      state.r2[k] = state.r1[k];
      state.r1[k] = r;
      return r;
    };
    for (; state.next < first; state.next++) for (let k = 0; k < 3; k++) step(state.next, k, sigmaMean[k]);
    const out = new Float64Array(count * 3);
    for (let i = 0; i < count; i++, state.next++) {
      for (let k = 0; k < 3; k++) {
        let x = sigmaB[k], speech = speechB[k];
        for (let j = 0; j < d; j++) {
          x += sigmaW[k * d + j] * poseToken[i * d + j];
          speech += speechW[k * d + j] * poseToken[i * d + j];
        }
        out[3 * i + k] = speech + step(state.next, k, gain[k] * softplus(x));
      }
    }
    return out;
  }

  /**
   * Turn each pose (count x 6: rotation vector rad, translation mm) by its residual (degrees) about the pivot, in place;
   * `scale` multiplies the residual (1: the motion as fitted; 0: the mean pose alone).
   */
  compose(pose: Float32Array, residualDeg: Float64Array, count: number, scale = 1): void {
    const p = this.params.pivotMm;
    const k = DEG * scale;
    for (let f = 0; f < count; f++) {
      const Rr = rotation(residualDeg[3 * f] * k, residualDeg[3 * f + 1] * k, residualDeg[3 * f + 2] * k);
      const R = mul(Rr, rotation(pose[6 * f], pose[6 * f + 1], pose[6 * f + 2]));
      const rv = rotationVector(R);
      const tx = pose[6 * f + 3] - p[0], ty = pose[6 * f + 4] - p[1], tz = pose[6 * f + 5] - p[2];
      pose[6 * f] = rv[0];
      pose[6 * f + 1] = rv[1];
      pose[6 * f + 2] = rv[2];
      pose[6 * f + 3] = Rr[0] * tx + Rr[1] * ty + Rr[2] * tz + p[0];
      pose[6 * f + 4] = Rr[3] * tx + Rr[4] * ty + Rr[5] * tz + p[1];
      pose[6 * f + 5] = Rr[6] * tx + Rr[7] * ty + Rr[8] * tz + p[2];
    }
  }
}

const DEG = Math.PI / 180;

/** Rodrigues: rotation vector (rad) -> row-major 3 x 3. */
function rotation(rx: number, ry: number, rz: number): number[] {
  const th = Math.hypot(rx, ry, rz);
  const a = th < 1e-6 ? 1 - (th * th) / 6 : Math.sin(th) / th;
  const b = th < 1e-6 ? 0.5 - (th * th) / 24 : (1 - Math.cos(th)) / (th * th);
  return [
    1 - b * (ry * ry + rz * rz), -a * rz + b * rx * ry, a * ry + b * rx * rz,
    a * rz + b * rx * ry, 1 - b * (rx * rx + rz * rz), -a * rx + b * ry * rz,
    -a * ry + b * rx * rz, a * rx + b * ry * rz, 1 - b * (rx * rx + ry * ry),
  ];
}

function mul(A: number[], B: number[]): number[] {
  const C = new Array<number>(9);
  for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
  return C;
}

/** Row-major rotation -> rotation vector (rad), for angles below pi (as geometry/pose.py matrix_to_rotvec). */
function rotationVector(R: number[]): [number, number, number] {
  const angle = Math.acos(Math.min(1, Math.max(-1, (R[0] + R[4] + R[8] - 1) / 2)));
  const s = Math.sin(angle);
  const factor = s < 1e-8 ? 0.5 : angle / (2 * s);
  return [(R[7] - R[5]) * factor, (R[2] - R[6]) * factor, (R[3] - R[1]) * factor];
}
