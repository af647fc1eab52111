/**
 * The demo shell: the only code that touches the page's DOM. It loads the face and the model; animates
 * an audio file the visitor opens or drops, a sample clip, or the microphone live while they speak; and plays
 * the take back with the face in sync (play, pause, scrub, loop) through the shared Player.
 */
import { loadTemplate, type FaceTemplate } from '../template/face-template';
import { FaceView } from '../render/face-view';
import { detectWebGPU } from '../gpu/capabilities';
import { TalkingFaceEngine, type Animation, type Backend } from '../engine/engine';
import { DEFAULT_TEMPLATE_URL, fetchManifest, templateUrlOf } from '../model/artefacts';
import type { Manifest } from '../model/manifest';
import { decodeAudio } from '../audio/decode';
import { Player, audioNotes } from '../player/player';
import { simdUnavailable } from '../attention/simd-kernel';
import { TakeView, type Take } from './take-view';
import { Recording } from './recording';
import { fetchSample, fetchSampleIndex, type SampleIndex } from './samples';
import { exportGlb, inspectGlb } from './export-glb';
import { exportGlbFile, exportRawFile } from './export-ui';
import { ui, showStatus, bindControls } from './controls';

let view: FaceView;
let player: Player;
let takeView: TakeView;
let engine: TalkingFaceEngine | null = null;
let autoBackend: Backend = 'cpu';
let take: Take | null = null;
let sampleIndex: SampleIndex | null = null;
let busy: AbortController | null = null;
let recording: Recording | null = null;
let lastGpu: Awaited<ReturnType<typeof detectWebGPU>> | null = null;

function publish(): void {
  Object.assign(globalThis, {
    talkingFace: {
      view, template: view?.template, gpu: lastGpu, engine, take, truthView: takeView?.truthView ?? null,
      exportGlb: async () => (take && engine ? exportGlb(take.animation, view.template, engine.unitsPerMm) : null),
      inspectGlb,
    },
  });
}

/** The manifest if it can be read (its error otherwise), and the face template it names (the default one without it). */
async function loadFace(): Promise<{ template: FaceTemplate; manifest: { manifest: Manifest; manifestUrl: URL } | Error }> {
  const manifest = await fetchManifest(undefined).catch((e: Error) => e);
  const url = manifest instanceof Error ? DEFAULT_TEMPLATE_URL : templateUrlOf(manifest.manifest, manifest.manifestUrl);
  return { template: await loadTemplate(url), manifest };
}

async function start(): Promise<void> {
  const [{ template, manifest }, gpu] = await Promise.all([loadFace(), detectWebGPU()]);
  lastGpu = gpu;
  view = new FaceView(ui.canvas, template);
  player = new Player(view, 1, { onFrame: (f) => take && engine && takeView.frameShown(take, engine, f, player.isPlaying), onEnded: () => (ui.playButton.textContent = 'Play') });
  takeView = new TakeView(view);
  publish();
  const base = `Face: ${template.id} (${template.vertexCount} vertices). ` +
    (gpu.available ? `WebGPU adapter: ${gpu.description}.` : `WebGPU: none (${gpu.description}); the CPU path will be used.`);
  showStatus(`${base} Loading the model…`);
  document.body.dataset.ready = 'true';
  try {
    if (manifest instanceof Error) throw manifest;
    engine = await TalkingFaceEngine.load({ ...manifest, template });
    player.unitsPerMm = engine.unitsPerMm;
    autoBackend = engine.backend;
    if (!gpu.available) ui.backendSelect.querySelector<HTMLOptionElement>('option[value="webgpu"]')!.disabled = true;
    publish();
    showStatus(`${base} Model ${engine.manifest.model.name} ready. Decoder: ${engine.backend} (${engine.backendReason}; CPU decoder: ${engine.cpuKernel === 'wasm-simd' ? 'WebAssembly SIMD' : `JavaScript (no SIMD: ${simdUnavailable || 'unavailable'})`} on ${engine.cpuThreads} thread${engine.cpuThreads > 1 ? 's' : ''}). Open or drop an audio file, or record.`);
    document.body.dataset.engine = 'ready';
    void loadSamples();
    engine.restFace().then(
      (rest) => {
        view.setRestFace(rest); // the mouth closed at rest, not the opened template
        document.body.dataset.rest = 'shown';
      },
      (err: Error) => showStatus(`The face at rest could not be computed: ${err.message}`, true),
    );
  } catch (e) {
    showStatus(`${base} The model could not be loaded: ${(e as Error).message}. The face can still be viewed.`, true);
    document.body.dataset.engine = 'error';
  }
}

function needEngine(): TalkingFaceEngine | null {
  if (!engine) showStatus('The model is not loaded, so audio cannot be animated. Reload the page to try again.', true);
  return engine;
}

function setBusy(controller: AbortController | null): void {
  busy = controller;
  ui.cancelButton.hidden = !controller;
  ui.recordButton.disabled = Boolean(controller);
}

/** Animate `samples` under a cancellable busy state; `label` names it in the progress line. */
async function animateTake(label: string, run: (e: TalkingFaceEngine, signal: AbortSignal) => Promise<Take | null>): Promise<void> {
  const e = needEngine();
  if (!e || recording) return;
  busy?.abort();
  stopPlayback();
  const controller = new AbortController();
  setBusy(controller);
  try {
    const t = await run(e, controller.signal);
    if (t) document.body.dataset.take = 'ready';
  } catch (err) {
    if (controller.signal.aborted) {
      showStatus(`Stopped animating ${label}. Open another file or record.`);
      document.body.dataset.take = take ? 'ready' : 'cancelled';
    } else {
      showStatus(`Could not ${label === 'the sample' ? 'open the sample' : `animate ${label}`}: ${(err as Error).message}`, true);
      document.body.dataset.take = 'error';
    }
  } finally {
    if (busy === controller) setBusy(null);
  }
}

function animateFile(file: File): Promise<void> {
  return animateTake(file.name, async (e, signal) => {
    showStatus(`Decoding ${file.name}…`);
    const audio = await decodeAudio(file, e.manifest.audio.sample_rate);
    const src = audio.source;
    const notes = audioNotes(audio.samples, src.seconds);
    ui.clipInfo.textContent = `${file.name}: ${src.seconds.toFixed(1)} s, ${src.channels === 1 ? 'mono' : `${src.channels} channels mixed to mono`}`;
    e.resetTimes();
    const t0 = performance.now();
    const animation = await e.animate(audio.samples, {
      unposed: true,
      signal,
      onProgress: (done, total) => showStatus(`Animating ${file.name}: frame ${done} of ${total} (${Math.round((100 * done) / total)}%)…` + (notes.length ? ` Note: ${notes.join('; ')}.` : '')),
    });
    return setTake({ animation, buffer: audio.buffer, samples: audio.samples, name: file.name, seconds: src.seconds, computeMs: performance.now() - t0, backend: e.backend }, notes);
  });
}

function openSample(name: string): Promise<void> {
  const c = sampleIndex?.clips.find((x) => x.name === name);
  if (!c) return Promise.resolve();
  return animateTake('the sample', async (e, signal) => {
    showStatus(`Loading the sample "${c.text}"…`);
    const { audio: bytes, truth } = await fetchSample(c, view.template.vertexCount, e.unitsPerMm);
    const audio = await decodeAudio(bytes, e.manifest.audio.sample_rate);
    e.resetTimes();
    const t0 = performance.now();
    const animation = await e.animate(audio.samples, { unposed: true, signal, onProgress: (done, total) => showStatus(`Animating the sample: frame ${done} of ${total}…`) });
    ui.clipInfo.textContent = `Sample (test split: unseen voice, sentence and face): "${c.text}"`;
    const t = setTake({ animation, buffer: audio.buffer, samples: audio.samples, name: c.name, seconds: c.seconds, computeMs: performance.now() - t0, backend: e.backend, truth });
    showStatus(`${ui.status.textContent} E_vl on this clip: ${takeView.lipError(t, e).toFixed(2)} mm.`);
    return t;
  });
}

function setTake(t: Take, notes: string[] = []): Take {
  take = t;
  player.load(t.animation, t.buffer, takeView.drawn(t));
  publish();
  const perFrame = t.computeMs / t.animation.frames;
  showStatus(`${t.name}: ${t.animation.frames} frames. Decoder ${t.backend}: ${perFrame.toFixed(1)} ms per frame, ` +
    `${(t.seconds / (t.computeMs / 1000)).toFixed(1)}x real time.` + (notes.length ? ` Note: ${notes.join('; ')}.` : ''));
  for (const b of [ui.playButton, ui.exportGlbButton, ui.exportRawButton, ui.scrub]) b.disabled = false;
  ui.headRerollButton.disabled = !engine?.hasHeadMotion;
  ui.scrub.max = String(t.animation.frames - 1);
  if (engine) takeView.showTimeline(t, engine);
  player.show(0);
  return t;
}

async function loadSamples(): Promise<void> {
  try {
    sampleIndex = await fetchSampleIndex();
    for (const c of sampleIndex.clips) {
      const o = document.createElement('option');
      o.value = c.name;
      o.textContent = `"${c.text}" (${c.source === 'human' ? 'recorded voice' : c.voice}, ${c.seconds.toFixed(1)} s)`;
      ui.sampleSelect.append(o);
    }
  } catch (e) {
    ui.sampleSelect.disabled = true;
    ui.sampleSelect.title = `No sample clips: ${(e as Error).message}`;
  }
}

/** The same take with the head's own motion drawn again (the lips and eyes do not change). */
function rerollHead(): Promise<void> {
  const t = take;
  if (!t || !engine?.hasHeadMotion) return Promise.resolve();
  return animateTake(t.name, async (e, signal) => {
    e.headMotionSeed = (e.headMotionSeed ?? 0) + 1;
    const t0 = performance.now();
    const animation = await e.animate(t.samples, { unposed: true, signal });
    setTake({ ...t, animation, computeMs: performance.now() - t0, lipError: undefined });
    showStatus(`${ui.status.textContent} Head motion drawn with seed ${e.headMotionSeed}.`);
    document.body.dataset.headSeed = String(e.headMotionSeed);
    return take;
  });
}

function play(): void {
  if (!take) return;
  ui.playButton.textContent = 'Pause';
  void player.play();
}

function stopPlayback(): void {
  player?.stop();
  ui.playButton.textContent = 'Play';
}

async function toggleRecording(): Promise<void> {
  const e = needEngine();
  if (!e) return;
  if (recording) {
    const r = recording;
    recording = null;
    ui.recordButton.textContent = 'Record';
    ui.recordButton.setAttribute('aria-pressed', 'false');
    ui.recordButton.disabled = true;
    showStatus('Finishing the take…');
    try {
      const done = await r.finish(() => showStatus('Animating the whole take (some frames were skipped live to keep up)…'));
      if (!done) return showStatus('The take was too short to animate. Press Record and speak for a moment.', true);
      const notes = audioNotes(done.samples, done.seconds).map((n) => n.replace('the audio is silent', 'the take is silent (is the microphone muted?)'));
      ui.clipInfo.textContent = `Recording: ${done.seconds.toFixed(1)} s`;
      setTake({ ...done, name: 'Recording', backend: e.backend }, notes);
      document.body.dataset.take = 'ready';
    } catch (err) {
      showStatus(`The recording could not be finished: ${(err as Error).message}`, true);
    } finally {
      ui.recordButton.disabled = false;
    }
    return;
  }
  stopPlayback();
  ui.recordButton.disabled = true;
  try {
    const r = await Recording.start(e, (f) => player.showLive(f), (err) => showStatus(`Live animation stopped: ${err.message}`, true));
    recording = r;
    ui.recordButton.textContent = 'Stop recording';
    ui.recordButton.setAttribute('aria-pressed', 'true');
    document.body.dataset.recording = 'true';
    const update = () => {
      if (recording !== r) return;
      showStatus(r.describe());
      setTimeout(update, 250);
    };
    update();
  } catch (err) {
    showStatus(`${(err as Error).message}`, true);
    document.body.dataset.recording = 'error';
  } finally {
    ui.recordButton.disabled = false;
  }
}

bindControls({
  openFile: (file) => void animateFile(file),
  openSample: (name) => void openSample(name),
  toggleRecording: () => void toggleRecording(),
  cancel: () => busy?.abort(),
  togglePlay: () => (player?.isPlaying ? stopPlayback() : play()),
  seek: (frame) => {
    stopPlayback();
    player.show(frame);
  },
  step: (delta) => {
    stopPlayback();
    player.show(player.current + delta);
  },
  hasTake: () => take !== null,
  setLoop: (on) => (player.loop = on),
  setArrows: (on) => takeView.setArrows(on),
  repaint: () => takeView.paint(take, engine, player.current, player.isPlaying),
  setSideBySide: (on) => {
    takeView.setSideBySide(on, take);
    publish();
    if (take) player.show(player.current);
  },
  pick: (x, y) => takeView.pick(x, y) && takeView.paint(take, engine, player.current, player.isPlaying),
  setBackend: (choice) => {
    if (!engine) return;
    const want: Backend = choice === 'auto' ? autoBackend : (choice as Backend);
    engine.setBackend(want).then(
      () => showStatus(`Decoder: ${engine!.backend}. New animations use it.`),
      (err: Error) => showStatus(`Cannot use ${want}: ${err.message}`, true),
    );
  },
  exportGlb: () => take && engine && void exportGlbFile(take.animation, take.name, view.template, engine.unitsPerMm),
  exportRaw: () => take && exportRawFile(take.animation, take.name, view.template),
  rerollHead: () => void rerollHead(),
});

start().catch((e: Error) => {
  showStatus(`Could not start: ${e.message}`, true);
  document.body.dataset.ready = 'error';
  console.error(e);
});
