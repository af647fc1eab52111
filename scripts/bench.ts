/**
 * npm run bench: the engine's speed and memory on this machine, in headless Chromium.
 * Builds the app, serves it, measures the demo's first load (bytes per file, time to ready: scripts/first-load.ts),
 * opens dev/bench.html, and writes docs/results/bench.json plus a table.
 * WebGPU here is SwiftShader (software): its figures are reported, not GPU figures.
 *
 *   npm run bench [-- OPTIONS]    (npm run bench -- --help lists them: USAGE below)
 */
import { chromium } from '@playwright/test';
import { execSync } from 'node:child_process';
import { existsSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { CHROMIUM_ARGS } from '../playwright.config';
import { checkManifest } from '../src/model/manifest';
import { parseSafetensors } from '../src/model/safetensors';
import { decodeTemplate } from '../src/template/face-template';
import { ReferenceDecoder, decoderWeights } from '../src/attention/reference';
import { FastDecoder } from '../src/attention/fast-decoder';
import { logMelFrames, logMelFramesMeyda, melFrameCount } from '../src/audio/mel';
import { StreamResampler } from '../src/audio/resample';
import { SPEECH, readWav16 } from '../tests/e2e/helpers/audio';
import { measureFirstLoad, measureOnnxAlone, printFirstLoad, type FirstLoad } from './first-load';
import { measureLiveDisplay, printLiveDisplay, type LiveDisplay } from './live-display';
import { envPort, portFree, positiveNumbers, readOptions, startServer, usageError, within } from './script-cli';

const ROOT = resolve(import.meta.dirname, '..');
const USAGE = `npm run bench [-- OPTIONS]   the engine's speed and memory in headless Chromium -> docs/results/bench.json
  --seconds 10,60          clip lengths to time (seconds, above 0)
  --backends cpu,webgpu    decoders to time (cpu, webgpu)
  --render-only            only the head's render benchmark, merged into the existing bench.json
  --first-load-only        the first load alone, and onnxruntime alone, printed; nothing written
  --first-load-url URL     with --first-load-only: of a page served elsewhere (e.g. an older build)
  --live-only              the demo live (fake microphone) on a 1x and a 2x screen, printed; nothing written
  --live-url URL           with --live-only: of a demo served elsewhere (e.g. an older build)
  --node-only              the Node part alone (Mel, CPU decoders), printed; nothing written
  --out FILE               write FILE instead of docs/results/bench.json (e.g. a reduced run's)
  BENCH_PORT=N             serve the build on port N (default 4191; it must be free)`;
const o = readOptions('bench', USAGE, {
  seconds: { type: 'string', default: '10,60' }, backends: { type: 'string', default: 'cpu,webgpu' }, 'render-only': { type: 'boolean' },
  'first-load-only': { type: 'boolean' }, 'first-load-url': { type: 'string' }, 'node-only': { type: 'boolean' },
  'live-only': { type: 'boolean' }, 'live-url': { type: 'string' }, out: { type: 'string' },
});
const OUT = resolve(ROOT, String(o.out ?? 'docs/results/bench.json'));
if (!existsSync(dirname(OUT))) usageError('bench', USAGE, `--out ${o.out}: the folder ${dirname(OUT)} does not exist`);
if (o['render-only'] && !existsSync(OUT)) usageError('bench', USAGE, `--render-only merges into ${OUT}, which does not exist: run the whole bench first`);
const seconds = positiveNumbers(String(o.seconds)) ?? usageError('bench', USAGE, `--seconds takes clip lengths above 0, such as 10,60 (not ${o.seconds})`);
const backends = String(o.backends).split(',');
if (!backends.every((b) => b === 'cpu' || b === 'webgpu')) usageError('bench', USAGE, `--backends takes cpu and/or webgpu (not ${o.backends})`);
const PORT = envPort('bench', USAGE, 'BENCH_PORT', 4191);
const renderOnly = Boolean(o['render-only']);
const firstLoadOnly = Boolean(o['first-load-only']);
if (o['first-load-url'] && !firstLoadOnly) usageError('bench', USAGE, '--first-load-url goes with --first-load-only (another page\'s figures are not written into bench.json)');
const liveOnly = Boolean(o['live-only']);
if (o['live-url'] && !liveOnly) usageError('bench', USAGE, '--live-url goes with --live-only (another page\'s figures are not written into bench.json)');
if ([renderOnly, firstLoadOnly, liveOnly].filter(Boolean).length > 1) usageError('bench', USAGE, '--render-only, --first-load-only and --live-only each run one part: give one');

/** The machine as the figures were taken: the load average says how busy it was (other work slows every figure here). */
async function machineState(t0: number): Promise<Record<string, unknown>> {
  const os = await import('node:os');
  return { cores: os.cpus().length, load_average: os.loadavg(), bench_seconds: (Date.now() - t0) / 1000, date: new Date().toISOString() };
}

/** The parts of the engine that run the same in Node (no Web Audio, no WebGPU): Mel and the CPU decoders. */
async function nodeBench(): Promise<Record<string, number | string>> {
  const models = resolve(ROOT, 'models');
  const bytes = (p: string) => {
    const b = readFileSync(resolve(models, p));
    return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer;
  };
  const manifest = checkManifest(JSON.parse(readFileSync(resolve(models, 'manifest.json'), 'utf8')));
  const template = await decodeTemplate(JSON.parse(readFileSync(resolve(models, manifest.template.path), 'utf8')), bytes(manifest.template.path.replace('.json', '.bin')));
  const m = manifest.model.config;
  const weights = decoderWeights(parseSafetensors(bytes(manifest.files.decoder_weights)).tensors, m, manifest.model.layer_norm_eps);
  const samples = readWav16(SPEECH);
  const seconds = samples.length / manifest.audio.sample_rate;
  const time = (fn: () => void, reps = 3) => {
    fn();
    const t = performance.now();
    for (let i = 0; i < reps; i++) fn();
    return (performance.now() - t) / reps;
  };
  const K = melFrameCount(samples.length, manifest.audio);
  const frames = 30;
  const n = template.vertexCount;
  const tokens = Float32Array.from({ length: frames * n * m.d_model }, (_, i) => Math.sin(i * 0.37));
  const poseTok = Float32Array.from({ length: frames * m.d_model }, (_, i) => Math.cos(i * 0.11));
  const latents = Float32Array.from({ length: frames * 2 * m.d_model }, (_, i) => Math.sin(i * 0.53));
  const fast = new FastDecoder(weights, template.adjacency, m);
  const fastJs = new FastDecoder(weights, template.adjacency, m, 'js');
  const reference = new ReferenceDecoder(weights, template.adjacency, m);
  return {
    mel_ms_per_audio_second: time(() => logMelFrames(samples, manifest.audio, 0, K)) / seconds,
    mel_meyda_extract_ms_per_audio_second: time(() => logMelFramesMeyda(samples, manifest.audio, 0, K), 1) / seconds,
    // speakStream()'s pieces brought to the model's rate, in pieces of 0.1 s: ms per second of audio
    ...Object.fromEntries([24000, 44100, 48000].map((rate) => [`resample_${rate}_ms_per_audio_second`, resampleMs(rate, manifest.audio.sample_rate, time)])),
    decoder_ms_per_frame: time(() => fast.decode(tokens, poseTok, frames)) / frames,
    decoder_kernel: fast.kernelName,
    // what the engine runs: the vertex tokens made of the hierarchical latents first (decodeLatents)
    decoder_latents_ms_per_frame: time(() => fast.decodeLatents(latents, poseTok, frames)) / frames,
    decoder_js_ms_per_frame: time(() => fastJs.decode(tokens, poseTok, frames)) / frames,
    reference_decoder_ms_per_frame: time(() => reference.decode(tokens, poseTok, 4), 1) / 4,
  };
}

/** Milliseconds per second of audio to bring a 2 s tone at `from` Hz to `to` Hz, streamed in pieces of 0.1 s. */
function resampleMs(from: number, to: number, time: (fn: () => void) => number): number {
  const x = Float32Array.from({ length: 2 * from }, (_, i) => Math.sin(i / 7));
  const piece = from / 10;
  return time(() => {
    const r = new StreamResampler(from, to);
    for (let at = 0; at < x.length; at += piece) r.push(x.subarray(at, at + piece));
  }) / 2;
}

async function main(): Promise<void> {
  const node = firstLoadOnly || renderOnly || liveOnly ? {} : await nodeBench();
  if (o['node-only']) {
    console.log(JSON.stringify(node, null, 1)); // a quick look; nothing written
    return;
  }
  if (!(await portFree(PORT))) throw new Error(`port ${PORT} is in use (another server would be measured): free it, or set BENCH_PORT`);
  execSync('npm run --silent build:test', { cwd: ROOT, stdio: 'inherit' });
  const server = startServer('npx', ['vite', 'preview', '--host', '127.0.0.1', '--port', String(PORT), '--strictPort'], ROOT);
  try {
    await server.ready(`http://127.0.0.1:${PORT}/dev/bench.html`);
    // The demo live, as a visitor sees it: a separate browser with a fake microphone, at a 1x and a 2x screen.
    const live: LiveDisplay[] = [];
    if (!renderOnly && !firstLoadOnly) {
      for (const scale of [1, 2]) live.push(await measureLiveDisplay(String(o['live-url'] ?? `http://127.0.0.1:${PORT}/`), SPEECH, scale));
    }
    if (liveOnly) {
      printLiveDisplay(live);
      return;
    }
    const browser = await chromium.launch({ executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium', args: [...CHROMIUM_ARGS, '--enable-precise-memory-info'] });
    const firstLoad = renderOnly ? null : await measureFirstLoad(browser, String(o['first-load-url'] ?? `http://127.0.0.1:${PORT}/`), 5);
    // The floor under it: onnxruntime-web alone, started as the engine starts it (dev/ort-start.html).
    if (firstLoad) await measureOnnxAlone(browser, `http://127.0.0.1:${PORT}/dev/ort-start.html`, firstLoad, 5);
    if (firstLoadOnly) {
      printFirstLoad(firstLoad!);
      await browser.close();
      return;
    }
    const page = await browser.newPage();
    page.on('pageerror', (e) => console.error(`page error: ${e.message}`));
    await page.goto(`http://127.0.0.1:${PORT}/dev/bench.html`);
    await page.waitForFunction(() => document.body.dataset.ready === 'true');
    const wav = readFileSync(resolve(ROOT, 'tests/fixtures/speech-kal.wav')).toString('base64');
    const t0 = Date.now();
    const result = (await within(page.evaluate(
      ([w, b, s, r]) => (globalThis as unknown as { runBench: (w: string, b: string[], s: number[], r: boolean) => Promise<Record<string, unknown>> }).runBench(w, b, s, r),
      [wav, backends, seconds, renderOnly] as const,
    ), 1800, 'the benchmark page')) as Record<string, unknown>;
    await browser.close();
    if (result.error) throw new Error(`benchmark failed in the page: ${result.error}`);
    if (renderOnly) {
      // Keep the engine's figures of the last full run; replace only the render benchmark's.
      const previous = JSON.parse(readFileSync(OUT, 'utf8')) as Record<string, unknown>;
      // The render figures carry the machine's state when they were taken (`machine` is the full run's).
      writeFileSync(OUT, JSON.stringify({ ...previous, render: { ...(result.render as object), machine: await machineState(t0) } }, null, 1) + '\n');
      printRender(result.render as Record<string, number>);
      console.log(`written: ${OUT} (render only)`);
      return;
    }
    result.node = node;
    result.first_load = firstLoad;
    result.live_display = live;
    result.machine = await machineState(t0);
    writeFileSync(OUT, JSON.stringify(result, null, 1) + '\n');
    print(result);
  } finally {
    server.stop();
  }
}

function print(r: Record<string, unknown>): void {
  const runs = r.runs as Record<string, { wall_ms: number; rtf: number; first_frame_ms: number; peak_heap_bytes: number; stages_ms: Record<string, number> }>;
  const f = (x: number | undefined, d = 1) => (x === undefined ? '-' : x.toFixed(d));
  console.log('\nrun            wall (ms)   RTF (x real time)   first frame (ms)   peak heap (MB)   mel / content / hier / pose / decoder / posing (ms)');
  for (const [name, v] of Object.entries(runs)) {
    const s = v.stages_ms;
    console.log(`${name.padEnd(14)} ${f(v.wall_ms, 0).padStart(9)}   ${f(v.rtf, 2).padStart(17)}   ${f(v.first_frame_ms, 0).padStart(16)}   ${f(v.peak_heap_bytes / 1e6).padStart(14)}   ` +
      [s.mel, s.content, s.hierarchical, s.pose, s.decoder, s.posing].map((x) => f(x, 0)).join(' / '));
  }
  console.log(`\nmodel load ${f(r.model_load_ms as number, 0)} ms (${f((r.model_load_transfer_bytes as number) / 2 ** 20, 2)} MiB transferred, onnxruntime ${r.ort_build} build), ` +
    `model files ${f((r.model_bytes as number) / 1e6, 2)} MB, first frame ${f(r.first_frame_ms as number, 0)} ms; ` +
    `CPU decoder: ${r.cpu_decoder_kernel}${r.cpu_decoder_fma ? ' (fused multiply-add)' : ''} on ${r.cpu_decoder_threads} thread(s)`);
  console.log(`streaming latency (sample in -> frame out) p50 ${f(r.stream_latency_ms as number, 0)} ms, p95 ${f(r.stream_latency_p95_ms as number, 0)} ms; ` +
    `of which look-ahead ${f(r.stream_look_ahead_ms as number, 0)} ms, pieces of ${f(r.stream_piece_ms as number, 0)} ms`);
  console.log('decoder time per frame by vertex count:', JSON.stringify(r.attention_by_vertices));
  const nd = r.node as Record<string, number> & { decoder_kernel: string };
  console.log(`Node: Mel ${f(nd.mel_ms_per_audio_second)} ms per audio second (Meyda.extract per frame: ${f(nd.mel_meyda_extract_ms_per_audio_second)}); ` +
    `decoder ${f(nd.decoder_ms_per_frame, 2)} ms per frame in ${nd.decoder_kernel}, ${f(nd.decoder_latents_ms_per_frame, 2)} with its tokens made (TypeScript kernel: ${f(nd.decoder_js_ms_per_frame, 2)}; reference: ${f(nd.reference_decoder_ms_per_frame, 2)})`);
  printRender(r.render as Record<string, number>);
  printFirstLoad(r.first_load as FirstLoad);
  printLiveDisplay(r.live_display as LiveDisplay[]);
  console.log('adapter:', JSON.stringify(r.adapter), `\nwritten: ${OUT}`);
}

/** The head's render benchmark (dev/render-bench.ts): per frame, the main thread's work and the whole frame. */
function printRender(v: Record<string, number>): void {
  const f = (x: number) => x.toFixed(2);
  console.log(`render (${v.width}x${v.height}, ${v.skin_vertices} skin vertices, ${v.triangles} triangles, ${v.draw_calls} draw calls): ` +
    `main thread ${f(v.main_thread_ms)} ms per frame (head update ${f(v.head_update_ms)}, of which the extra geometry ${f(v.extra_geometry_ms)}; ` +
    `render call ${f(v.render_call_ms)}); whole frame with SwiftShader's software rendering ${f(v.frame_ms)} ms`);
}

main().catch((e) => {
  console.error(`bench: ${(e as Error).message}`);
  process.exit(1);
});
