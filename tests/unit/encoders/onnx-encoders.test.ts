/** The exported ONNX encoders (content, hierarchical, pose conv + LSTM) on onnxruntime-node against PyTorch's fixture tensors. */
import { describe, expect, it } from 'vitest';
import * as ort from 'onnxruntime-node';
import type { Manifest } from '../../../src/model/manifest';
import { f32, type Tensor } from '../../../src/model/safetensors';
import { loadFixtures, loadManifest, maxAbsDiff, runOnnx } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);

describe('the ONNX encoders vs the PyTorch fixture', () => {
  it('the ONNX encoders on onnxruntime-node match PyTorch within 1e-5 (logits: and 1e-6 of their scale)', async () => {
    const m = manifest.model.config;
    const mel = f32(fx, 'mel');
    const K = mel.length / manifest.audio.n_mels;
    const melT = new ort.Tensor('float32', mel, [1, K, manifest.audio.n_mels]);
    const logits = (await runOnnx(manifest.files.content_encoder, { mel: melT })).logits.data as Float32Array;
    // Logits reach about 50: float32 carries 4e-6 there, so the bound grows with the tensor's scale (1e-6 of it).
    const ref = f32(fx, 'content_logits');
    expect(maxAbsDiff(logits, ref)).toBeLessThan(1e-5 + 1e-6 * ref.reduce((s, v) => Math.max(s, Math.abs(v)), 0));
    const win = f32(fx, 'windows');
    const F = win.length / (m.window * m.content_classes);
    const latents = (await runOnnx(manifest.files.hierarchical, { windows: new ort.Tensor('float32', win, [F, m.window, m.content_classes]) })).latents.data as Float32Array;
    expect(latents.length).toBe(F * 2 * m.d_model);
    expect(maxAbsDiff(latents, f32(fx, 'hierarchical_latents'))).toBeLessThan(1e-5);
    const conv = (await runOnnx(manifest.files.pose_conv, { mel: melT })).conv;
    expect(maxAbsDiff(conv.data as Float32Array, f32(fx, 'pose_conv'))).toBeLessThan(1e-5);
    const z = new ort.Tensor('float32', new Float32Array(m.pose_channels), [1, 1, m.pose_channels]);
    const pf = (await runOnnx(manifest.files.pose_lstm, { conv, h0: z, c0: z })).pose_features.data as Float32Array;
    expect(maxAbsDiff(pf, f32(fx, 'pose_features'))).toBeLessThan(1e-5);
  });
});
