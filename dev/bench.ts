/**
 * Benchmark page (dev/bench.html), driven by scripts/bench.ts in headless Chromium. Measures the engine
 * on this machine and leaves the figures in globalThis.benchResult; nothing here asserts a speed.
 */
import { TalkingFaceEngine, type Backend } from '../src/engine/engine';
import { decodeAudio } from '../src/audio/decode';
import { ReferenceDecoder } from '../src/attention/reference';
import { FastDecoder } from '../src/attention/fast-decoder';
import { fmaModule } from '../src/attention/simd-kernel';
import { GpuDecoder } from '../src/attention/gpu-decoder';
import { requestSharedDevice, detectWebGPU, isHardwareAdapter } from '../src/gpu/capabilities';
import { buildAdjacency } from '../src/template/mesh-topology';
import { renderBench } from './render-bench';

const now = () => performance.now();
const heap = () => (performance as unknown as { memory?: { usedJSHeapSize: number } }).memory?.usedJSHeapSize ?? 0;

/** The speech fixture repeated to `seconds` (real speech, so every stage does real work). */
function speechOf(seconds: number, clip: Float32Array, rate: number): Float32Array {
  const out = new Float32Array(Math.round(seconds * rate));
  for (let i = 0; i < out.length; i += clip.length) out.set(clip.subarray(0, Math.min(clip.length, out.length - i)), i);
  return out;
}

/** A triangulated grid (rows x cols) plus `extra` lone vertices: an N-vertex mesh for scaling the attention. */
function gridAdjacency(rows: number, cols: number, extra: number) {
  const tris: number[] = [];
  for (let r = 0; r + 1 < rows; r++)
    for (let c = 0; c + 1 < cols; c++) {
      const a = r * cols + c;
      tris.push(a, a + 1, a + cols + 1, a, a + cols + 1, a + cols);
    }
  return buildAdjacency(rows * cols + extra, Uint32Array.from(tris));
}

async function run(wavBytes: ArrayBuffer, backends: Backend[], clipSeconds: number[], renderOnly: boolean): Promise<Record<string, unknown>> {
  const result: Record<string, unknown> = { userAgent: navigator.userAgent, crossOriginIsolated };
  const gpu = await detectWebGPU();
  result.adapter = gpu.info;

  let t = now();
  // The CPU decoder first; the encoders' providers as 'auto' would choose them ('cpu' alone keeps them on WebAssembly
  // even where the webgpu rows below run on a hardware GPU).
  const engine = await TalkingFaceEngine.load({ backend: 'cpu', onnxProviders: isHardwareAdapter(gpu) ? ['webgpu', 'wasm'] : ['wasm'] });
  result.model_load_ms = now() - t;
  // What loading the engine fetched (this page's own requests; the decoder workers' scripts are not seen here), and
  // which onnxruntime build: the plain WebAssembly one unless the WebGPU provider is used (issue 18).
  const fetched = (performance.getEntriesByType('resource') as PerformanceResourceTiming[]).filter((r) => r.startTime >= t);
  result.model_load_files = Object.fromEntries(fetched.map((r) => [new URL(r.name).pathname, { transfer_bytes: r.transferSize, body_bytes: r.decodedBodySize }]));
  result.model_load_transfer_bytes = fetched.reduce((sum, r) => sum + r.transferSize, 0);
  result.ort_build = fetched.some((r) => r.name.includes('.jsep.')) ? 'jsep' : 'wasm';
  const rate = engine.manifest.audio.sample_rate;
  const wav = await decodeAudio(wavBytes, rate);
  // The head on screen (dev/render-bench.ts): 3 s of speech drawn frame by frame. After the timed rows, so that the
  // first of them (the "cold" one) is the first clip animated after loading, as its name says.
  const render = async () => (result.render = await renderBench(engine, speechOf(3, wav.samples, rate)));
  if (renderOnly) {
    await render();
    return result;
  }
  result.cpu_decoder_threads = engine.cpuThreads;
  result.cpu_decoder_kernel = engine.cpuKernel;
  result.cpu_decoder_fma = fmaModule() !== null; // its matrix products and GELU fused (relaxed SIMD)
  const bytes = await Promise.all(engine.manifest.runtime_files.map(async (k) => (await fetch(`/models/${engine.manifest.files[k]}`)).arrayBuffer()));
  result.model_bytes = bytes.reduce((s, b) => s + b.byteLength, 0);

  const stages: Record<string, unknown> = {};
  for (const backend of backends) {
    if (backend === 'webgpu' && !gpu.adapter) continue;
    await engine.setBackend(backend);
    // The first clip after loading pays for compiling (JIT in the page and the decoder workers, shader
    // pipelines): run it as its own "cold" row; the timed rows after it are the steady state.
    for (let seconds of [0, ...clipSeconds]) {
      const cold = seconds === 0;
      if (cold) seconds = backend === 'cpu' ? clipSeconds[0] : 2; // (a software GPU only needs its pipelines compiled)
      if (backend === 'webgpu' && seconds > 10 && gpu.info?.isFallbackAdapter) continue; // software GPU: 10 s is enough to report
      const audio = speechOf(seconds, wav.samples, rate);
      engine.resetTimes();
      let first = -1;
      let peak = heap();
      t = now();
      await engine.animate(audio, {
        keep: false,
        onFrames: () => {
          if (first < 0) first = now() - t;
          peak = Math.max(peak, heap());
        },
      });
      const wall = now() - t;
      const name = `${backend}_${seconds}s${cold ? '_cold' : ''}`;
      stages[name] = { wall_ms: wall, rtf: seconds / (wall / 1000), first_frame_ms: first, peak_heap_bytes: peak, stages_ms: { ...engine.times } };
      result[`rtf_${backend === 'webgpu' ? 'webgpu' : 'cpu'}_${seconds}s${cold ? '_cold' : ''}`] = seconds / (wall / 1000);
      if (backend === 'cpu' && cold) result.first_frame_ms = first; // what a visitor waits for on the first clip
    }
  }
  result.runs = stages;
  await engine.setBackend('cpu'); // the engine as loaded
  await render();

  // Decode time per frame against the vertex count (decoder weights do not depend on N).
  const m = engine.manifest.model.config;
  const weights = engine.decoderWeights;
  const meshes: Record<string, ReturnType<typeof gridAdjacency>> = {
    '468': engine.template.adjacency,
    '1790': gridAdjacency(34, 52, 22),
    '5023': gridAdjacency(31, 162, 1),
  };
  const scaling: Record<string, unknown> = {};
  for (const [label, adjacency] of Object.entries(meshes)) {
    const n = adjacency.offsets.length - 1;
    const frames = 8;
    const tokens = Float32Array.from({ length: frames * n * m.d_model }, (_, i) => Math.sin(i * 0.37));
    const poseTok = Float32Array.from({ length: frames * m.d_model }, (_, i) => Math.cos(i * 0.11));
    const row: Record<string, number> = {};
    for (const [key, kernel] of [['cpu_ms_per_frame', 'wasm-simd'], ['cpu_js_ms_per_frame', 'js']] as const) {
      const fast = new FastDecoder(weights, adjacency, m, kernel);
      fast.decode(tokens, poseTok, 1); // warm-up: let the JIT compile the kernels
      // The median of five batches: one batch's time moved by half between runs on a shared machine.
      const times = Array.from({ length: 5 }, () => {
        t = now();
        fast.decode(tokens, poseTok, frames);
        return (now() - t) / frames;
      }).sort((a, b) => a - b);
      row[key] = times[2];
    }
    const reference = new ReferenceDecoder(weights, adjacency, m);
    t = now();
    reference.decode(tokens, poseTok, Math.min(frames, 2));
    row.reference_ms_per_frame = (now() - t) / Math.min(frames, 2);
    if (gpu.adapter && backends.includes('webgpu')) {
      const dec = new GpuDecoder(await requestSharedDevice(), weights, adjacency, m, frames);
      await dec.decode(tokens, poseTok, frames); // warm-up: pipeline compilation
      t = now();
      await dec.decode(tokens, poseTok, frames);
      row.webgpu_ms_per_frame = (now() - t) / frames;
      dec.destroy();
    }
    scaling[label] = row;
  }
  result.attention_by_vertices = scaling;

  // Streaming: 16 ms pieces (what the capture worklet delivers) pushed at real-time pace. Latency, as
  // StreamSession measures it: from the arrival of the sample at a frame's instant to the frame's
  // emission (look-ahead + piece size + processing).
  await engine.setBackend('cpu');
  const audio = speechOf(6, wav.samples, rate);
  const piece = Math.round(rate * 0.016);
  const stream = engine.createStream(() => undefined);
  const startWall = now();
  for (let i = 0; i < audio.length; i += piece) {
    const due = startWall + ((i + piece) / rate) * 1000; // a piece can be pushed once its last sample exists
    const wait = due - now();
    if (wait > 0) await new Promise((r) => setTimeout(r, wait));
    await stream.push(audio.subarray(i, i + piece));
  }
  const lat = stream.latency;
  await stream.end();
  result.stream_look_ahead_ms = stream.lookAheadMs;
  result.stream_piece_ms = (piece / rate) * 1000;
  result.stream_latency_ms = lat.p50Ms;
  result.stream_latency_p95_ms = lat.p95Ms;
  // Past the look-ahead: the frame's sample waiting for the rest of its piece (up to one piece), and processing.
  result.stream_beyond_look_ahead_p50_ms = lat.p50Ms - stream.lookAheadMs;
  return result;
}

/** Called by scripts/bench.ts with a speech recording (base64 WAV). */
Object.assign(globalThis, {
  runBench: async (wavBase64: string, backends: Backend[], seconds: number[], renderOnly = false) => {
    const bytes = Uint8Array.from(atob(wavBase64), (c) => c.charCodeAt(0));
    try {
      return await run(bytes.buffer, backends, seconds, renderOnly);
    } catch (e) {
      return { error: (e as Error).message, stack: (e as Error).stack };
    }
  },
});
document.body.dataset.ready = 'true';
