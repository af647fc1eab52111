import { test, expect } from './fixtures';

/**
 * The WGSL GAVA decoder in headless Chromium (WebGPU on SwiftShader, software but exact) against the
 * TypeScript reference and against PyTorch, on the exporter's fixture tokens (dev/parity.html).
 */
test('WGSL decoder = TypeScript reference = fast CPU decoder (WebAssembly SIMD and TypeScript) = PyTorch, and the whole engine = PyTorch', async ({ page }) => {
  await page.goto('/dev/parity.html');
  const result = await page.waitForFunction(() => (globalThis as unknown as { parityResult?: unknown }).parityResult, null, { timeout: 60_000 });
  const r = (await result.jsonValue()) as Record<string, number | boolean | string | { architecture: string } | null>;
  expect(r.error, String(r.error)).toBeUndefined();
  expect((r.adapter as { architecture: string }).architecture).toBe('swiftshader');
  expect(r.gpuVsCpuOffsets as number).toBeLessThan(1e-4);
  expect(r.gpuVsCpuPose as number).toBeLessThan(1e-5);
  expect(r.gpuLatentsVsCpuOffsets as number, 'the vertex tokens made on the GPU').toBeLessThan(1e-5);
  expect(r.gpuLatentsVsCpuPose as number, 'the vertex tokens made on the GPU').toBeLessThan(1e-5);
  expect(r.gpuVsTorchOffsets as number).toBeLessThan(1e-4);
  expect(r.simdFusedMultiplyAdd, 'Chromium has relaxed SIMD: the SIMD decoder below fuses its matrix products, GELU and attention').toBe(true);
  for (const kernel of ['wasm-simd', 'js']) {
    expect(r[`fast_${kernel}_VsCpuOffsets`] as number, `fast decoder, ${kernel}`).toBeLessThan(1e-4);
    expect(r[`fast_${kernel}_VsCpuPose`] as number, `fast decoder, ${kernel}`).toBeLessThan(1e-5);
    expect(r[`fast_${kernel}_TokensVsTorch`] as number, `vertex tokens of the latents, ${kernel}`).toBeLessThan(1e-5);
  }
  expect(r.cpuVsTorchOffsets as number).toBeLessThan(1e-4);
  expect(r.cpuVsTorchPose as number).toBeLessThan(1e-5);
  expect(r.gpuRepeatable).toBe(true);
  // The ONNX encoders on onnxruntime-web, wasm and webgpu execution providers, against PyTorch.
  const encoders = r.encoders as unknown as Record<string, Record<string, number>>;
  expect(Object.keys(encoders).sort()).toEqual(['wasm', 'webgpu']);
  for (const [provider, row] of Object.entries(encoders)) {
    expect(row.provider_used, provider).toBe(1);
    for (const stage of ['content', 'hierarchical', 'pose_conv', 'pose_lstm']) expect(row[stage], `${provider} ${stage}`).toBeLessThan(1e-4);
  }
  // The whole engine against PyTorch's final vertices (template units: cm), chunked = whole, WebGPU = CPU.
  expect(r.engineFrames).toBe(18);
  expect(r.engineCpuThreads, 'the CPU decoder ran on its worker pool (2 cores)').toBe(2);
  expect(r.engineCpuKernel, 'the workers decode in WebAssembly SIMD').toBe('wasm-simd');
  expect(r.engineCpuVsTorch as number).toBeLessThan(1e-4);
  expect(r.engineChunkedVsWhole as number).toBeLessThan(1e-5);
  expect(r.engineGpuVsCpu as number).toBeLessThan(1e-5);
  expect(r.engineBackend).toBe('webgpu');
  // Streaming = offline; frames come out before the stream ends, each waiting for at most 150 ms of audio.
  expect(r.streamFrames).toBe(18);
  expect(r.streamFramesBeforeEnd as number).toBeGreaterThan(0);
  expect(r.streamVsOffline as number).toBeLessThan(1e-5);
  expect(r.streamLookAheadMs as number).toBeLessThanOrEqual(150);
});
