/**
 * The browser's inference path, stage by stage, against the tensors PyTorch computed for the same clip
 * (models/fixtures, written by the exporter): Mel (meyda), content windows, the ONNX encoders on
 * onnxruntime-node, the TypeScript GAVA decoder, and the posed vertices.
 */
import { describe, expect, it, beforeAll } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import * as ort from 'onnxruntime-node';
import { checkManifest, frameToMelIndex, type Manifest } from '../../src/model/manifest';
import { parseSafetensors, f32, type Tensor } from '../../src/model/safetensors';
import { logMel, logMelFrames, logMelFramesMeyda, melFrameCount } from '../../src/audio/mel';
import { contentWindows, softmaxRows } from '../../src/model/windows';
import { ReferenceDecoder, applyPose, decoderWeights, gelu } from '../../src/attention/reference';
import { FastDecoder, geluInPlace, matmulRows } from '../../src/attention/fast-decoder';
import { jsKernel, SimdKernel } from '../../src/attention/decoder-kernels';
import { assemble, generatedSource, KERNELS } from '../../scripts/build-wasm';
import { decodeTemplate } from '../../src/template/face-template';

const MODELS = resolve(import.meta.dirname, '../..', process.env.MODELS_DIR ?? 'models');
const ROOT = resolve(import.meta.dirname, '../..');
const buf = (p: string) => {
  const b = readFileSync(resolve(MODELS, p));
  return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer;
};

let manifest: Manifest;
let fx: Map<string, Tensor>;
const maxAbsDiff = (a: ArrayLike<number>, b: ArrayLike<number>) => {
  expect(a.length).toBe(b.length);
  let m = 0;
  for (let i = 0; i < a.length; i++) m = Math.max(m, Math.abs(a[i] - b[i]));
  return m;
};

beforeAll(() => {
  manifest = checkManifest(JSON.parse(readFileSync(resolve(MODELS, 'manifest.json'), 'utf8')));
  fx = parseSafetensors(buf(manifest.fixtures.file)).tensors;
});

async function run(file: string, feeds: Record<string, ort.Tensor>): Promise<Record<string, ort.Tensor>> {
  const s = await ort.InferenceSession.create(resolve(MODELS, file));
  return s.run(feeds) as Promise<Record<string, ort.Tensor>>;
}

describe('TypeScript + onnxruntime-node vs the PyTorch fixture', () => {
  it('log-Mel with meyda matches Python', () => {
    const mel = logMel(f32(fx, 'audio'), manifest.audio);
    expect(maxAbsDiff(mel, f32(fx, 'mel'))).toBeLessThan(1e-4);
  });

  it('the fast log-Mel equals Meyda.extract, on speech, loud noise, silence and a streaming offset', () => {
    const a = manifest.audio;
    const speech = f32(fx, 'audio');
    let seed = 1;
    const noise = Float32Array.from({ length: 8000 }, () => ((seed = (seed * 16807) % 2147483647) / 2147483647 - 0.5) * 2);
    for (const x of [speech, noise, new Float32Array(3000)]) {
      const K = melFrameCount(x.length, a);
      const fast = logMelFrames(x, a, 0, K);
      const meyda = logMelFramesMeyda(x, a, 0, K);
      let rel = 0;
      for (let i = 0; i < fast.length; i++) rel = Math.max(rel, Math.abs(fast[i] - meyda[i]) / Math.max(1, Math.abs(meyda[i])));
      expect(rel).toBeLessThan(1e-6);
    }
    // A window of the signal with its offset gives the same frames as the whole signal.
    const part = logMelFrames(speech.subarray(3000, 6000), a, 25, 5, undefined, 3000, speech.length);
    expect(maxAbsDiff(part, logMelFrames(speech, a, 25, 5))).toBe(0);
  });

  it('frame -> Mel index and the content windows match', () => {
    const melIndex = fx.get('mel_index')!.data as BigInt64Array;
    for (let i = 0; i < melIndex.length; i++) expect(frameToMelIndex(i, manifest.audio)).toBe(Number(melIndex[i]));
    const post = softmaxRows(f32(fx, 'content_logits').slice(), manifest.model.config.content_classes);
    const win = contentWindows(post, Array.from(melIndex, Number), manifest.model.config);
    expect(maxAbsDiff(win, f32(fx, 'windows'))).toBeLessThan(1e-6);
  });

  it('the ONNX encoders on onnxruntime-node match PyTorch within 1e-5 (logits: and 1e-6 of their scale)', async () => {
    const m = manifest.model.config;
    const mel = f32(fx, 'mel');
    const K = mel.length / manifest.audio.n_mels;
    const melT = new ort.Tensor('float32', mel, [1, K, manifest.audio.n_mels]);
    const logits = (await run(manifest.files.content_encoder, { mel: melT })).logits.data as Float32Array;
    // Logits reach about 50: float32 carries 4e-6 there, so the bound grows with the tensor's scale (1e-6 of it).
    const ref = f32(fx, 'content_logits');
    expect(maxAbsDiff(logits, ref)).toBeLessThan(1e-5 + 1e-6 * ref.reduce((s, v) => Math.max(s, Math.abs(v)), 0));
    const win = f32(fx, 'windows');
    const F = win.length / (m.window * m.content_classes);
    const tokens = (await run(manifest.files.hierarchical, { windows: new ort.Tensor('float32', win, [F, m.window, m.content_classes]) })).tokens.data as Float32Array;
    const want = f32(fx, 'tokens');
    expect(maxAbsDiff(tokens.subarray(0, want.length), want)).toBeLessThan(1e-5);
    const conv = (await run(manifest.files.pose_conv, { mel: melT })).conv;
    expect(maxAbsDiff(conv.data as Float32Array, f32(fx, 'pose_conv'))).toBeLessThan(1e-5);
    const z = new ort.Tensor('float32', new Float32Array(m.pose_channels), [1, 1, m.pose_channels]);
    const pf = (await run(manifest.files.pose_lstm, { conv, h0: z, c0: z })).pose_features.data as Float32Array;
    expect(maxAbsDiff(pf, f32(fx, 'pose_features'))).toBeLessThan(1e-5);
  });

  it('the TypeScript GAVA decoder matches PyTorch layer by layer, and the posed vertices', async () => {
    const m = manifest.model.config;
    const template = await decodeTemplate(JSON.parse(readFileSync(resolve(MODELS, manifest.template.path), 'utf8')), buf(manifest.template.path.replace('.json', '.bin')));
    const weights = decoderWeights(parseSafetensors(buf(manifest.files.decoder_weights)).tensors, m);
    const dec = new ReferenceDecoder(weights, template.adjacency, m);
    const frames = manifest.fixtures.token_frames;
    const layers: Float32Array[] = [];
    const poseTok = f32(fx, 'pose_token');
    const out = dec.decode(f32(fx, 'tokens'), poseTok, frames, layers);
    for (let i = 0; i < m.layers; i++) {
      const want = f32(fx, `layer${i}`);
      expect(maxAbsDiff(layers[i], want.subarray(0, layers[i].length))).toBeLessThan(1e-4);
    }
    const wantOffsets = f32(fx, 'offsets').subarray(0, out.offsets.length);
    expect(maxAbsDiff(out.offsets, wantOffsets)).toBeLessThan(1e-4);
    expect(maxAbsDiff(out.pose, f32(fx, 'pose').subarray(0, out.pose.length))).toBeLessThan(1e-5);
    const y = applyPose(f32(fx, 'template_mm'), out.offsets, out.pose, frames);
    expect(maxAbsDiff(y, f32(fx, 'vertices').subarray(0, y.length))).toBeLessThan(1e-3); // mm: 1e-4 of the template's cm
  });

  it.each(['js', 'wasm-simd'] as const)('the fast CPU decoder (%s arithmetic) matches PyTorch and the reference decoder', async (kernel) => {
    const m = manifest.model.config;
    const template = await decodeTemplate(JSON.parse(readFileSync(resolve(MODELS, manifest.template.path), 'utf8')), buf(manifest.template.path.replace('.json', '.bin')));
    const weights = decoderWeights(parseSafetensors(buf(manifest.files.decoder_weights)).tensors, m);
    const frames = manifest.fixtures.token_frames;
    const tokens = f32(fx, 'tokens'), poseTok = f32(fx, 'pose_token');
    const decoder = new FastDecoder(weights, template.adjacency, m, kernel);
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

  it('the engine\'s default CPU decoder here is the SIMD one', async () => {
    const m = manifest.model.config;
    const template = await decodeTemplate(JSON.parse(readFileSync(resolve(MODELS, manifest.template.path), 'utf8')), buf(manifest.template.path.replace('.json', '.bin')));
    const weights = decoderWeights(parseSafetensors(buf(manifest.files.decoder_weights)).tensors, m);
    expect(new FastDecoder(weights, template.adjacency, m).kernelName).toBe('wasm-simd');
  });
});

describe('attention maps (the paper\'s Fig. 7 and Fig. 10)', () => {
  it('the reference decoder\'s attention weights equal PyTorch\'s, for every layer', async () => {
    const m = manifest.model.config;
    const template = await decodeTemplate(JSON.parse(readFileSync(resolve(MODELS, manifest.template.path), 'utf8')), buf(manifest.template.path.replace('.json', '.bin')));
    const weights = decoderWeights(parseSafetensors(buf(manifest.files.decoder_weights)).tensors, m);
    const dec = new ReferenceDecoder(weights, template.adjacency, m);
    const n = template.vertexCount;
    for (let layer = 0; layer < m.layers; layer++) {
      const maps = dec.attention(f32(fx, 'tokens'), f32(fx, 'pose_token'), layer);
      expect(maxAbsDiff(maps.poseToken, f32(fx, `attention_pose${layer}`))).toBeLessThan(1e-5);
      const table = f32(fx, `attention_vertex${layer}`);
      const K = table.length / n;
      let worst = 0;
      for (let j = 0; j < n; j++) {
        let sum = 0;
        for (let s = 0; s < maps.keyStart[j + 1] - maps.keyStart[j]; s++) {
          worst = Math.max(worst, Math.abs(maps.vertexWeights[maps.keyStart[j] + s] - table[j * K + s]));
          sum += maps.vertexWeights[maps.keyStart[j] + s];
        }
        expect(sum).toBeCloseTo(1, 5);
      }
      expect(worst).toBeLessThan(1e-5);
    }
  });
});

describe('the fast decoder\'s kernels', () => {
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

  it('the SIMD kernel\'s operations equal the TypeScript kernel\'s, for every remainder', () => {
    const simd = new SimdKernel(1 << 20);
    const wave = (n: number, f: number, a = 1) => Float32Array.from({ length: n }, (_, i) => a * Math.sin(i * f + 0.3));
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
      jsKernel.layerNorm(X, 5, d, g, bb, want);
      const got = simd.alloc(5 * d);
      simd.layerNorm(simd.place(X), 5, d, simd.place(g), simd.place(bb), got);
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
    // Residual sums, with a remainder after the vectors.
    const x = wave(23, 0.3), y = wave(23, 0.8);
    const sx = simd.place(x);
    simd.add(sx, simd.place(y), 23);
    jsKernel.add(x, y, 23);
    expect(maxAbsDiff(sx, x)).toBe(0);
  });

  it('the SIMD attention equals the TypeScript attention on ragged key lists, large and small scores', () => {
    const simd = new SimdKernel(1 << 20);
    for (const [d, heads, amp] of [[32, 4, 1], [16, 1, 1], [32, 2, 40]]) {
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

  it('the embedded WebAssembly is what the committed .wat assembles to (npm run build:wasm)', async () => {
    for (const k of KERNELS) {
      const bytes = await assemble(k.wat);
      expect(readFileSync(resolve(ROOT, k.out), 'utf8')).toBe(generatedSource(k.wat, bytes));
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
