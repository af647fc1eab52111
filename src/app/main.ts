/**
 * The demo shell: the only code that touches the page's DOM. It loads the face and the model; animates
 * an audio file the visitor opens or drops, or the microphone live while they speak; and plays the take
 * back with the face in sync (play, pause, scrub, loop).
 */
import { loadTemplate } from '../template/face-template';
import { FaceView } from '../render/face-view';
import { detectWebGPU } from '../gpu/capabilities';
import { TalkingFaceEngine, type Animation, type Backend, type Frames } from '../engine/engine';
import type { LiveSession } from '../engine/live';
import { decodeAudio, levels } from '../audio/decode';
import { openMicrophone } from '../audio/capture';

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
const stage = $<HTMLElement>('stage');
const dropHint = $<HTMLParagraphElement>('drop-hint');

function showStatus(text: string, isError = false): void {
  status.textContent = text;
  status.classList.toggle('error', isError);
}

interface Take {
  animation: Animation;
  buffer: AudioBuffer;
  name: string;
  seconds: number;
  computeMs: number;
  backend: Backend;
}

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
  Object.assign(globalThis, { talkingFace: { view, template: view?.template, gpu: lastGpu, engine, take } });
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
    showStatus(`${baseStatus} Model ${engine.manifest.model.name} ready. Decoder: ${engine.backend} (${engine.backendReason}). Open or drop an audio file, or record.`);
    document.body.dataset.engine = 'ready';
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
    setTake({ animation, buffer: audio.buffer, name: file.name, seconds: src.seconds, computeMs: performance.now() - computeStart, backend: e.backend }, notes);
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
  scrub.disabled = false;
  scrub.max = String(t.animation.frames - 1);
  showFrame(0);
  document.body.dataset.take = 'ready';
}

function showFrame(frame: number): void {
  if (!take?.animation.unposed || !engine) return;
  const n = view.template.vertexCount;
  const f = Math.min(Math.max(0, frame), take.animation.frames - 1);
  current = f;
  view.setVertices(take.animation.unposed.subarray(f * n * 3, (f + 1) * n * 3));
  const p = take.animation.pose;
  const s = engine.unitsPerMm;
  view.setPose(p[f * 6], p[f * 6 + 1], p[f * 6 + 2], p[f * 6 + 3] * s, p[f * 6 + 4] * s, p[f * 6 + 5] * s);
  scrub.value = String(f);
  timeLabel.value = `${(f / take.animation.fps).toFixed(2)} s`;
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
      setTake({ animation, buffer, name: 'Recording', seconds, computeMs, backend: e.backend }, notes);
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
  let i = 0;
  for (const f of chunks) {
    vertices.set(f.vertices, i * per);
    unposed.set(f.unposed, i * per);
    pose.set(f.pose, i * 6);
    i += f.count;
  }
  return { fps, frames: count, vertices, pose, unposed };
}

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
