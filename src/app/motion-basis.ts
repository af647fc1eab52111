/**
 * A few motion components for a long animation: the mean displacement and the top K principal
 * directions of the per-frame displacements, with each frame's coefficients. The .glb export uses it
 * for clips too long for one morph target per frame (export-glb.ts): K = 8 targets, the number glTF
 * asks every viewer to support at once, whatever the clip's length.
 *
 * The directions come from subspace iteration (Q <- orth(D^T D Q), a few rounds from a deterministic
 * start) on at most `fitFrames` frames evenly spread over the clip (a long clip's motion is the same motion again:
 * 2,048 frames, over a minute, find its directions), then every frame is projected on them: O(iterations x
 * min(frames, fitFrames) x dims x K + frames x dims x K). It yields to the event loop as it goes (a 10-minute clip
 * of the whole head is seconds of work), says how far it is, and stops if its signal is aborted.
 */
import { slicer, type Slicing } from '../engine/frames';

export interface MotionBasis {
  /** (dims) the mean displacement */
  mean: Float32Array;
  /** (K x dims) orthonormal directions, strongest first */
  basis: Float32Array;
  /** (frames x K) each frame's coordinates along the directions */
  coefficients: Float32Array;
  components: number;
  /** largest distance of any point (3 consecutive dims) from its reconstruction, in the data's units */
  maxError: number;
}

export interface MotionBasisOptions extends Slicing {
  /** Rounds of subspace iteration (default 8). */
  iterations?: number;
  /** At most this many frames, evenly spread, find the directions (default 2,048). */
  fitFrames?: number;
}

/** D: frames x dims displacements (row-major), dims a multiple of 3 (points). */
export async function motionBasis(D: Float32Array, frames: number, dims: number, K: number, options: MotionBasisOptions = {}): Promise<MotionBasis> {
  if (D.length !== frames * dims) throw new Error(`motionBasis: ${D.length} values, not ${frames} x ${dims}`);
  const { iterations = 8, fitFrames = 2048, onProgress, signal } = options;
  signal?.throwIfAborted();
  K = Math.max(0, Math.min(K, frames, dims));
  const fit = Array.from({ length: Math.min(frames, fitFrames) }, (_, j) => Math.floor((j * frames) / Math.min(frames, fitFrames)));
  // Work in frame-rows: the mean reads every frame; each round the fitted frames twice; the end, every frame twice.
  const total = frames + iterations * 2 * fit.length + 2 * frames;
  const step = slicer(total, { onProgress, signal });
  const mean = new Float32Array(dims);
  const acc = new Float64Array(dims);
  for (let f = 0; f < frames; f++) {
    for (let i = 0; i < dims; i++) acc[i] += D[f * dims + i];
    await step();
  }
  for (let i = 0; i < dims; i++) mean[i] = acc[i] / Math.max(1, frames);

  // Q: K x dims, rows orthonormal. Start from K frames spread over the clip (deterministic).
  const Q = new Float64Array(K * dims);
  for (let k = 0; k < K; k++) {
    const f = Math.floor(((k + 0.5) * frames) / K);
    for (let i = 0; i < dims; i++) Q[k * dims + i] = D[f * dims + i] - mean[i] + 1e-3 * Math.sin((k + 1) * (i + 1));
  }
  orthonormalise(Q, K, dims);
  const P = new Float64Array(frames * K); // D_centred Q^T
  for (let it = 0; it < iterations; it++) {
    for (const f of fit) {
      project(D, mean, f, dims, Q, K, P);
      await step();
    }
    // Q <- P^T D_centred (K x dims) over the fitted frames, then orthonormalise
    Q.fill(0);
    for (const f of fit) {
      const row = f * dims;
      for (let k = 0; k < K; k++) {
        const p = P[f * K + k];
        if (p === 0) continue;
        const q = k * dims;
        for (let i = 0; i < dims; i++) Q[q + i] += p * (D[row + i] - mean[i]);
      }
      await step();
    }
    orthonormalise(Q, K, dims);
  }
  for (let f = 0; f < frames; f++) {
    project(D, mean, f, dims, Q, K, P);
    await step();
  }
  // Order by strength (the variance along each direction).
  const strength = Array.from({ length: K }, (_, k) => {
    let s = 0;
    for (let f = 0; f < frames; f++) s += P[f * K + k] ** 2;
    return s;
  });
  const order = strength.map((_, k) => k).sort((a, b) => strength[b] - strength[a]);
  const basis = new Float32Array(K * dims);
  const coefficients = new Float32Array(frames * K);
  order.forEach((k, j) => {
    for (let i = 0; i < dims; i++) basis[j * dims + i] = Q[k * dims + i];
    for (let f = 0; f < frames; f++) coefficients[f * K + j] = P[f * K + k];
  });
  let maxError = 0;
  const r = new Float64Array(dims);
  for (let f = 0; f < frames; f++) {
    for (let i = 0; i < dims; i++) r[i] = mean[i];
    for (let k = 0; k < K; k++) {
      const c = coefficients[f * K + k];
      for (let i = 0; i < dims; i++) r[i] += c * basis[k * dims + i];
    }
    for (let i = 0; i < dims; i += 3) {
      const e = Math.hypot(D[f * dims + i] - r[i], D[f * dims + i + 1] - r[i + 1], D[f * dims + i + 2] - r[i + 2]);
      if (e > maxError) maxError = e;
    }
    await step();
  }
  onProgress?.(1);
  return { mean, basis, coefficients, components: K, maxError };
}

/** Frame f's coordinates along the K rows of Q, into P. */
function project(D: Float32Array, mean: Float32Array, f: number, dims: number, Q: Float64Array, K: number, P: Float64Array): void {
  const row = f * dims;
  for (let k = 0; k < K; k++) {
    const q = k * dims;
    let s = 0;
    for (let i = 0; i < dims; i++) s += (D[row + i] - mean[i]) * Q[q + i];
    P[f * K + k] = s;
  }
}

/** Modified Gram-Schmidt on the K rows of Q (twice, for accuracy); a vanishing row becomes zeros. */
function orthonormalise(Q: Float64Array, K: number, dims: number): void {
  for (let pass = 0; pass < 2; pass++) {
    for (let k = 0; k < K; k++) {
      const a = k * dims;
      for (let j = 0; j < k; j++) {
        const b = j * dims;
        let dot = 0;
        for (let i = 0; i < dims; i++) dot += Q[a + i] * Q[b + i];
        for (let i = 0; i < dims; i++) Q[a + i] -= dot * Q[b + i];
      }
      let norm = 0;
      for (let i = 0; i < dims; i++) norm += Q[a + i] * Q[a + i];
      norm = Math.sqrt(norm);
      for (let i = 0; i < dims; i++) Q[a + i] = norm > 1e-12 ? Q[a + i] / norm : 0;
    }
  }
}
