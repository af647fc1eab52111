/**
 * Test page (dev/parity.html, loaded by tests/e2e/engine-parity.spec.ts): runs the TypeScript reference
 * decoder, the fast CPU decoder and the WGSL decoder on the exporter's fixture tokens and reports their differences from
 * each other and from PyTorch. Not part of the app.
 */
import { checkManifest, DEFAULT_MANIFEST_URL } from '../src/model/manifest';
import { parseSafetensors, f32 } from '../src/model/safetensors';
import { MM_PER_UNIT, loadTemplate } from '../src/template/face-template';
import { ReferenceDecoder, decoderWeights, vertexTokens } from '../src/attention/reference';
import { FastDecoder } from '../src/attention/fast-decoder';
import { fmaModule } from '../src/attention/simd-kernel';
import { GpuDecoder } from '../src/attention/gpu-decoder';
import { detectWebGPU, requestSharedDevice } from '../src/gpu/capabilities';
import { TalkingFaceEngine } from '../src/engine/engine';
import { OnnxModel, type ExecutionProvider } from '../src/encoders/onnx-model';
import { specOf } from '../src/encoders/onnx-spec';

const maxAbsDiff = (a: ArrayLike<number>, b: ArrayLike<number>) => {
  let m = 0;
  for (let i = 0; i < a.length; i++) m = Math.max(m, Math.abs(a[i] - b[i]));
  return m;
};

async function main() {
  const manifest = checkManifest(await (await fetch(DEFAULT_MANIFEST_URL)).json());
  const bin = async (f: string) => (await fetch(`/models/${f}`)).arrayBuffer();
  const fx = parseSafetensors(await bin(manifest.fixtures.file)).tensors;
  const template = await loadTemplate(`/models/${manifest.template.path}`);
  const m = manifest.model.config;
  const weights = decoderWeights(parseSafetensors(await bin(manifest.files.decoder_weights)).tensors, m, manifest.model.layer_norm_eps);
  const frames = manifest.fixtures.token_frames;
  const tokens = f32(fx, 'tokens');
  const poseTok = f32(fx, 'pose_token').subarray(0, frames * m.d_model);
  const cpu = new ReferenceDecoder(weights, template.adjacency, m).decode(tokens, poseTok, frames);
  const gpu = await detectWebGPU();
  const result: Record<string, unknown> = { adapter: gpu.info, frames };
  if (gpu.adapter) {
    const device = await requestSharedDevice();
    const dec = new GpuDecoder(device, weights, template.adjacency, m, 8);
    const g = await dec.decode(tokens, poseTok, frames);
    result.gpuVsCpuOffsets = maxAbsDiff(g.offsets, cpu.offsets);
    result.gpuVsCpuPose = maxAbsDiff(g.pose, cpu.pose);
    result.gpuVsTorchOffsets = maxAbsDiff(g.offsets, f32(fx, 'offsets'));
    // A second call reuses the buffers: same answer.
    const again = await dec.decode(tokens, poseTok, frames);
    result.gpuRepeatable = maxAbsDiff(again.offsets, g.offsets) === 0;
    // From the hierarchical latents, the vertex tokens made on the GPU: against the reference decoder on the
    // reference's tokens of the same latents
    const latents = f32(fx, 'hierarchical_latents').subarray(0, frames * 2 * m.d_model);
    const fromLatents = await dec.decodeLatents(latents, poseTok, frames);
    const cpuFromLatents = new ReferenceDecoder(weights, template.adjacency, m).decode(vertexTokens(weights, latents, frames, m.d_model), poseTok, frames);
    result.gpuLatentsVsCpuOffsets = maxAbsDiff(fromLatents.offsets, cpuFromLatents.offsets);
    result.gpuLatentsVsCpuPose = maxAbsDiff(fromLatents.pose, cpuFromLatents.pose);
    dec.destroy();
  }
  result.simdFusedMultiplyAdd = fmaModule() !== null; // the SIMD decoder's matrix products, GELU and attention fused (relaxed SIMD)
  for (const kernel of ['wasm-simd', 'js'] as const) {
    const decoder = new FastDecoder(weights, template.adjacency, m, kernel);
    const fast = decoder.decode(tokens, poseTok, frames);
    result[`fast_${kernel}_VsCpuOffsets`] = maxAbsDiff(fast.offsets, cpu.offsets);
    result[`fast_${kernel}_VsCpuPose`] = maxAbsDiff(fast.pose, cpu.pose);
    // the vertex tokens the decoder makes of the hierarchical latents, against PyTorch's
    result[`fast_${kernel}_TokensVsTorch`] = maxAbsDiff(decoder.vertexTokens(f32(fx, 'hierarchical_latents'), frames), tokens);
  }
  result.cpuVsTorchOffsets = maxAbsDiff(cpu.offsets, f32(fx, 'offsets'));

  // The ONNX encoders on onnxruntime-web, on each execution provider, against PyTorch.
  const providers: ExecutionProvider[] = gpu.adapter ? ['wasm', 'webgpu'] : ['wasm'];
  const encoders: Record<string, Record<string, number>> = {};
  const mel = f32(fx, 'mel');
  const K = mel.length / manifest.audio.n_mels;
  const win = f32(fx, 'windows');
  const F = win.length / (m.window * m.content_classes);
  for (const provider of providers) {
    const session = async (key: string) => OnnxModel.create(specOf(manifest, key, await bin(manifest.files[key])), [provider]);
    const content = await session('content_encoder');
    const hier = await session('hierarchical');
    const conv = await session('pose_conv');
    const lstm = await session('pose_lstm');
    const row: Record<string, number> = {};
    row.content = maxAbsDiff((await content.run({ mel: { data: mel, shape: [1, K, manifest.audio.n_mels] } })).logits.data, f32(fx, 'content_logits'));
    const latents = (await hier.run({ windows: { data: win, shape: [F, m.window, m.content_classes] } })).latents.data;
    row.hierarchical = maxAbsDiff(latents, f32(fx, 'hierarchical_latents'));
    const convOut = (await conv.run({ mel: { data: mel, shape: [1, K, manifest.audio.n_mels] } })).conv;
    row.pose_conv = maxAbsDiff(convOut.data, f32(fx, 'pose_conv'));
    const zero = new Float32Array(m.pose_channels);
    const pf = (await lstm.run({ conv: { data: convOut.data, shape: [1, K, m.pose_channels] }, h0: { data: zero, shape: [1, 1, m.pose_channels] }, c0: { data: zero, shape: [1, 1, m.pose_channels] } })).pose_features.data;
    row.pose_lstm = maxAbsDiff(pf, f32(fx, 'pose_features'));
    row.provider_used = content.provider === provider ? 1 : 0;
    encoders[provider] = row;
    for (const s of [content, hier, conv, lstm]) await s.release();
  }
  result.encoders = encoders;
  result.cpuVsTorchPose = maxAbsDiff(cpu.pose, f32(fx, 'pose'));

  // The whole engine (meyda Mel, ONNX encoders on onnxruntime-web, decoder, posing) on the fixture clip,
  // against PyTorch's vertices, in the template's units; in one chunk and in chunks of 5 frames.
  const audio = f32(fx, 'audio');
  const mmPerUnit = MM_PER_UNIT[template.units];
  // With the head's own motion (seed 0, the engine's default) and the lip closure when the model has them: PyTorch
  // drew the same residuals and closed the same lips.
  const torchVertices = Float32Array.from(f32(fx, fx.has('vertices_sampled') ? 'vertices_sampled' : 'vertices'), (v) => v / mmPerUnit);
  const engine = await TalkingFaceEngine.load({ backend: 'cpu', onnxProviders: ['wasm'] });
  const whole = await engine.animate(audio);
  const chunked = await engine.animate(audio, { chunkFrames: 5 });
  result.engineFrames = whole.frames;
  result.engineCpuThreads = engine.cpuThreads;
  result.engineCpuKernel = engine.cpuKernel;
  result.engineCpuVsTorch = maxAbsDiff(whole.vertices, torchVertices);
  result.engineChunkedVsWhole = maxAbsDiff(chunked.vertices, whole.vertices);

  // Streaming: the same audio pushed in irregular pieces gives the same frames as the offline animation.
  const streamed = new Float32Array(whole.vertices.length);
  let emitted = 0;
  const stream = engine.createStream((first, frames) => {
    streamed.set(frames.vertices, first * template.vertexCount * 3);
    emitted += frames.count;
  });
  const pieces = [1234, 128, 4000, 77, 3000];
  for (let i = 0, k = 0; i < audio.length; k++) {
    const size = pieces[k % pieces.length];
    await stream.push(audio.subarray(i, i + size));
    i += size;
  }
  const beforeEnd = emitted;
  await stream.end();
  result.streamFrames = emitted;
  result.streamFramesBeforeEnd = beforeEnd;
  result.streamVsOffline = maxAbsDiff(streamed, whole.vertices);
  result.streamLookAheadMs = stream.lookAheadMs;
  if (gpu.adapter) {
    await engine.setBackend('webgpu');
    const g = await engine.animate(audio, { chunkFrames: 7 });
    result.engineGpuVsCpu = maxAbsDiff(g.vertices, whole.vertices);
    result.engineBackend = engine.backend;
  }
  Object.assign(globalThis, { parityResult: result });
  document.getElementById('status')!.textContent = JSON.stringify(result);
}

main().catch((e: Error) => {
  Object.assign(globalThis, { parityResult: { error: e.message } });
  document.getElementById('status')!.textContent = `error: ${e.message}`;
});
