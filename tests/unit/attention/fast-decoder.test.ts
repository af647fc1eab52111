/** The fast CPU decoder (src/attention/fast-decoder.ts) against PyTorch and the reference decoder, with each arithmetic kernel. */
import { describe, expect, it } from 'vitest';
import type { Manifest } from '../../../src/model/manifest';
import { f32 } from '../../../src/model/safetensors';
import { ReferenceDecoder, gelu, vertexTokens } from '../../../src/attention/reference';
import { FastDecoder, geluInPlace, matmulRows } from '../../../src/attention/fast-decoder';
import { loadDecoderWeights, loadFixtures, loadManifest, loadTemplateFile, maxAbsDiff } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);

/** The exported model's decoder on `kernel`, with what the tests feed it. */
async function exportedDecoder(kernel: 'js' | 'wasm-simd') {
  const m = manifest.model.config;
  const template = await loadTemplateFile(manifest);
  const weights = loadDecoderWeights(manifest);
  const decoder = new FastDecoder(weights, template.adjacency, m, kernel);
  return { m, template, weights, decoder, frames: manifest.fixtures.token_frames, poseTok: f32(fx, 'pose_token') };
}

describe('the fast decoder vs the PyTorch fixture', () => {
  it.each(['js', 'wasm-simd'] as const)('the fast CPU decoder (%s arithmetic) matches PyTorch and the reference decoder', async (kernel) => {
    const { m, template, weights, decoder, frames, poseTok } = await exportedDecoder(kernel);
    const tokens = f32(fx, 'tokens');
    expect(decoder.kernelName).toBe(kernel);
    const fast = decoder.decode(tokens, poseTok, frames);
    const ref = new ReferenceDecoder(weights, template.adjacency, m).decode(tokens, poseTok, frames);
    expect(maxAbsDiff(fast.offsets, f32(fx, 'offsets').subarray(0, fast.offsets.length))).toBeLessThan(1e-4);
    expect(maxAbsDiff(fast.pose, f32(fx, 'pose').subarray(0, fast.pose.length))).toBeLessThan(1e-5);
    expect(maxAbsDiff(fast.offsets, ref.offsets)).toBeLessThan(1e-4);
    expect(maxAbsDiff(fast.pose, ref.pose)).toBeLessThan(1e-5);
    // Decoding again reuses the buffers: the same numbers.
    expect(maxAbsDiff(decoder.decode(tokens, poseTok, frames).offsets, fast.offsets)).toBe(0);
  });

  it.each(['js', 'wasm-simd'] as const)('the fast decoder (%s) makes the vertex tokens of the hierarchical latents as PyTorch and the reference do', async (kernel) => {
    const { m, template, weights, decoder, frames, poseTok } = await exportedDecoder(kernel);
    const latents = f32(fx, 'hierarchical_latents');
    const tokens = decoder.vertexTokens(latents, frames);
    const scale = f32(fx, 'tokens').reduce((s, v) => Math.max(s, Math.abs(v)), 0);
    expect(scale).toBeGreaterThan(0.1);
    expect(maxAbsDiff(tokens, f32(fx, 'tokens'))).toBeLessThan(1e-5 * Math.max(1, scale));
    expect(maxAbsDiff(tokens, vertexTokens(weights, latents, frames, m.d_model))).toBeLessThan(1e-5 * Math.max(1, scale));
    // decodeLatents is decode of those tokens, to the bit, and matches PyTorch's every frame of the clip
    const all = manifest.fixtures.frames;
    const fromLatents = decoder.decodeLatents(latents, poseTok, all);
    const fromTokens = decoder.decode(decoder.vertexTokens(latents, all), poseTok, all);
    expect(maxAbsDiff(fromLatents.offsets, fromTokens.offsets)).toBe(0);
    expect(maxAbsDiff(fromLatents.pose, fromTokens.pose)).toBe(0);
    expect(maxAbsDiff(fromLatents.offsets, f32(fx, 'offsets'))).toBeLessThan(1e-4);
    expect(maxAbsDiff(fromLatents.pose, f32(fx, 'pose'))).toBeLessThan(1e-5);
    // weights of another mesh: tokens still decode, latents are refused with the reason
    const other = { ...weights, vertexEmbedding: weights.vertexEmbedding.subarray(0, 10 * m.d_model) };
    const mismatched = new FastDecoder(other, template.adjacency, m, kernel);
    expect(maxAbsDiff(mismatched.decode(f32(fx, 'tokens'), poseTok, frames).offsets, decoder.decode(f32(fx, 'tokens'), poseTok, frames).offsets)).toBe(0);
    expect(() => mismatched.decodeLatents(latents, poseTok, frames)).toThrow(`10 vertices, the template ${template.adjacency.offsets.length - 1}`);
  });

  it('refuses arrays shorter than the frames asked for, naming the short one (they decoded NaN)', async () => {
    const { m, template, weights, decoder, frames, poseTok } = await exportedDecoder('js');
    const tokens = f32(fx, 'tokens');
    const latents = f32(fx, 'hierarchical_latents');
    const d = m.d_model;
    expect(() => decoder.decode(tokens, poseTok, frames + 1)).toThrow(/FastDecoder.decode: tokens holds \d+ floats, fewer than 3 frames/);
    expect(() => decoder.decodeLatents(latents.subarray(0, 2 * 2 * d), poseTok, 3)).toThrow(/decodeLatents: latents holds 128 floats, fewer than 3 frames of 64/);
    expect(() => decoder.decodeLatents(latents, poseTok.subarray(0, d), 2)).toThrow(/poseToken holds 32 floats/);
    expect(() => decoder.decodeLatents(latents, poseTok, 1.5)).toThrow(/frames must be a whole number/);
    expect(() => new ReferenceDecoder(weights, template.adjacency, m).decode(tokens, poseTok, frames + 1)).toThrow(/ReferenceDecoder.decode: tokens/);
    expect(Array.from(decoder.decodeLatents(latents, poseTok, 2).pose).every(Number.isFinite)).toBe(true);
  });

  it('the engine\'s default CPU decoder here is the SIMD one', async () => {
    const m = manifest.model.config;
    const template = await loadTemplateFile(manifest);
    const weights = loadDecoderWeights(manifest);
    expect(new FastDecoder(weights, template.adjacency, m).kernelName).toBe('wasm-simd');
  });
});

describe('the fast decoder\'s arithmetic', () => {
  it('blocked matrix product equals the plain sum for every remainder of rows and outputs', () => {
    for (const [rows, outs, cols] of [[1, 1, 3], [2, 4, 5], [3, 6, 7], [5, 9, 16], [8, 3, 32]]) {
      const W = Float32Array.from({ length: outs * cols }, (_, i) => Math.sin(i * 1.3));
      const b = Float32Array.from({ length: outs }, (_, i) => i - 1.5);
      const X = Float32Array.from({ length: rows * cols }, (_, i) => Math.cos(i * 0.7));
      const out = new Float32Array(rows * outs);
      matmulRows(W, b, outs, cols, X, rows, out);
      for (let t = 0; t < rows; t++)
        for (let o = 0; o < outs; o++) {
          let s = b[o];
          for (let i = 0; i < cols; i++) s += W[o * cols + i] * X[t * cols + i];
          expect(out[t * outs + o]).toBeCloseTo(s, 5);
        }
    }
  });

  it('tabulated GELU equals the erf formula everywhere, including the tails', () => {
    const xs = Float32Array.from({ length: 20001 }, (_, i) => -10 + i / 1000);
    const got = xs.slice();
    geluInPlace(got, got.length);
    let worst = 0;
    for (let i = 0; i < xs.length; i++) worst = Math.max(worst, Math.abs(got[i] - gelu(xs[i])));
    expect(worst).toBeLessThan(5e-7); // the reference's own erf is good to 1.5e-7
  });
});
