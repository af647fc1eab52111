/**
 * The demo shell: the only code that touches the page's DOM. It loads the face and the model,
 * animates an audio file the visitor opens or drops, and plays it back with the face in sync.
 */
import { loadTemplate } from '../template/face-template';
import { FaceView } from '../render/face-view';
import { detectWebGPU } from '../gpu/capabilities';
import { TalkingFaceEngine, type Animation } from '../engine/engine';
import { decodeAudio, levels } from '../audio/decode';

const TEMPLATE_URL = '/models/template/template.json';
const MANIFEST_URL = '/models/manifest.json';

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const status = $<HTMLParagraphElement>('status');
const canvas = $<HTMLCanvasElement>('face-canvas');
const fileInput = $<HTMLInputElement>('file-input');
const playButton = $<HTMLButtonElement>('play-button');
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
}

let view: FaceView;
let engine: TalkingFaceEngine | null = null;
let take: Take | null = null;
let audioContext: AudioContext | null = null;
let playing: { source: AudioBufferSourceNode; startedAt: number } | null = null;
let baseStatus = '';

async function start(): Promise<void> {
  const [template, gpu] = await Promise.all([loadTemplate(TEMPLATE_URL), detectWebGPU()]);
  view = new FaceView(canvas, template);
  Object.assign(globalThis, { talkingFace: { view, template, gpu } });
  baseStatus = `Face: ${template.id} (${template.vertexCount} vertices). ` +
    (gpu.available ? `WebGPU adapter: ${gpu.description}.` : `WebGPU: none (${gpu.description}); the CPU path will be used.`);
  showStatus(`${baseStatus} Loading the model…`);
  document.body.dataset.ready = 'true';
  try {
    engine = await TalkingFaceEngine.load({ manifestUrl: MANIFEST_URL });
    Object.assign(globalThis, { talkingFace: { view, template, gpu, engine } });
    showStatus(`${baseStatus} Model ${engine.manifest.model.name} ready (decoder: ${engine.backend}). Open or drop an audio file.`);
    document.body.dataset.engine = 'ready';
  } catch (e) {
    showStatus(`${baseStatus} The model could not be loaded: ${(e as Error).message}`, true);
    document.body.dataset.engine = 'error';
  }
}

async function animateFile(file: File): Promise<void> {
  if (!engine) {
    showStatus('The model is not loaded, so audio cannot be animated yet.', true);
    return;
  }
  stop();
  playButton.disabled = true;
  const t0 = performance.now();
  try {
    showStatus(`Decoding ${file.name}…`);
    const audio = await decodeAudio(file, engine.manifest.audio.sample_rate);
    const lv = levels(audio.samples);
    const notes: string[] = [];
    if (lv.peak < 1e-3) notes.push('the recording is silent, so the mouth stays closed');
    if (lv.clipped > 0.01) notes.push(`${(100 * lv.clipped).toFixed(1)}% of the samples are clipped`);
    engine.resetTimes();
    const animation = await engine.animate(audio.samples, {
      unposed: true,
      onProgress: (done, total) => showStatus(`Animating ${file.name}: frame ${done} of ${total}…`),
    });
    const seconds = (performance.now() - t0) / 1000;
    take = { animation, buffer: audio.buffer, name: file.name };
    Object.assign(globalThis, { talkingFace: { ...(globalThis as unknown as { talkingFace: object }).talkingFace, take } });
    const src = audio.source;
    clipInfo.textContent = `${file.name}: ${src.seconds.toFixed(1)} s, ${src.channels === 1 ? 'mono' : `${src.channels} channels mixed to mono`}`;
    showStatus(`Animated ${animation.frames} frames in ${seconds.toFixed(1)} s (${(src.seconds / seconds).toFixed(1)}x real time, decoder: ${engine.backend}).` +
      (notes.length ? ` Note: ${notes.join('; ')}.` : ''));
    playButton.disabled = false;
    showFrame(0);
    document.body.dataset.take = 'ready';
  } catch (e) {
    showStatus(`Could not animate ${file.name}: ${(e as Error).message}`, true);
    document.body.dataset.take = 'error';
  }
}

function showFrame(frame: number): void {
  if (!take?.animation.unposed) return;
  const n = view.template.vertexCount;
  const f = Math.min(Math.max(0, frame), take.animation.frames - 1);
  view.setVertices(take.animation.unposed.subarray(f * n * 3, (f + 1) * n * 3));
  const p = take.animation.pose;
  const s = engine!.unitsPerMm;
  view.setPose(p[f * 6], p[f * 6 + 1], p[f * 6 + 2], p[f * 6 + 3] * s, p[f * 6 + 4] * s, p[f * 6 + 5] * s);
}

function play(): void {
  if (!take) return;
  audioContext ??= new AudioContext();
  const source = audioContext.createBufferSource();
  source.buffer = take.buffer;
  source.connect(audioContext.destination);
  source.onended = () => stop();
  const startedAt = audioContext.currentTime + 0.05;
  source.start(startedAt);
  playing = { source, startedAt };
  playButton.textContent = 'Stop';
  const tick = () => {
    if (!playing || !take || !audioContext) return;
    showFrame(Math.floor((audioContext.currentTime - playing.startedAt) * take.animation.fps));
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
}

function stop(): void {
  if (playing) {
    playing.source.onended = null;
    playing.source.stop();
    playing = null;
  }
  playButton.textContent = 'Play';
}

fileInput.addEventListener('change', () => {
  const file = fileInput.files?.[0];
  if (file) void animateFile(file);
  fileInput.value = '';
});
playButton.addEventListener('click', () => (playing ? stop() : play()));
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
