/** The SIMD kernel (src/attention/simd-kernel.ts) against the TypeScript kernel (decoder-kernels.ts), and the committed wasm against its .wat. */
import { describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { gelu } from '../../../src/attention/reference';
import { jsKernel } from '../../../src/attention/decoder-kernels';
import { SimdKernel } from '../../../src/attention/simd-kernel';
import { assemble, generatedSource, KERNELS } from '../../../scripts/build-wasm';
import { ROOT, maxAbsDiff } from '../helpers/exported';

const wave = (n: number, f: number, a = 1) => Float32Array.from({ length: n }, (_, i) => a * Math.sin(i * f + 0.3));

describe('the SIMD kernel', () => {
  it('the SIMD kernel\'s operations equal the TypeScript kernel\'s, for every remainder', () => {
    const simd = new SimdKernel(1 << 20);
    // Matrix products: outputs in 16s and 4s (and not a multiple of 4: the TypeScript product), odd column counts.
    for (const [rows, outs, cols] of [[2, 4, 1], [2, 16, 5], [4, 20, 7], [6, 36, 32], [2, 6, 8], [470, 96, 32]]) {
      const W = wave(outs * cols, 1.3), b = wave(outs, 0.9);
      const X = wave(rows * cols, 0.7);
      const want = new Float32Array(rows * outs);
      jsKernel.matmul(jsKernel.pack(W, b, outs, cols), X, rows, want);
      const got = simd.alloc(rows * outs);
      simd.matmul(simd.pack(W, b, outs, cols), simd.place(X), rows, got);
      expect(maxAbsDiff(got, want)).toBeLessThan(1e-5 * cols);
    }
    expect(() => simd.matmul(simd.pack(wave(16, 1), wave(4, 1), 4, 4), simd.alloc(12), 3, simd.alloc(12))).toThrow(/even/);
    expect(() => simd.matmul(simd.pack(wave(16, 1), wave(4, 1), 4, 4), new Float32Array(8), 2, simd.alloc(8))).toThrow(/not allocated/);
    // LayerNorm: float32 vectors where d is a multiple of 4, else float64 exactly as the TypeScript kernel.
    for (const d of [4, 7, 32]) {
      const X = wave(5 * d, 0.41, 3), g = wave(d, 0.2), bb = wave(d, 0.5);
      const want = new Float32Array(5 * d);
      jsKernel.layerNorm(X, 5, d, g, bb, want, 1e-5);
      const got = simd.alloc(5 * d);
      simd.layerNorm(simd.place(X), 5, d, simd.place(g), simd.place(bb), got, 1e-5);
      if (d % 4) expect(maxAbsDiff(got, want)).toBe(0);
      else expect(maxAbsDiff(got, want)).toBeLessThan(2e-6);
    }
    // GELU: vectors with the A&S erf (the reference decoder's formula) and the table for the remainder.
    const xs = Float32Array.from({ length: 20003 }, (_, i) => -10 + i / 1000);
    const got = simd.place(xs);
    simd.gelu(got, got.length - 1); // 20,002 values: the last two of them by the table, the very last untouched
    let worst = 0;
    for (let i = 0; i < xs.length - 1; i++) worst = Math.max(worst, Math.abs(got[i] - gelu(xs[i])) / Math.max(1, Math.abs(xs[i])));
    expect(worst).toBeLessThan(2e-7);
    expect(got[xs.length - 1]).toBe(xs[xs.length - 1]);
    const tail = xs.slice(20000, 20002);
    jsKernel.gelu(tail, 2);
    expect(Array.from(got.subarray(20000, 20002))).toEqual(Array.from(tail));
    // Eight values a turn (two vectors interleaved) give the bits that four a turn give: each vector of four on its own.
    const one = simd.alloc(4);
    for (let i = 0; i + 4 <= 20000; i += 4) {
      one.set(xs.subarray(i, i + 4));
      simd.gelu(one, 4);
      if (one.some((v, j) => v !== got[i + j])) throw new Error(`GELU at ${i}: four a turn ${Array.from(one)}, eight ${Array.from(got.subarray(i, i + 4))}`);
    }
    // Residual sums, with a remainder after the vectors.
    const x = wave(23, 0.3), y = wave(23, 0.8);
    const sx = simd.place(x);
    simd.add(sx, simd.place(y), 23);
    jsKernel.add(x, y, 23);
    expect(maxAbsDiff(sx, x)).toBe(0);
    // One row added to every row (the vertex tokens' a): vectors where d is a multiple of 4, else the TypeScript loop;
    // the same bits either way, and no row past `rows` written.
    for (const [rows, d] of [[468, 32], [3, 8], [5, 7]]) {
      const X = wave(rows * d, 0.37, 2), row = wave(d, 0.91);
      const want = new Float32Array(rows * d + d);
      jsKernel.addRow(X, row, rows, d, want);
      const got = simd.alloc(rows * d + d);
      simd.addRow(simd.place(X), simd.place(row), rows, d, got);
      expect(maxAbsDiff(got, want)).toBe(0);
      expect(want[rows * d + 1]).toBe(0);
      expect(got[rows * d + 1]).toBe(0);
      expect(want[d + 1]).toBe(Math.fround(X[d + 1] + row[1]));
    }
  });

  it.each([true, false])('the SIMD attention (fused multiply-adds: %s) equals the TypeScript attention on ragged key lists, large and small scores', (fma) => {
    const simd = new SimdKernel(1 << 20, fma);
    expect(simd.fusedMultiplyAdd).toBe(fma);
    // d 32 in 4 heads: the model's shape, which runs attention_d32h4 (all heads of a key at once); the others the general attention.
    for (const [d, heads, amp] of [[32, 4, 1], [32, 4, 40], [16, 1, 1], [32, 2, 40]]) {
      const tokens = 9;
      const keyStart = Int32Array.from([0, 1, 3, 6, 6 + 9, 16, 18, 20, 23, 24]); // one token sees all 9
      const keys = Int32Array.from([0, 1, 0, 2, 5, 8, 0, 1, 2, 3, 4, 5, 6, 7, 8, 4, 5, 3, 6, 2, 7, 1, 4, 8]);
      const qkv = Float32Array.from({ length: tokens * 3 * d }, (_, i) => amp * Math.sin(i * 0.37));
      const want = new Float32Array(tokens * d);
      jsKernel.attention(qkv, tokens, d, heads, keyStart, keys, new Float64Array(tokens), want);
      const got = simd.alloc(tokens * d);
      simd.attention(simd.place(qkv), tokens, d, heads, simd.placeInts(keyStart), simd.placeInts(keys), simd.scratch(tokens), got);
      expect(maxAbsDiff(got, want)).toBeLessThan(1e-5 * amp);
    }
  });

  it('fuses its matrix products, GELU and attention where relaxed SIMD is there (vitest runs Node with it), and they equal the plain ones', () => {
    const fused = new SimdKernel(1 << 20);
    const plain = new SimdKernel(1 << 20, false);
    expect([fused.fusedMultiplyAdd, plain.fusedMultiplyAdd]).toEqual([true, false]);
    for (const [rows, outs, cols] of [[2, 4, 3], [4, 20, 7], [470, 96, 32], [470, 32, 64]]) {
      const W = wave(outs * cols, 1.3), b = wave(outs, 0.9), X = wave(rows * cols, 0.7);
      const [a, c] = [fused, plain].map((k) => {
        const out = k.alloc(rows * outs);
        k.matmul(k.pack(W, b, outs, cols), k.place(X), rows, out);
        return out;
      });
      expect(maxAbsDiff(a, c)).toBeLessThan(1e-6 * cols);
    }
    const xs = Float32Array.from({ length: 4003 }, (_, i) => -10 + i / 200);
    const [a, c] = [fused, plain].map((k) => {
      const out = k.place(xs);
      k.gelu(out, out.length);
      return out;
    });
    expect(maxAbsDiff(a, c)).toBeLessThan(1e-6);
    expect(maxAbsDiff(a, c)).toBeGreaterThan(0); // the fused GELU is not the plain one
    // and the model's attention (attention_d32h4): fused, not the plain one, and as near
    const tokens = 5, d = 32;
    const keyStart = Int32Array.from([0, 2, 4, 7, 9, 14]);
    const keys = Int32Array.from([0, 1, 1, 2, 2, 3, 0, 3, 4, 4, 0, 1, 2, 3]);
    const qkv = Float32Array.from({ length: tokens * 3 * d }, (_, i) => 3 * Math.sin(i * 0.37));
    const [p, q] = [fused, plain].map((k) => {
      const out = k.alloc(tokens * d);
      k.attention(k.place(qkv), tokens, d, 4, k.placeInts(keyStart), k.placeInts(keys), k.scratch(tokens), out);
      return out;
    });
    expect(maxAbsDiff(p, q)).toBeLessThan(1e-5);
    expect(maxAbsDiff(p, q)).toBeGreaterThan(0);
  });

  it('the embedded WebAssembly is what the committed .wat assembles to (npm run build:wasm)', async () => {
    for (const k of KERNELS) {
      const bytes = await assemble(k);
      expect(readFileSync(resolve(ROOT, k.out), 'utf8')).toBe(generatedSource(k, bytes));
    }
  });
});
