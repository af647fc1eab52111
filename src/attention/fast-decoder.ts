/**
 * The GAVA decoder on the CPU, written for speed: the engine's CPU backend.
 *
 * Same layers and numbers as ReferenceDecoder (reference.ts, the readable version the tests hold
 * it to), computed differently:
 * - every projection is one matrix product over all N + 1 tokens of a frame, blocked 2 tokens x 4
 *   outputs so each weight and input load feeds several multiply-adds (about 3x the per-element loop);
 * - the keys each token attends to are one precomputed list (self first, then the 1-ring; the pose
 *   token: every token), no per-key closures;
 * - GELU reads a table of the exact function with cubic Hermite interpolation (error < 1e-9), not
 *   an erf with an exp per element;
 * - buffers are allocated once.
 */
import type { ModelConstants } from '../model/manifest';
import type { Adjacency } from '../template/mesh-topology';
import { keyLists, type DecodeResult, type DecoderWeights } from './reference';

const LN_EPS = 1e-5;

/** out[t, o] = b[o] + sum_i W[o, i] X[t, i] for t < rows: W (outs x cols) row-major, X and out row-major. */
export function matmulRows(W: Float32Array, b: Float32Array, outs: number, cols: number, X: Float32Array, rows: number, out: Float32Array): void {
  const outs4 = outs - (outs % 4);
  let t = 0;
  for (; t + 1 < rows; t += 2) {
    const x0 = t * cols, x1 = x0 + cols, o0 = t * outs, o1 = o0 + outs;
    let o = 0;
    for (; o < outs4; o += 4) {
      let a0 = b[o], a1 = b[o + 1], a2 = b[o + 2], a3 = b[o + 3];
      let c0 = a0, c1 = a1, c2 = a2, c3 = a3;
      const w0 = o * cols, w1 = w0 + cols, w2 = w1 + cols, w3 = w2 + cols;
      for (let i = 0; i < cols; i++) {
        const p = X[x0 + i], q = X[x1 + i];
        const u0 = W[w0 + i], u1 = W[w1 + i], u2 = W[w2 + i], u3 = W[w3 + i];
        a0 += u0 * p; a1 += u1 * p; a2 += u2 * p; a3 += u3 * p;
        c0 += u0 * q; c1 += u1 * q; c2 += u2 * q; c3 += u3 * q;
      }
      out[o0 + o] = a0; out[o0 + o + 1] = a1; out[o0 + o + 2] = a2; out[o0 + o + 3] = a3;
      out[o1 + o] = c0; out[o1 + o + 1] = c1; out[o1 + o + 2] = c2; out[o1 + o + 3] = c3;
    }
    for (; o < outs; o++) {
      let a = b[o], c = b[o];
      const w = o * cols;
      for (let i = 0; i < cols; i++) {
        a += W[w + i] * X[x0 + i];
        c += W[w + i] * X[x1 + i];
      }
      out[o0 + o] = a;
      out[o1 + o] = c;
    }
  }
  for (; t < rows; t++) {
    const x0 = t * cols, o0 = t * outs;
    for (let o = 0; o < outs; o++) {
      let a = b[o];
      const w = o * cols;
      for (let i = 0; i < cols; i++) a += W[w + i] * X[x0 + i];
      out[o0 + o] = a;
    }
  }
}

/** Row-wise LayerNorm of X (rows x d) into out. */
function layerNormRows(X: Float32Array, rows: number, d: number, g: Float32Array, b: Float32Array, out: Float32Array): void {
  for (let t = 0; t < rows; t++) {
    const o = t * d;
    let mean = 0;
    for (let i = 0; i < d; i++) mean += X[o + i];
    mean /= d;
    let v = 0;
    for (let i = 0; i < d; i++) {
      const c = X[o + i] - mean;
      v += c * c;
    }
    const inv = 1 / Math.sqrt(v / d + LN_EPS);
    for (let i = 0; i < d; i++) out[o + i] = (X[o + i] - mean) * inv * g[i] + b[i];
  }
}

// GELU table: x/2 (1 + erf(x / sqrt 2)) and its derivative at STEPS points per unit on [-RANGE, RANGE].
const RANGE = 8;
const STEPS = 128;
const SIZE = 2 * RANGE * STEPS + 1;
let geluTable: { value: Float64Array; slope: Float64Array } | null = null;

/** erf to double precision (W. J. Cody's rational approximations, as in most libm's). */
function erfDouble(x: number): number {
  // Series for small |x|, continued fraction via erfc for large: both to ~1e-15.
  const a = Math.abs(x);
  if (a < 2.5) {
    let sum = a, term = a;
    const x2 = a * a;
    for (let k = 1; k < 60; k++) {
      term *= -x2 / k;
      const add = term / (2 * k + 1);
      sum += add;
      if (Math.abs(add) < 1e-17 * Math.abs(sum)) break;
    }
    return Math.sign(x) * (2 / Math.sqrt(Math.PI)) * sum;
  }
  // erfc(a) = exp(-a^2)/sqrt(pi) * 1/(a + 1/2/(a + 1/(a + 3/2/(a + 2/(a + ...)))))
  let f = a;
  for (let k = 60; k >= 1; k--) f = a + (k / 2) / f;
  const erfc = Math.exp(-a * a) / Math.sqrt(Math.PI) / f;
  return Math.sign(x) * (1 - erfc);
}

function buildGeluTable(): { value: Float64Array; slope: Float64Array } {
  const value = new Float64Array(SIZE);
  const slope = new Float64Array(SIZE);
  for (let i = 0; i < SIZE; i++) {
    const x = -RANGE + i / STEPS;
    const cdf = 0.5 * (1 + erfDouble(x * Math.SQRT1_2));
    const pdf = Math.exp(-0.5 * x * x) / Math.sqrt(2 * Math.PI);
    value[i] = x * cdf;
    slope[i] = (cdf + x * pdf) / STEPS; // derivative per table step
  }
  return { value, slope };
}

/** GELU in place over a[0..count): table lookup with cubic Hermite interpolation. */
export function geluInPlace(a: Float32Array, count: number): void {
  const tab = (geluTable ??= buildGeluTable());
  const { value, slope } = tab;
  for (let i = 0; i < count; i++) {
    const x = a[i];
    if (x >= RANGE) continue; // gelu(x) = x to float precision
    if (x <= -RANGE) {
      a[i] = 0;
      continue;
    }
    const u = (x + RANGE) * STEPS;
    const k = Math.floor(u);
    const s = u - k;
    const s2 = s * s, s3 = s2 * s;
    a[i] = (2 * s3 - 3 * s2 + 1) * value[k] + (s3 - 2 * s2 + s) * slope[k] + (3 * s2 - 2 * s3) * value[k + 1] + (s3 - s2) * slope[k + 1];
  }
}

export class FastDecoder {
  readonly n: number;
  private readonly d: number;
  private readonly tokens: number;
  private readonly x: Float32Array;
  private readonly h: Float32Array;
  private readonly qkv: Float32Array;
  private readonly attn: Float32Array;
  private readonly hidden: Float32Array;
  private readonly scores: Float64Array;
  private readonly keyStart: Int32Array; // token t attends to keys keyIndex[keyStart[t] .. keyStart[t + 1])
  private readonly keyIndex: Int32Array;
  private readonly raw = new Float32Array(6);

  constructor(
    readonly weights: DecoderWeights,
    readonly adjacency: Adjacency,
    readonly m: ModelConstants,
  ) {
    const n = adjacency.offsets.length - 1;
    this.n = n;
    this.d = m.d_model;
    const T = n + 1;
    this.tokens = T;
    this.x = new Float32Array(T * this.d);
    this.h = new Float32Array(T * this.d);
    this.qkv = new Float32Array(T * 3 * this.d);
    this.attn = new Float32Array(T * this.d);
    this.hidden = new Float32Array(T * m.ffn);
    this.scores = new Float64Array(T);
    const lists = keyLists(adjacency, true);
    this.keyStart = lists.keyStart;
    this.keyIndex = lists.keys;
  }

  /** tokens (F x N x d), poseToken (F x d) -> displacement (F x N x 3, mm) and pose (F x 6) per frame. */
  decode(tokens: Float32Array, poseToken: Float32Array, frames: number): DecodeResult {
    const { n, d } = this;
    const offsets = new Float32Array(frames * n * 3);
    const pose = new Float32Array(frames * 6);
    for (let f = 0; f < frames; f++) {
      this.x.set(tokens.subarray(f * n * d, (f + 1) * n * d), 0);
      this.x.set(poseToken.subarray(f * d, (f + 1) * d), n * d);
      for (const L of this.weights.layers) this.layer(L);
      this.heads(offsets, pose, f);
    }
    return { offsets, pose };
  }

  private layer(L: DecoderWeights['layers'][number]): void {
    const { d, x, h, qkv, attn, hidden, scores, keyStart, keyIndex } = this;
    const T = this.tokens;
    const ffn = this.m.ffn;
    const heads = this.m.heads;
    const dk = d / heads;
    const d3 = 3 * d;
    const scale = 1 / Math.sqrt(dk);
    layerNormRows(x, T, d, L.ln1g, L.ln1b, h);
    matmulRows(L.qkvW, L.qkvB, d3, d, h, T, qkv);
    for (let t = 0; t < T; t++) {
      const k0 = keyStart[t], k1 = keyStart[t + 1];
      for (let hd = 0; hd < heads; hd++) {
        const qo = t * d3 + hd * dk;
        let max = -Infinity;
        for (let s = k0; s < k1; s++) {
          const ko = keyIndex[s] * d3 + d + hd * dk;
          let dot = 0;
          for (let i = 0; i < dk; i++) dot += qkv[qo + i] * qkv[ko + i];
          dot *= scale;
          scores[s - k0] = dot;
          if (dot > max) max = dot;
        }
        let sum = 0;
        for (let s = 0; s < k1 - k0; s++) {
          const e = Math.exp(scores[s] - max);
          scores[s] = e;
          sum += e;
        }
        const ao = t * d + hd * dk;
        for (let i = 0; i < dk; i++) attn[ao + i] = 0;
        const inv = 1 / sum;
        for (let s = k0; s < k1; s++) {
          const w = scores[s - k0] * inv;
          const vo = keyIndex[s] * d3 + 2 * d + hd * dk;
          for (let i = 0; i < dk; i++) attn[ao + i] += w * qkv[vo + i];
        }
      }
    }
    matmulRows(L.outW, L.outB, d, d, attn, T, h);
    for (let i = 0; i < T * d; i++) x[i] += h[i];
    layerNormRows(x, T, d, L.ln2g, L.ln2b, h);
    matmulRows(L.ffn1W, L.ffn1B, ffn, d, h, T, hidden);
    geluInPlace(hidden, T * ffn);
    matmulRows(L.ffn2W, L.ffn2B, d, ffn, hidden, T, attn);
    for (let i = 0; i < T * d; i++) x[i] += attn[i];
  }

  private heads(offsets: Float32Array, pose: Float32Array, f: number): void {
    const { n, d, x, h, raw } = this;
    const w = this.weights;
    layerNormRows(x, this.tokens, d, w.lnG, w.lnB, h);
    matmulRows(w.dispW, w.dispB, 3, d, h, n, offsets.subarray(f * n * 3, (f + 1) * n * 3));
    matmulRows(w.poseW, w.poseB, 6, d, h.subarray(n * d), 1, raw);
    for (let i = 0; i < 3; i++) pose[f * 6 + i] = this.m.max_rotation * Math.tanh(raw[i]);
    for (let i = 3; i < 6; i++) pose[f * 6 + i] = this.m.max_translation_mm * Math.tanh(raw[i]);
  }
}
