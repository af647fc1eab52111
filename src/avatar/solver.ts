/**
 * From the model's per-frame displacement O (unposed minus template, mm) to ARKit weights in [0, 1]: bounded
 * least squares on the basis (basis.ts),
 *
 *   min_w || B w - (O - neutralOffset) ||^2 + lambda || w ||^2 + sum_k mu_k w_k,   0 <= w <= 1,
 *
 * solved exactly by a primal active-set method on the normal equations (the Gram matrix B^T B is computed once;
 * each step solves the free weights by Cholesky), started from the previous frame's weights and bounds:
 * consecutive frames differ little, so most frames need one or two solves. The small ridge term makes the
 * minimiser unique (some shapes overlap, e.g. mouthLeft and jawLeft near the chin), so the answer does not
 * depend on the start: chunked, streamed and whole-clip solves agree. The L1 term (mu_k; on w >= 0 it is linear)
 * keeps the weights sparse: the motion goes to the shapes that explain it, the rig's articulators first.
 */
import { ARKIT_NAMES } from './names';
import type { ArkitBasis } from './basis';

export interface SolverOptions {
  /** The ridge term, as a fraction of the mean squared norm of the shapes (default 1e-3). */
  ridge?: number;
  /**
   * The L1 term on the speech shapes (the rig's articulators: basis.speech) and on the others, as fractions of each
   * shape's squared norm (default 0.002 and 0.02): a shape is used only where it explains more than that, so the
   * motion is not spread over expressions that cancel each other (mouthFrown against mouthUpperUp, say).
   */
  sparsity?: { speech: number; other: number };
}

/** What carries from one frame to the next: the last weights (the warm start). */
export interface SolverState {
  weights: Float32Array;
}

export class BlendshapeSolver {
  readonly shapeCount = ARKIT_NAMES.length;
  /** Linear solves used by the last frame (for the cost measure). */
  lastSolves = 0;
  private readonly active: number[];
  private readonly rows: Float32Array; // (A x 3N) the fitted shapes, one per row
  private readonly gram: Float64Array; // (A x A) B^T B + lambda I
  private readonly scale: number;
  private readonly l1: Float64Array; // per fitted shape: the L1 weight (w >= 0, so a linear term)
  private readonly h: Float64Array;
  private readonly w: Float64Array;
  private readonly z: Float64Array;
  private readonly bound: Int8Array; // per fitted shape: 0 free, -1 held at 0, +1 held at 1
  private readonly chol: Float64Array;
  private readonly rhs: Float64Array;

  constructor(readonly basis: ArkitBasis, options: SolverOptions = {}) {
    const n3 = basis.n * 3;
    this.active = basis.fitted.flatMap((on, k) => (on ? [k] : []));
    const A = this.active.length;
    this.rows = new Float32Array(A * n3);
    this.active.forEach((k, a) => this.rows.set(basis.shapes.subarray(k * n3, (k + 1) * n3), a * n3));
    this.gram = new Float64Array(A * A);
    for (let a = 0; a < A; a++) {
      for (let b = a; b < A; b++) {
        const g = dot(this.rows, a * n3, this.rows, b * n3, n3);
        this.gram[a * A + b] = g;
        this.gram[b * A + a] = g;
      }
    }
    let trace = 0;
    for (let a = 0; a < A; a++) trace += this.gram[a * A + a];
    this.scale = trace / A;
    const sparsity = options.sparsity ?? { speech: 0.002, other: 0.02 };
    this.l1 = Float64Array.from(this.active, (k, a) => (basis.speech[k] ? sparsity.speech : sparsity.other) * this.gram[a * A + a]);
    for (let a = 0; a < A; a++) this.gram[a * A + a] += (options.ridge ?? 1e-3) * this.scale;
    [this.h, this.w, this.z, this.rhs] = [0, 0, 0, 0].map(() => new Float64Array(A));
    this.bound = new Int8Array(A);
    this.chol = new Float64Array(A * A);
  }

  newState(): SolverState {
    return { weights: new Float32Array(this.shapeCount) };
  }

  /**
   * Weights of one frame: `offsets` holds O (N x 3, mm) from index `at`; the result (52, ARKIT_NAMES order) is
   * written to `out` from `outAt` and kept in `state` for the next frame.
   */
  solve(offsets: ArrayLike<number>, at: number, state: SolverState, out: Float32Array, outAt = 0): void {
    const { active, rows, gram, h, w, z, bound } = this;
    const A = active.length;
    const n3 = this.basis.n * 3;
    const neutral = this.basis.neutralOffset;
    for (let a = 0; a < A; a++) {
      let s = 0;
      const r = a * n3;
      for (let i = 0; i < n3; i++) s += rows[r + i] * (offsets[at + i] - neutral[i]);
      h[a] = s - this.l1[a];
      w[a] = Math.min(1, Math.max(0, state.weights[active[a]]));
      bound[a] = w[a] <= 0 ? -1 : w[a] >= 1 ? 1 : 0;
    }
    const eps = 1e-9 * this.scale;
    let solves = 0;
    // Primal active set: w stays feasible; each step minimises over the free weights with the others held.
    for (let step = 0; step < 8 * A + 8; step++) {
      solves++;
      this.solveFree(); // z: the free weights' minimiser
      let alpha = 1, blocking = -1;
      for (let a = 0; a < A; a++) {
        if (bound[a] !== 0) continue;
        const d = z[a] - w[a];
        const room = d < 0 ? -w[a] / d : d > 0 ? (1 - w[a]) / d : Infinity;
        if (room < alpha) [alpha, blocking] = [room, a];
      }
      for (let a = 0; a < A; a++) if (bound[a] === 0) w[a] += alpha * (z[a] - w[a]);
      if (blocking >= 0) {
        bound[blocking] = z[blocking] < w[blocking] || w[blocking] < 0.5 ? -1 : 1;
        w[blocking] = bound[blocking] < 0 ? 0 : 1;
        continue;
      }
      // Optimal over the free set: release every held weight whose gradient wants it back inside (the next step
      // holds again any that the joint solve pushes out, so the cost still falls at every step).
      let released = 0;
      for (let a = 0; a < A; a++) {
        if (bound[a] === 0) continue;
        let g = -h[a];
        for (let b = 0; b < A; b++) g += gram[a * A + b] * w[b];
        if ((bound[a] < 0 ? -g : g) > eps) { // moving inside lowers the cost
          bound[a] = 0;
          released++;
        }
      }
      if (!released) break;
    }
    this.lastSolves = solves;
    state.weights.fill(0); // the shapes not fitted stay 0
    for (let a = 0; a < A; a++) state.weights[active[a]] = w[a];
    out.set(state.weights, outAt);
  }

  /** z_F = G_FF^-1 (h_F - G_FB w_B) by Cholesky over the free weights; held weights copy w. */
  private solveFree(): void {
    const { gram, h, w, z, bound, chol: L, rhs } = this;
    const A = this.active.length;
    const free: number[] = [];
    for (let a = 0; a < A; a++) {
      if (bound[a] !== 0) z[a] = w[a];
      else free.push(a);
    }
    const m = free.length;
    for (let i = 0; i < m; i++) {
      let s = h[free[i]];
      for (let b = 0; b < A; b++) if (bound[b] !== 0) s -= gram[free[i] * A + b] * w[b];
      rhs[i] = s;
      for (let j = 0; j <= i; j++) {
        let v = gram[free[i] * A + free[j]];
        for (let k = 0; k < j; k++) v -= L[i * A + k] * L[j * A + k];
        L[i * A + j] = i === j ? Math.sqrt(v) : v / L[j * A + j];
      }
    }
    for (let i = 0; i < m; i++) { // L y = rhs
      let s = rhs[i];
      for (let k = 0; k < i; k++) s -= L[i * A + k] * rhs[k];
      rhs[i] = s / L[i * A + i];
    }
    for (let i = m - 1; i >= 0; i--) { // L^T x = y
      let s = rhs[i];
      for (let k = i + 1; k < m; k++) s -= L[k * A + i] * rhs[k];
      rhs[i] = s / L[i * A + i];
    }
    for (let i = 0; i < m; i++) z[free[i]] = rhs[i];
  }

  /** The displacement O (N x 3, mm) the weights make: neutralOffset + B w. */
  reconstruct(weights: ArrayLike<number>, at = 0, out = new Float32Array(this.basis.n * 3)): Float32Array {
    const n3 = this.basis.n * 3;
    out.set(this.basis.neutralOffset);
    for (let k = 0; k < this.shapeCount; k++) {
      const wk = weights[at + k];
      if (wk === 0) continue;
      const s = this.basis.shapes.subarray(k * n3, (k + 1) * n3);
      for (let i = 0; i < n3; i++) out[i] += wk * s[i];
    }
    return out;
  }
}

function dot(a: Float32Array, ai: number, b: Float32Array, bi: number, n: number): number {
  let s = 0;
  for (let i = 0; i < n; i++) s += a[ai + i] * b[bi + i];
  return s;
}
