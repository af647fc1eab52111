/**
 * The content window of each animation frame (paper: d_i, W x D): phone posteriors
 * (softmax of the content encoder's logits) for content frames [c - (W - 1 - future), c + future]
 * around c = floor(mel_index / content_stride); frames outside the clip read zeros.
 */
import type { ModelConstants } from '../model/manifest';

/** Softmax over each row of a (rows x D) matrix, in place. */
export function softmaxRows(x: Float32Array, D: number): Float32Array {
  for (let r = 0; r < x.length / D; r++) {
    let max = -Infinity;
    for (let j = 0; j < D; j++) max = Math.max(max, x[r * D + j]);
    let sum = 0;
    for (let j = 0; j < D; j++) {
      const e = Math.exp(x[r * D + j] - max);
      x[r * D + j] = e;
      sum += e;
    }
    for (let j = 0; j < D; j++) x[r * D + j] /= sum;
  }
  return x;
}

/**
 * posteriors: (Kc x D) for content frames [contentOffset, contentOffset + Kc) of the clip; totalContent: the clip's
 * content frame count (frames past it are outside the clip). melIndex: per animation frame. -> (F x W x D).
 */
export function contentWindows(posteriors: Float32Array, melIndex: ArrayLike<number>, m: ModelConstants, contentOffset = 0, totalContent?: number): Float32Array {
  const D = m.content_classes;
  const W = m.window;
  const Kc = posteriors.length / D;
  const total = totalContent ?? contentOffset + Kc;
  const out = new Float32Array(melIndex.length * W * D);
  for (let f = 0; f < melIndex.length; f++) {
    const c = Math.floor(melIndex[f] / m.content_stride);
    for (let w = 0; w < W; w++) {
      const idx = c + w - (W - 1 - m.window_future);
      if (idx < 0 || idx >= total) continue;
      const local = idx - contentOffset;
      if (local < 0 || local >= Kc) throw new RangeError(`content frame ${idx} is not in the computed range [${contentOffset}, ${contentOffset + Kc})`);
      out.set(posteriors.subarray(local * D, local * D + D), (f * W + w) * D);
    }
  }
  return out;
}
