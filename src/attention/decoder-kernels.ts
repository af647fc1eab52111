/**
 * The arithmetic of the fast CPU decoder (fast-decoder.ts), twice: in TypeScript (jsKernel) and in
 * WebAssembly SIMD (SimdKernel in simd-kernel.ts, simd/decoder.wat, four float lanes). The decoder is written once
 * against the DecoderKernel interface and runs on either; tests hold both to the readable
 * ReferenceDecoder and to PyTorch.
 *
 * A kernel owns the storage the decoder works in. For SIMD that is one WebAssembly memory, sized
 * once up front (growing it would detach every view), holding the weights (transposed, so four
 * consecutive outputs are one vector load), the key lists, the GELU table and the buffers.
 */

/** A weight matrix (outs x cols, row-major) and bias, in the layout a kernel wants. */
export interface PackedWeight {
  readonly outs: number;
  readonly cols: number;
  readonly w: Float32Array;
  readonly b: Float32Array;
}

export interface DecoderKernel {
  /** 'wasm-simd' or 'js'. */
  readonly name: string;
  /** Float32 storage this kernel can read and write (zeros). */
  alloc(length: number): Float32Array;
  /** A copy of `values` where this kernel can read it. */
  place(values: Float32Array): Float32Array;
  placeInts(values: Int32Array): Int32Array;
  /** Scratch for attention scores, `length` the longest key list: float64 each (the SIMD kernel's: 16 bytes each, four heads' float32 scores). */
  scratch(length: number): Float64Array;
  pack(W: Float32Array, b: Float32Array, outs: number, cols: number): PackedWeight;
  /** out[t, o] = b[o] + sum_i W[o, i] X[t, i] for t < rows (rows even for SIMD). */
  matmul(w: PackedWeight, X: Float32Array, rows: number, out: Float32Array): void;
  layerNorm(X: Float32Array, rows: number, d: number, g: Float32Array, b: Float32Array, out: Float32Array, eps: number): void;
  attention(qkv: Float32Array, tokens: number, d: number, heads: number, keyStart: Int32Array, keyIndex: Int32Array,
    scores: Float64Array, out: Float32Array): void;
  gelu(a: Float32Array, count: number): void;
  /** x[i] += y[i] for i < count */
  add(x: Float32Array, y: Float32Array, count: number): void;
  /** out[r, i] = x[r, i] + row[i] for r < rows, i < d: `row` added to every row of x. */
  addRow(x: Float32Array, row: Float32Array, rows: number, d: number, out: Float32Array): void;
}

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
export function layerNormRows(X: Float32Array, rows: number, d: number, g: Float32Array, b: Float32Array, out: Float32Array, eps: number): void {
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
    const inv = 1 / Math.sqrt(v / d + eps);
    for (let i = 0; i < d; i++) out[o + i] = (X[o + i] - mean) * inv * g[i] + b[i];
  }
}

// GELU table: x/2 (1 + erf(x / sqrt 2)) and its derivative at GELU_STEPS points per unit on [-GELU_RANGE, GELU_RANGE].
export const GELU_RANGE = 8;
export const GELU_STEPS = 128;
const SIZE = 2 * GELU_RANGE * GELU_STEPS + 1;
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

/** The table (built once). */
export function geluTableData(): { value: Float64Array; slope: Float64Array } {
  if (geluTable) return geluTable;
  const value = new Float64Array(SIZE);
  const slope = new Float64Array(SIZE);
  for (let i = 0; i < SIZE; i++) {
    const x = -GELU_RANGE + i / GELU_STEPS;
    const cdf = 0.5 * (1 + erfDouble(x * Math.SQRT1_2));
    const pdf = Math.exp(-0.5 * x * x) / Math.sqrt(2 * Math.PI);
    value[i] = x * cdf;
    slope[i] = (cdf + x * pdf) / GELU_STEPS; // derivative per table step
  }
  return (geluTable = { value, slope });
}

/** GELU in place over a[0..count): table lookup with cubic Hermite interpolation. */
export function geluInPlace(a: Float32Array, count: number): void {
  const tab = geluTableData();
  const { value, slope } = tab;
  for (let i = 0; i < count; i++) {
    const x = a[i];
    if (x >= GELU_RANGE) continue; // gelu(x) = x to float precision
    if (x <= -GELU_RANGE) {
      a[i] = 0;
      continue;
    }
    const u = (x + GELU_RANGE) * GELU_STEPS;
    const k = Math.floor(u);
    const s = u - k;
    const s2 = s * s, s3 = s2 * s;
    a[i] = (2 * s3 - 3 * s2 + 1) * value[k] + (s3 - 2 * s2 + s) * slope[k] + (3 * s2 - 2 * s3) * value[k + 1] + (s3 - s2) * slope[k + 1];
  }
}

/**
 * Neighbour-masked multi-head attention: qkv rows (tokens x 3d: queries, keys, values); token t
 * attends to keys keyIndex[keyStart[t] .. keyStart[t + 1]); per head softmax(q.k / sqrt(dk)) times
 * the values, into out (tokens x d). `scores`: scratch for the longest key list.
 */
export function attentionRows(qkv: Float32Array, tokens: number, d: number, heads: number, keyStart: Int32Array,
  keyIndex: Int32Array, scores: Float64Array, out: Float32Array): void {
  const dk = d / heads;
  const d3 = 3 * d;
  const scale = 1 / Math.sqrt(dk);
  for (let t = 0; t < tokens; t++) {
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
      for (let i = 0; i < dk; i++) out[ao + i] = 0;
      const inv = 1 / sum;
      for (let s = k0; s < k1; s++) {
        const w = scores[s - k0] * inv;
        const vo = keyIndex[s] * d3 + 2 * d + hd * dk;
        for (let i = 0; i < dk; i++) out[ao + i] += w * qkv[vo + i];
      }
    }
  }
}

/** The TypeScript kernel: ordinary arrays, weights as they are. */
export const jsKernel: DecoderKernel = {
  name: 'js',
  alloc: (length) => new Float32Array(length),
  place: (values) => values,
  placeInts: (values) => values,
  scratch: (length) => new Float64Array(length),
  pack: (W, b, outs, cols) => ({ outs, cols, w: W, b }),
  matmul: (p, X, rows, out) => matmulRows(p.w, p.b, p.outs, p.cols, X, rows, out),
  layerNorm: layerNormRows,
  attention: attentionRows,
  gelu: geluInPlace,
  add: (x, y, count) => {
    for (let i = 0; i < count; i++) x[i] += y[i];
  },
  addRow: addRowTo,
};

/** out[r, i] = x[r, i] + row[i] for r < rows, i < d. */
export function addRowTo(x: Float32Array, row: Float32Array, rows: number, d: number, out: Float32Array): void {
  for (let r = 0; r < rows; r++) {
    const o = r * d;
    for (let i = 0; i < d; i++) out[o + i] = x[o + i] + row[i];
  }
}
