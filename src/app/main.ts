/**
 * The demo shell: the only code that touches the page's DOM. It loads the face and the model; animates
 * an audio file the visitor opens or drops, or the microphone live while they speak; and plays the take
 * back with the face in sync (play, pause, scrub, loop).
 */
import { loadTemplate, lipMask as lipMaskOf } from '../template/face-template';
import { FaceView } from '../render/face-view';
import { detectWebGPU } from '../gpu/capabilities';
import { TalkingFaceEngine, type Animation, type Backend, type Frames } from '../engine/engine';
import { innerLipGaps } from '../template/lip-gap';
import { LipTimeline } from './timeline';
import type { LiveSession } from '../engine/live';
import { decodeAudio, levels } from '../audio/decode';
import { openMicrophone } from '../audio/capture';
import { exportGlb, inspectGlb, rawFrames, download, GLB_COMPONENTS, GLB_EXACT_FRAMES } from './export-glb';

const TEMPLATE_URL = '/models/template/template.json';
const MANIFEST_URL = '/models/manifest.json';
/** Longer clips get a warning with the expected time (they still work: memory stays bounded). */
const LONG_CLIP_SECONDS = 120;

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const status = $<HTMLParagraphElement>('status');
const canvas = $<HTMLCanvasElement>('face-canvas');
const fileInput = $<HTMLInputElement>('file-input');
const recordButton = $<HTMLButtonElement>('record-button');
const cancelButton = $<HTMLButtonElement>('cancel-button');
const backendSelect = $<HTMLSelectElement>('backend-select');
const playButton = $<HTMLButtonElement>('play-button');
const loopCheck = $<HTMLInputElement>('loop-check');
const scrub = $<HTMLInputElement>('scrub');
const timeLabel = $<HTMLOutputElement>('time-label');
const clipInfo = $<HTMLSpanElement>('clip-info');
const sampleSelect = $<HTMLSelectElement>('sample-select');
const arrowsCheck = $<HTMLInputElement>('arrows-check');
const paintSelect = $<HTMLSelectElement>('paint-select');
const sideCheck = $<HTMLInputElement>('side-check');
const gtView = $<HTMLElement>('gt-view');
const gtCanvas = $<HTMLCanvasElement>('gt-canvas');
const legend = $<HTMLParagraphElement>('legend');
const exportGlbButton = $<HTMLButtonElement>('export-glb');
const exportRawButton = $<HTMLButtonElement>('export-raw');
const stage = $<HTMLElement>('stage');
const dropHint = $<HTMLParagraphElement>('drop-hint');
const timeline = new LipTimeline($<HTMLCanvasElement>('timeline'));
addEventListener('resize', () => timeline.redraw());

function showStatus(text: string, isError = false): void {
  status.textContent = text;
  status.classList.toggle('error', isError);
}

interface Take {
  animation: Animation;
  buffer: AudioBuffer;
  /** The audio at the model's rate (for attention maps). */
  samples: Float32Array;
  name: string;
  seconds: number;
  computeMs: number;
  backend: Backend;
  truth?: Truth;
  /** E_vl of the whole take against its ground truth (mm), computed once. */
  lipError?: number;
}

/** Ground truth of a sample clip: the subject's neutral face, the unposed frames and poses (template units). */
interface Truth {
  template: Float32Array;
  unposed: Float32Array;
  pose: Float32Array;
  frames: number;
  /** The sample's inner-lip gap per frame (mm) and aligned phones, from its index (for the timeline). */
  lipGapMm?: number[];
  phones?: [string, number, number][];
}

interface SampleEntry {
  name: string; text: string; voice: string; source: string; frames: number; seconds: number;
  audio: string; ground_truth: string; vertices: number; audio_sha256: string; ground_truth_sha256: string;
  lip_gap_mm: number[]; phones: [string, number, number][];
}

const SAMPLES_URL = '/models/samples/index.json';
let sampleIndex: { units: string; clips: SampleEntry[] } | null = null;
let truthView: FaceView | null = null;
let pickedVertex: number | null = null;
let paintJob = 0;
let lipMask: Uint8Array | null = null;

let view: FaceView;
let engine: TalkingFaceEngine | null = null;
let autoBackend: Backend = 'cpu';
let take: Take | null = null;
let audioContext: AudioContext | null = null;
let playing: { source: AudioBufferSourceNode; startedAt: number; fromFrame: number } | null = null;
let current = 0;
let busy: AbortController | null = null;
let recording: { live: LiveSession; frames: Frames[]; started: number } | null = null;
let baseStatus = '';

function publish(): void {
  Object.assign(globalThis, {
    talkingFace: {
      view, template: view?.template, gpu: lastGpu, engine, take, truthView,
      exportGlb: async () => (take && engine ? exportGlb(take.animation, view.template, engine.unitsPerMm) : null),
      inspectGlb,
    },
  });
}
let lastGpu: Awaited<ReturnType<typeof detectWebGPU>> | null = null;

async function start(): Promise<void> {
  const [template, gpu] = await Promise.all([loadTemplate(TEMPLATE_URL), detectWebGPU()]);
  lastGpu = gpu;
  view = new FaceView(canvas, template);
  publish();
  baseStatus = `Face: ${template.id} (${template.vertexCount} vertices). ` +
    (gpu.available ? `WebGPU adapter: ${gpu.description}.` : `WebGPU: none (${gpu.description}); the CPU path will be used.`);
  showStatus(`${baseStatus} Loading the model…`);
  document.body.dataset.ready = 'true';
  try {
    engine = await TalkingFaceEngine.load({ manifestUrl: MANIFEST_URL });
    autoBackend = engine.backend;
    if (!gpu.available) backendSelect.querySelector<HTMLOptionElement>('option[value="webgpu"]')!.disabled = true;
    publish();
    showStatus(`${baseStatus} Model ${engine.manifest.model.name} ready. Decoder: ${engine.backend} (${engine.backendReason}; CPU decoder: ${engine.cpuKernel === 'wasm-simd' ? 'WebAssembly SIMD' : 'JavaScript'} on ${engine.cpuThreads} thread${engine.cpuThreads > 1 ? 's' : ''}). Open or drop an audio file, or record.`);
    document.body.dataset.engine = 'ready';
    void loadSampleIndex();
    const e = engine;
    e.restFace().then(
      (rest) => {
        if (!take) view.setVertices(rest); // the mouth closed at rest, not the opened template
        document.body.dataset.rest = 'shown';
      },
      (err: Error) => showStatus(`The face at rest could not be computed: ${err.message}`, true),
    );
  } catch (e) {
    showStatus(`${baseStatus} The model could not be loaded: ${(e as Error).message}. The face can still be viewed.`, true);
    document.body.dataset.engine = 'error';
  }
}

function needEngine(): TalkingFaceEngine | null {
  if (!engine) showStatus('The model is not loaded, so audio cannot be animated. Reload the page to try again.', true);
  return engine;
}

function setBusy(controller: AbortController | null): void {
  busy = controller;
  cancelButton.hidden = !controller;
  recordButton.disabled = Boolean(controller);
}

async function animateFile(file: File): Promise<void> {
  const e = needEngine();
  if (!e || recording) return;
  busy?.abort();
  stopPlayback();
  const controller = new AbortController();
  setBusy(controller);
  try {
    showStatus(`Decoding ${file.name}…`);
    const audio = await decodeAudio(file, e.manifest.audio.sample_rate);
    const lv = levels(audio.samples);
    const notes: string[] = [];
    if (lv.peak < 1e-3) notes.push('the recording is silent, so the mouth stays closed');
    if (lv.clipped > 0.01) notes.push(`${(100 * lv.clipped).toFixed(1)}% of the samples are clipped (distorted); the motion may be less accurate`);
    const src = audio.source;
    clipInfo.textContent = `${file.name}: ${src.seconds.toFixed(1)} s, ${src.channels === 1 ? 'mono' : `${src.channels} channels mixed to mono`}`;
    if (src.seconds > LONG_CLIP_SECONDS) {
      notes.push(`a long clip (${(src.seconds / 60).toFixed(1)} min): it is animated in chunks with bounded memory; Cancel stops it`);
    }
    e.resetTimes();
    const computeStart = performance.now();
    const animation = await e.animate(audio.samples, {
      unposed: true,
      signal: controller.signal,
      onProgress: (done, total) => showStatus(`Animating ${file.name}: frame ${done} of ${total} (${Math.round((100 * done) / total)}%)…` + (notes.length ? ` Note: ${notes.join('; ')}.` : '')),
    });
    setTake({ animation, buffer: audio.buffer, samples: audio.samples, name: file.name, seconds: src.seconds, computeMs: performance.now() - computeStart, backend: e.backend }, notes);
  } catch (err) {
    if (controller.signal.aborted) {
      showStatus(`Stopped animating ${file.name}. Open another file or record.`);
      document.body.dataset.take = take ? 'ready' : 'cancelled';
    } else {
      showStatus(`Could not animate ${file.name}: ${(err as Error).message}`, true);
      document.body.dataset.take = 'error';
    }
  } finally {
    if (busy === controller) setBusy(null);
  }
}

function setTake(t: Take, notes: string[] = []): void {
  take = t;
  publish();
  const perFrame = t.computeMs / t.animation.frames;
  showStatus(`${t.name}: ${t.animation.frames} frames. Decoder ${t.backend}: ${perFrame.toFixed(1)} ms per frame, ` +
    `${(t.seconds / (t.computeMs / 1000)).toFixed(1)}x real time.` + (notes.length ? ` Note: ${notes.join('; ')}.` : ''));
  playButton.disabled = false;
  exportGlbButton.disabled = false;
  exportRawButton.disabled = false;
  scrub.disabled = false;
  scrub.max = String(t.animation.frames - 1);
  showTimeline(t);
  showFrame(0);
  document.body.dataset.take = 'ready';
}

/** The lip timeline of a take: predicted gap and heard phones, and the truth's for a sample clip. */
function showTimeline(t: Take): void {
  const e = engine;
  const a = t.animation;
  if (!e || !a.unposed) return timeline.clear();
  const { lips_inner_upper: upper, lips_inner_lower: lower } = view.template.regions;
  const gap = innerLipGaps(a.unposed, a.frames, view.template.vertexCount, upper, lower).map((g) => g / e.unitsPerMm);
  timeline.show({ fps: a.fps, gap, heard: Array.from(a.phones, (k) => e.manifest.content_phones[k]), truthGap: t.truth?.lipGapMm, truthPhones: t.truth?.phones });
}

/** Frame f of the prediction as drawn: on the sample subject's own face when there is ground truth. */
let predictedScratch = new Float32Array(0);
function predictedFrame(f: number): Float32Array {
  const n3 = view.template.vertexCount * 3;
  const u = take!.animation.unposed!.subarray(f * n3, (f + 1) * n3);
  const truth = take!.truth;
  if (!truth) return u;
  if (predictedScratch.length !== n3) predictedScratch = new Float32Array(n3); // reused: callers use it at once
  const out = predictedScratch;
  for (let i = 0; i < n3; i++) out[i] = truth.template[i] + u[i] - view.template.positions[i];
  return out;
}

function showFrame(frame: number): void {
  if (!take?.animation.unposed || !engine) return;
  const n = view.template.vertexCount;
  const f = Math.min(Math.max(0, frame), take.animation.frames - 1);
  current = f;
  view.setVertices(predictedFrame(f));
  const p = take.animation.pose;
  const s = engine.unitsPerMm;
  view.setPose(p[f * 6], p[f * 6 + 1], p[f * 6 + 2], p[f * 6 + 3] * s, p[f * 6 + 4] * s, p[f * 6 + 5] * s);
  const truth = take.truth;
  if (truth && truthView) {
    const g = Math.min(f, truth.frames - 1);
    truthView.setVertices(truth.unposed.subarray(g * n * 3, (g + 1) * n * 3));
    const q = truth.pose;
    truthView.setPose(q[g * 6], q[g * 6 + 1], q[g * 6 + 2], q[g * 6 + 3], q[g * 6 + 4], q[g * 6 + 5]);
  }
  timeline.setPlayhead(f);
  scrub.value = String(f);
  timeLabel.value = `${(f / take.animation.fps).toFixed(2)} s`;
  paint();
}

/** Colour the face by the chosen quantity at the current frame (attention maps only when paused: they are recomputed). */
function paint(): void {
  const mode = paintSelect.value;
  const job = ++paintJob;
  const n = view.template.vertexCount;
  if (mode === 'none' || !take || !engine) {
    view.setColorMap(null);
    legend.hidden = true;
    return;
  }
  if (mode === 'error') {
    const truth = take.truth;
    if (!truth) {
      view.setColorMap(null);
      showLegend('The error map needs a sample clip (it has ground truth).');
      return;
    }
    const f = Math.min(current, truth.frames - 1);
    const pred = predictedFrame(current);
    const mmPerUnit = 1 / engine.unitsPerMm;
    const err = new Float32Array(n);
    let lipMax = 0;
    for (let v = 0; v < n; v++) {
      const o = (f * n + v) * 3;
      err[v] = mmPerUnit * Math.hypot(pred[3 * v] - truth.unposed[o], pred[3 * v + 1] - truth.unposed[o + 1], pred[3 * v + 2] - truth.unposed[o + 2]);
      if (lipMask?.[v]) lipMax = Math.max(lipMax, err[v]);
    }
    view.setColorMap(err, 5);
    showLegend(`Error vs ground truth: 0<span class="ramp"></span>5 mm. This frame's largest lip error ${lipMax.toFixed(2)} mm; clip E_vl ${(take.lipError ??= clipLipError()).toFixed(2)} mm.`);
    return;
  }
  if (playing) {
    showLegend('Attention maps are computed for the paused frame: pause or scrub.');
    return;
  }
  const frame = current;
  void engine.attentionAt(take.samples, frame).then((maps) => {
    if (job !== paintJob) return;
    const values = new Float32Array(n);
    let max = 0;
    if (mode === 'pose-attention') {
      for (let v = 0; v < n; v++) max = Math.max(max, (values[v] = maps.poseToken[v]));
      view.setColorMap(values, max);
      showLegend(`Pose token attention, layer ${maps.layer + 1} (paper Fig. 7): 0<span class="ramp"></span>${max.toFixed(4)}; the pose token itself: ${maps.poseToken[n].toFixed(4)}.`);
    } else {
      const j = pickedVertex ?? view.template.regions.lips_outer_upper[Math.floor(view.template.regions.lips_outer_upper.length / 2)];
      for (let k = maps.keyStart[j]; k < maps.keyStart[j + 1]; k++) max = Math.max(max, (values[maps.keys[k]] = maps.vertexWeights[k]));
      view.setColorMap(values, max);
      showLegend(`Vertex ${j}'s attention over itself and its ${maps.keyStart[j + 1] - maps.keyStart[j] - 1} neighbours, layer ${maps.layer + 1} (paper Fig. 10): ` +
        `0<span class="ramp"></span>${max.toFixed(3)}. Click the face to choose another vertex.`);
    }
    document.body.dataset.painted = mode;
  }, (err: Error) => showLegend(`Attention map failed: ${err.message}`));
}

function showLegend(html: string): void {
  legend.innerHTML = html;
  legend.hidden = false;
}

/** The paper's E_vl for the current sample take: mean over frames of the largest lip-vertex error (mm). */
function clipLipError(): number {
  const truth = take?.truth;
  if (!truth || !lipMask || !engine) return NaN;
  const n = view.template.vertexCount;
  const frames = Math.min(truth.frames, take!.animation.frames);
  let sum = 0;
  for (let f = 0; f < frames; f++) {
    const pred = predictedFrame(f);
    let worst = 0;
    for (let v = 0; v < n; v++) {
      if (!lipMask[v]) continue;
      const o = (f * n + v) * 3;
      worst = Math.max(worst, Math.hypot(pred[3 * v] - truth.unposed[o], pred[3 * v + 1] - truth.unposed[o + 1], pred[3 * v + 2] - truth.unposed[o + 2]));
    }
    sum += worst / engine.unitsPerMm;
  }
  return sum / frames;
}

async function loadSampleIndex(): Promise<void> {
  try {
    const res = await fetch(SAMPLES_URL);
    if (!res.ok) throw new Error(`HTTP ${res.status}`);
    sampleIndex = await res.json();
    for (const c of sampleIndex!.clips) {
      const o = document.createElement('option');
      o.value = c.name;
      o.textContent = `"${c.text}" (${c.source === 'human' ? 'recorded voice' : c.voice}, ${c.seconds.toFixed(1)} s)`;
      sampleSelect.append(o);
    }
  } catch (e) {
    sampleSelect.disabled = true;
    sampleSelect.title = `No sample clips: ${(e as Error).message}`;
  }
}

async function sha256Hex(bytes: ArrayBuffer): Promise<string> {
  return Array.from(new Uint8Array(await crypto.subtle.digest('SHA-256', bytes)), (b) => b.toString(16).padStart(2, '0')).join('');
}

async function openSample(name: string): Promise<void> {
  const e = needEngine();
  const c = sampleIndex?.clips.find((x) => x.name === name);
  if (!e || !c || recording) return;
  busy?.abort();
  stopPlayback();
  const controller = new AbortController();
  setBusy(controller);
  try {
    showStatus(`Loading the sample "${c.text}"…`);
    const [audioBytes, truthBytes] = await Promise.all([c.audio, c.ground_truth].map(async (f) => {
      const r = await fetch(`/models/samples/${f}`);
      if (!r.ok) throw new Error(`${f}: HTTP ${r.status}`);
      return r.arrayBuffer();
    }));
    if ((await sha256Hex(audioBytes)) !== c.audio_sha256 || (await sha256Hex(truthBytes)) !== c.ground_truth_sha256) {
      throw new Error('the sample files do not match their index (corrupt download?)');
    }
    const n = view.template.vertexCount;
    if (c.vertices !== n) throw new Error(`the sample has ${c.vertices} vertices, the face ${n}`);
    const truth = { ...decodeTruth(truthBytes, n, c.frames, e.unitsPerMm), lipGapMm: c.lip_gap_mm, phones: c.phones };
    lipMask ??= lipMaskOf(view.template);
    const audio = await decodeAudio(audioBytes, e.manifest.audio.sample_rate);
    e.resetTimes();
    const t0 = performance.now();
    const animation = await e.animate(audio.samples, {
      unposed: true,
      signal: controller.signal,
      onProgress: (done, total) => showStatus(`Animating the sample: frame ${done} of ${total}…`),
    });
    clipInfo.textContent = `Sample (test split: unseen voice, sentence and face): "${c.text}"`;
    setTake({ animation, buffer: audio.buffer, samples: audio.samples, name: c.name, seconds: c.seconds, computeMs: performance.now() - t0, backend: e.backend, truth });
    take!.lipError = clipLipError();
    showStatus(`${status.textContent} E_vl on this clip: ${take!.lipError.toFixed(2)} mm.`);
  } catch (err) {
    if (!controller.signal.aborted) showStatus(`Could not open the sample: ${(err as Error).message}`, true);
  } finally {
    if (busy === controller) setBusy(null);
  }
}

/** samples.py's layout: float32 (N,3) neutral face; int16 (F,N,3) micrometre offsets; float32 (F,6) pose (units). */
function decodeTruth(bytes: ArrayBuffer, n: number, frames: number, unitsPerMm: number): Truth {
  const expected = n * 12 + frames * n * 6 + frames * 24;
  if (bytes.byteLength !== expected) throw new Error(`ground truth has ${bytes.byteLength} bytes, expected ${expected}`);
  const view = new DataView(bytes);
  const template = new Float32Array(n * 3);
  for (let i = 0; i < n * 3; i++) template[i] = view.getFloat32(4 * i, true);
  const unposed = new Float32Array(frames * n * 3);
  const base = n * 12;
  for (let i = 0; i < frames * n * 3; i++) unposed[i] = template[i % (n * 3)] + (view.getInt16(base + 2 * i, true) / 1000) * unitsPerMm;
  const pose = new Float32Array(frames * 6);
  const pb = base + frames * n * 6;
  for (let i = 0; i < frames * 6; i++) pose[i] = view.getFloat32(pb + 4 * i, true);
  return { template, unposed, pose, frames };
}

function showLiveFrame(frames: Frames): void {
  if (!engine) return;
  const n = view.template.vertexCount;
  const last = frames.count - 1;
  view.setVertices(frames.unposed.subarray(last * n * 3, (last + 1) * n * 3));
  const p = frames.pose.subarray(last * 6, last * 6 + 6);
  const s = engine.unitsPerMm;
  view.setPose(p[0], p[1], p[2], p[3] * s, p[4] * s, p[5] * s);
}

function play(): void {
  if (!take) return;
  audioContext ??= new AudioContext();
  void audioContext.resume();
  const from = current >= take.animation.frames - 1 ? 0 : current;
  const source = audioContext.createBufferSource();
  source.buffer = take.buffer;
  source.connect(audioContext.destination);
  source.onended = () => {
    if (playing?.source !== source) return;
    playing = null;
    if (loopCheck.checked) {
      showFrame(0);
      play();
    } else {
      showFrame(take!.animation.frames - 1);
      playButton.textContent = 'Play';
    }
  };
  const startedAt = audioContext.currentTime + 0.05;
  source.start(startedAt, from / take.animation.fps);
  playing = { source, startedAt, fromFrame: from };
  playButton.textContent = 'Pause';
  const tick = () => {
    if (playing?.source !== source || !take || !audioContext) return;
    const f = playing.fromFrame + Math.floor((audioContext.currentTime - playing.startedAt) * take.animation.fps);
    if (f >= playing.fromFrame) showFrame(f);
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
}

function stopPlayback(): void {
  if (playing) {
    const p = playing;
    playing = null;
    p.source.onended = null;
    p.source.stop();
  }
  playButton.textContent = 'Play';
}

async function toggleRecording(): Promise<void> {
  const e = needEngine();
  if (!e) return;
  if (recording) {
    const r = recording;
    recording = null;
    recordButton.textContent = 'Record';
    recordButton.setAttribute('aria-pressed', 'false');
    recordButton.disabled = true;
    showStatus('Finishing the take…');
    try {
      const samples = await r.live.stop();
      const rate = e.manifest.audio.sample_rate;
      if (samples.length < rate / 10) {
        showStatus('The take was too short to animate. Press Record and speak for a moment.', true);
        return;
      }
      const buffer = new AudioBuffer({ length: samples.length, sampleRate: rate, numberOfChannels: 1 });
      buffer.copyToChannel(new Float32Array(samples), 0);
      const seconds = samples.length / rate;
      const computeMs = e.times.mel + e.times.content + e.times.hierarchical + e.times.pose + e.times.decoder + e.times.posing;
      const streamed = r.frames.reduce((s, f) => s + f.count, 0);
      let animation: Animation;
      if (r.live.stream.skippedFrames === 0 && streamed === e.frameCount(samples.length)) {
        animation = joinFrames(r.frames, e.fps);
      } else {
        // The device fell behind while live (frames were skipped to stay live): animate the take again, whole.
        showStatus('Animating the whole take (some frames were skipped live to keep up)…');
        animation = await e.animate(samples, { unposed: true });
      }
      const lv = levels(samples);
      const notes = lv.peak < 1e-3 ? ['the take is silent (is the microphone muted?)'] : [];
      clipInfo.textContent = `Recording: ${seconds.toFixed(1)} s`;
      setTake({ animation, buffer, samples, name: 'Recording', seconds, computeMs, backend: e.backend }, notes);
    } catch (err) {
      showStatus(`The recording could not be finished: ${(err as Error).message}`, true);
    } finally {
      recordButton.disabled = false;
    }
    return;
  }
  stopPlayback();
  recordButton.disabled = true;
  try {
    const media = await openMicrophone();
    e.resetTimes();
    const frames: Frames[] = [];
    const live = await e.listen(media, (_, f) => {
      frames.push(f);
      showLiveFrame(f);
    }, { onError: (err) => showStatus(`Live animation stopped: ${err.message}`, true) });
    recording = { live, frames, started: performance.now() };
    recordButton.textContent = 'Stop recording';
    recordButton.setAttribute('aria-pressed', 'true');
    document.body.dataset.recording = 'true';
    const update = () => {
      if (recording?.live !== live) return;
      const lat = live.stream.latency;
      showStatus(`Recording ${live.seconds.toFixed(1)} s: the face follows your voice. Decoder ${e.backend}, ` +
        `latency ${Number.isFinite(lat.p50Ms) ? Math.round(lat.p50Ms) : '…'} ms (look-ahead ${Math.round(live.stream.lookAheadMs)} ms)` +
        (live.stream.skippedFrames ? `, ${live.stream.skippedFrames} frames skipped to keep up` : '') + '.');
      setTimeout(update, 250);
    };
    update();
  } catch (err) {
    showStatus(`${(err as Error).message}`, true);
    document.body.dataset.recording = 'error';
  } finally {
    recordButton.disabled = false;
  }
}

function joinFrames(chunks: Frames[], fps: number): Animation {
  const count = chunks.reduce((s, f) => s + f.count, 0);
  const per = chunks[0]?.vertices.length / Math.max(1, chunks[0]?.count ?? 1) || 0;
  const vertices = new Float32Array(count * per);
  const unposed = new Float32Array(count * per);
  const pose = new Float32Array(count * 6);
  const phones = new Uint8Array(count);
  let i = 0;
  for (const f of chunks) {
    vertices.set(f.vertices, i * per);
    unposed.set(f.unposed, i * per);
    pose.set(f.pose, i * 6);
    phones.set(f.phones, i);
    i += f.count;
  }
  return { fps, frames: count, vertices, pose, unposed, phones };
}

sampleSelect.addEventListener('change', () => {
  if (sampleSelect.value) void openSample(sampleSelect.value);
});
arrowsCheck.addEventListener('change', () => {
  view.showPoseArrows(arrowsCheck.checked);
  truthView?.showPoseArrows(arrowsCheck.checked);
});
paintSelect.addEventListener('change', () => paint());
sideCheck.addEventListener('change', () => {
  gtView.hidden = !sideCheck.checked;
  if (sideCheck.checked && !truthView) {
    truthView = new FaceView(gtCanvas, view.template);
    truthView.showPoseArrows(arrowsCheck.checked);
    publish();
  }
  if (sideCheck.checked && !take?.truth) showLegend('Side by side needs a sample clip (it has ground truth).');
  showFrame(current);
});
canvas.addEventListener('click', (ev) => {
  if (paintSelect.value !== 'vertex-attention') return;
  const v = view.pickVertex(ev.clientX, ev.clientY);
  if (v !== null) {
    pickedVertex = v;
    paint();
  }
});
exportGlbButton.addEventListener('click', async () => {
  if (!take || !engine) return;
  exportGlbButton.disabled = true;
  try {
    if (take.animation.frames > GLB_EXACT_FRAMES) {
      showStatus(`Preparing the .glb: finding the clip's ${GLB_COMPONENTS} strongest motion components…`);
      await new Promise((r) => setTimeout(r, 30)); // let the message show before the work
    }
    const glb = await exportGlb(take.animation, view.template, engine.unitsPerMm);
    download(new Blob([glb.bytes], { type: 'model/gltf-binary' }), `${take.name.replace(/\.[^.]+$/, '')}.glb`);
    showStatus(`Exported ${glb.frames} frames as .glb (${(glb.bytes.byteLength / 1e6).toFixed(1)} MB)` +
      (glb.encoding === 'components'
        ? `: the clip is longer than ${GLB_EXACT_FRAMES} frames, so its motion is ${glb.morphTargets} morph targets with per-frame weights ` +
          `(largest deviation from the exact frames: ${glb.maxErrorMm.toFixed(2)} mm).`
        : ', one morph target per frame.'));
  } catch (err) {
    showStatus(`Export failed: ${(err as Error).message}`, true);
  } finally {
    exportGlbButton.disabled = false;
  }
});
exportRawButton.addEventListener('click', () => {
  if (!take) return;
  const n = view.template.vertexCount;
  download(rawFrames(take.animation), `${take.name.replace(/\.[^.]+$/, '')}.${take.animation.frames}x${n}x3.f32`);
  showStatus(`Exported ${take.animation.frames} frames x ${n} vertices x 3 as float32 (little-endian, ${view.template.units}, ${take.animation.fps} fps).`);
});

fileInput.addEventListener('change', () => {
  const file = fileInput.files?.[0];
  if (file) void animateFile(file);
  fileInput.value = '';
});
recordButton.addEventListener('click', () => void toggleRecording());
cancelButton.addEventListener('click', () => busy?.abort());
playButton.addEventListener('click', () => (playing ? stopPlayback() : play()));
scrub.addEventListener('input', () => {
  stopPlayback();
  showFrame(Number(scrub.value));
});
backendSelect.addEventListener('change', () => {
  if (!engine) return;
  const want: Backend = backendSelect.value === 'auto' ? autoBackend : (backendSelect.value as Backend);
  engine.setBackend(want).then(
    () => showStatus(`Decoder: ${engine!.backend}. New animations use it.`),
    (err: Error) => showStatus(`Cannot use ${want}: ${err.message}`, true),
  );
});
document.addEventListener('keydown', (ev) => {
  // Space plays/pauses and arrows step frames when the viewer has focus.
  if (document.activeElement !== canvas || !take) return;
  if (ev.key === ' ') {
    ev.preventDefault();
    if (playing) stopPlayback();
    else play();
  } else if (ev.key === 'ArrowRight' || ev.key === 'ArrowLeft') {
    ev.preventDefault();
    stopPlayback();
    showFrame(current + (ev.key === 'ArrowRight' ? 1 : -1));
  }
});
stage.addEventListener('dragover', (e) => {
  e.preventDefault();
  stage.classList.add('dragging');
  dropHint.hidden = false;
});
stage.addEventListener('dragleave', () => {
  stage.classList.remove('dragging');
  dropHint.hidden = true;
});
stage.addEventListener('drop', (e) => {
  e.preventDefault();
  stage.classList.remove('dragging');
  dropHint.hidden = true;
  const file = e.dataTransfer?.files?.[0];
  if (file) void animateFile(file);
});

start().catch((e: Error) => {
  showStatus(`Could not start: ${e.message}`, true);
  document.body.dataset.ready = 'error';
  console.error(e);
});
