/**
 * The demo shell: the only code that touches the page's DOM. It loads the face and the model; animates an audio file the
 * visitor opens or drops, a sample clip, or the microphone live; and plays the take back in sync through the shared Player.
 */
import { FaceView } from '../render/face-view';
import type { WebGPUSupport } from '../gpu/capabilities';
import type { TalkingFaceEngine, Backend } from '../engine/engine';
import { decodeAudio } from '../audio/decode';
import { Player } from '../player/player';
import { TakeView, animateAudio, redrawHead, type Take } from './take-view';
import { Recording } from './recording';
import { MicrophoneChoice } from './microphone-choice';
import { fetchSample, fillSampleSelect, markSample, type SampleIndex } from './samples';
import { setupDetails, decoderDetails, switchBackend, takeDetails, bindDetailsPanel } from './details';
import { exportGlb, inspectGlb } from './export-glb';
import { cancelExport, exportGlbFile, exportRawFile, exportVideoFile } from './export-ui';
import { ui, showStatus, tell, announce, lockWidth, bindControls, enableControls, type HeadChange } from './controls';
import { isolated } from './names';
import { bindKeys } from './keyboard';
import { innerLipGaps } from '../template/lip-gap';
import { startLoading } from './startup';

let view: FaceView, player: Player, takeView: TakeView;
let engine: TalkingFaceEngine | null = null;
let autoBackend: Backend = 'cpu', take: Take | null = null;
let sampleIndex: SampleIndex | null = null;
let busy: AbortController | null = null;
let recording: Recording | null = null, recordPending = false;
let starting: AbortController | null = null; // Escape cancels a recording still starting (the browser asking for the microphone)
let finishing = false; // a recording's take being finished
let headRedraw = false; // the clip being animated is the take's head drawn again
let lastGpu: WebGPUSupport | null = null;
let modelSettled = (): void => undefined;
const modelTried = new Promise<void>((resolve) => (modelSettled = resolve)); // start() has the model in, or has failed to
/** The current take's most important note about its audio (silent, no speech, clipped, short), or ''. */
let takeNote = '';
const microphones = new MicrophoneChoice(ui.microphoneSelect);

function publish(): void {
  Object.assign(globalThis, { talkingFace: {
    view, template: view?.template, gpu: lastGpu, engine, take, truthView: takeView?.truthView ?? null, inspectGlb, innerLipGaps,
    exportGlb: async () => (take && engine ? exportGlb(take.animation, view.template, engine.unitsPerMm) : null),
  } });
}

/**
 * Start the face and the model together: the template, the model's files and onnxruntime arrive in parallel, and
 * each ONNX session is created as soon as its file is in (engine.ts), while the face is being drawn.
 */
async function start(): Promise<void> {
  const loading = startLoading();
  const { template: face, gpu } = await loading.face;
  lastGpu = gpu;
  view = new FaceView(ui.canvas, face, { lifePaused: true }); // still until the model is ready (face-view.ts)
  player = new Player(view, 1, { onFrame: (f) => take && engine && takeView.frameShown(take, engine, f, player.isPlaying), onEnded: () => showPaused('Finished playing'),
    onBlocked: () => tell('Click or press a key to hear it: the browser plays sound only after a gesture on the page.'), onUnblocked: () => take && tell(`Playing ${isolated(take.name)}.`) });
  takeView = new TakeView(view);
  player.loop = ui.loopCheck.checked; // as ticked while the face loaded, or as the browser restored the page (TakeView too)
  publish();
  ui.setupInfo.textContent = setupDetails(face, gpu);
  showStatus('Loading the model…');
  void view.drawn.then(() => (document.body.dataset.ready ||= 'true'));
  try {
    engine = await loading.engine;
    player.unitsPerMm = engine.unitsPerMm;
    autoBackend = engine.backend;
    if (!gpu.available) ui.backendSelect.querySelector<HTMLOptionElement>('option[value="webgpu"]')!.disabled = true;
    ui.backendSelect.disabled = false; // (a choice made before the engine was there would not have been applied)
    publish();
    ui.setupInfo.textContent += ` Model ${engine.manifest.model.name}. ${decoderDetails(engine)}`;
    const ready = 'Ready: open or drop an audio file, choose a sample, or press Record.';
    tell(ready);
    document.body.dataset.engine = 'ready';
    void fillSampleSelect(ui.sampleSelect).then((index) => {
      sampleIndex = index;
      // A model served without sample clips: the message names only what there is (if nothing has been said since).
      if (!index && ui.status.textContent === ready) tell('Ready: open or drop an audio file, or press Record.');
    });
    engine.restFace().then((rest) => {
      view.setRestFace(rest); // the mouth closed at rest, not the opened template
      document.body.dataset.rest = 'shown';
    }, (err: Error) => tell(`The face at rest could not be computed: ${err.message}`, true));
  } catch (e) {
    ui.setupInfo.textContent += ` The model could not be loaded: ${(e as Error).message}.`;
    tell('The model could not be loaded. The face can still be viewed; reload the page to try again (Details says why).', true);
    document.body.dataset.engine = 'error';
  } finally {
    view.setLifePaused(false); // loaded or not, nothing more competes with the face for the main thread
    modelSettled();
  }
}

/** The model, or null with why not: still loading, or failed (where the demo could not start, its message stays). */
function needEngine(): TalkingFaceEngine | null {
  const failed = Boolean(document.body.dataset.engine); // ('ready' sets engine first)
  if (!engine && document.body.dataset.ready !== 'error') tell(failed ? 'The model is not loaded, so audio cannot be animated. Reload the page to try again.' : 'The model is still loading: press Record again once it is ready.', failed); // (not started: its message stays)
  return engine;
}

/** The model once it is in (`signal`: cancelled meanwhile, its reason thrown); an Error where it could not be loaded. */
async function modelIn(waiting: string, signal: AbortSignal): Promise<TalkingFaceEngine> {
  if (!engine) showStatus(waiting);
  if (!engine) await Promise.race([modelTried, new Promise((resolve) => signal.addEventListener('abort', resolve, { once: true }))]);
  signal.throwIfAborted();
  if (!engine) throw new Error('the model could not be loaded (Details says why); reload the page to try again');
  return engine;
}

const refreshControls = (): void => enableControls({ take: Boolean(take), busy: Boolean(busy), headRedraw,
  recording: Boolean(recording) || finishing, headMotion: Boolean(engine?.hasHeadMotion) });

function setBusy(controller: AbortController | null, isHeadRedraw = false): void {
  [busy, headRedraw] = [controller, isHeadRedraw];
  refreshControls();
  if (!controller) markSample(ui.sampleSelect, sampleIndex, take?.name); // a sample cancelled or failed is not shown: choosing it again retries
}

/** Animate a clip under a cancellable busy state, then play it: opening a file is asking to hear it. */
async function animateTake(label: string, run: (e: TalkingFaceEngine, signal: AbortSignal) => Promise<Take | null>, headRedraw = false): Promise<void> {
  if ((!engine && document.body.dataset.engine) || recording || recordPending || finishing) { // (recordPending: the microphone is being asked for, or let go)
    if (!engine) needEngine(); // (failed: says so)
    else if (finishing) tell('Finishing the recording: open the file or sample once it is ready.');
    else if (recording || recordPending) tell(recording ? 'Recording: stop it first (Stop recording or Escape), then open a file or a sample.' : 'The recording is starting (the browser may be asking for the microphone): Escape cancels it; then open a file or a sample.');
    markSample(ui.sampleSelect, sampleIndex, take?.name);
    return;
  }
  busy?.abort();
  stopPlayback();
  const controller = new AbortController();
  setBusy(controller, headRedraw);
  announce(`Animating ${label}…`);
  try {
    const e = engine ?? (await modelIn(`The model is still loading: ${label} is animated once it is in (Escape cancels)…`, controller.signal)); // (in: no await)
    const t = await run(e, controller.signal);
    if (t) {
      document.body.dataset.take = 'ready';
      play();
    }
  } catch (err) {
    if (controller.signal.aborted) {
      if (busy !== controller) return; // another clip took its place: that one speaks for itself
      tell(headRedraw ? 'Stopped drawing the head again: the take is as it was.' : `Stopped animating ${label}. Open another file or record.`);
      document.body.dataset.take = take ? 'ready' : 'cancelled';
    } else if (document.body.dataset.ready !== 'error') { // (the demo could not start meanwhile: its message stays)
      tell(`Could not ${label === 'the sample' ? 'open the sample' : `animate ${label}`}: ${(err as Error).message}`, true);
      document.body.dataset.take = 'error';
    }
  } finally {
    if (busy === controller) setBusy(null);
  }
}

function animateFile(file: File): Promise<void> {
  return animateTake(isolated(file.name), async (e, signal) => {
    showStatus(`Decoding ${isolated(file.name)}…`);
    const audio = await decodeAudio(file, e.manifest.audio.sample_rate, signal); // Cancel need not wait for a long decode
    const src = audio.source;
    const { animation, computeMs, samples, notes } = await animateAudio(e, file.name, audio.samples, src.seconds, signal, src.statedSeconds);
    ui.clipInfo.textContent = `${isolated(file.name)}: ${src.seconds.toFixed(1)} s, ${src.channels === 1 ? 'mono' : `${src.channels} channels mixed to mono`}.`;
    return setTake({ animation, buffer: audio.buffer, samples, name: file.name, seconds: src.seconds, computeMs, backend: e.backend, notes });
  });
}

function openSample(name: string): Promise<void> {
  const c = sampleIndex?.clips.find((x) => x.name === name);
  if (!c) return Promise.resolve();
  return animateTake('the sample', async (e, signal) => {
    showStatus(`Loading the sample "${c.text}"…`);
    const { audio: bytes, truth } = await fetchSample(c, view.template.vertexCount, e.unitsPerMm, signal);
    const audio = await decodeAudio(bytes, e.manifest.audio.sample_rate);
    ui.clipInfo.textContent = `Sample (test split: unseen voice, sentence and face): "${c.text}".`;
    const { animation, computeMs, samples, notes } = await animateAudio(e, 'the sample', audio.samples, c.seconds, signal);
    return setTake({ animation, buffer: audio.buffer, samples, name: c.name, seconds: c.seconds, computeMs, backend: e.backend, truth, notes });
  });
}

/** A take to show and play: its figures in the details, its most important note (if any) kept for the status line. */
function setTake(t: Take): Take {
  const notes = t.notes ?? [];
  take = t;
  markSample(ui.sampleSelect, sampleIndex, t.name);
  player.load(t.animation, t.buffer, takeView.drawn(t));
  publish();
  ui.takeInfo.textContent = takeDetails(t, notes) + (t.truth && engine ? ` E_vl on this clip: ${takeView.lipError(t, engine).toFixed(2)} mm.` : '');
  ui.exportInfo.textContent = '';
  takeNote = notes.length ? `${isolated(t.name)}: ${notes[0]}.` : '';
  ui.playButton.textContent = 'Play'; // loading it stopped any playback
  refreshControls();
  ui.scrub.max = String(t.animation.frames - 1);
  if (engine) takeView.showTimeline(t, engine);
  takeView.setSideBySide(ui.sideCheck.checked, t, false); // the truth pane follows the take
  player.show(0);
  return t;
}

/** The take's head motion drawn again, with the next seed or at a new scale (the lips and eyes do not change). */
function redrawTakeHead(change: HeadChange): void {
  if (engine?.hasHeadMotion && take) void animateTake(isolated(take.name), async (e, signal) => setTake(await redrawHead(e, take!, signal, change)), true);
}

function play(): void {
  if (!take) return;
  ui.playButton.textContent = 'Pause';
  tell(takeNote ? `Playing. ${takeNote}` : `Playing ${isolated(take.name)}: Space or Escape pauses.`);
  void player.play();
}

/** After playback stops: the status says so (keeping the take's note) and what to do next. */
function showPaused(what: string): void {
  ui.playButton.textContent = 'Play';
  if (take) tell(takeNote ? `${what}. ${takeNote}` : `${what}: press Play to watch it again, or open another file.`);
}

function stopPlayback(): void {
  if (!player?.isPlaying) return;
  player.stop();
  showPaused('Paused');
  takeView.paint(take, engine, player.current, false); // an attention map is drawn for the paused frame
}

/** Record starts and stops the microphone take. The button stays enabled (and keeps the focus) while it changes state. */
async function toggleRecording(): Promise<void> {
  const e = needEngine(); // (null: says why not)
  if (!e || recordPending) return;
  recordPending = true;
  ui.recordButton.setAttribute('aria-disabled', 'true');
  try {
    await (recording ? stopRecording(e, recording) : startRecording(e));
  } finally {
    recordPending = false;
    ui.recordButton.removeAttribute('aria-disabled');
  }
}

async function startRecording(e: TalkingFaceEngine): Promise<void> {
  stopPlayback();
  const start = (starting = new AbortController());
  showStatus('Opening the microphone (the browser may ask you first; Escape cancels)…');
  try {
    const r = await Recording.start(e, () => microphones.open(), (f) => player.showLive(f, e.fps), tell, start.signal);
    stopPlayback(); // played while the microphone opened
    recording = r;
    refreshControls();
    ui.recordButton.textContent = 'Stop recording';
    ui.recordButton.classList.add('recording'); // its label says the state: no aria-pressed beside it
    document.body.dataset.recording = 'true';
    tell('Recording: the face follows your voice. Press Stop recording or Escape to stop.');
    r.follow((line) => { ui.takeInfo.textContent = line; }, tell);
  } catch (err) {
    if (start.signal.aborted) return tell('Recording cancelled before it started. Press Record to try again.');
    tell(`${(err as Error).message}`, true);
    document.body.dataset.recording = 'error';
  } finally {
    starting = null;
  }
}

async function stopRecording(e: TalkingFaceEngine, r: Recording): Promise<void> {
  [recording, finishing] = [null, true];
  ui.recordButton.textContent = 'Record';
  ui.recordButton.classList.remove('recording');
  tell('Recording stopped; finishing the take…');
  const controller = new AbortController(); // Cancel and Escape stop the take's animation, where it needs one
  const reanimating = (f: number, all: number) => {
    if (!busy) setBusy(controller); // Record stays enabled (aria-disabled: toggleRecording), with the focus
    showStatus(`Animating the whole take (frames were skipped live to keep up): frame ${f} of ${all}…`);
  };
  try {
    const done = await r.finish(reanimating, controller.signal);
    if (!done) return tell('The take was too short to animate. Press Record and speak for a moment.', true);
    ui.clipInfo.textContent = `Recording: ${done.seconds.toFixed(1)} s.`;
    setTake({ ...done, name: 'Recording', backend: e.backend });
    const held = done.heldFrames && `Stopped animating the whole take: it keeps the live frames (the ${done.heldFrames} skipped to keep up hold the frame before them). Press Play.`;
    tell(held || takeNote || 'Recording is ready: press Play.');
    document.body.dataset.take = 'ready';
  } catch (err) {
    if (controller.signal.aborted) tell('Stopped finishing the recording before any frame was made: the take is discarded. Press Record to record again.');
    else tell(`The recording could not be finished: ${(err as Error).message}`, true);
  } finally {
    finishing = false;
    if (busy === controller) setBusy(null); // which refreshes the controls
    else refreshControls();
  }
}

/** Escape: cancel a .glb being prepared, else a recording starting, else stop recording, else playback, else the clip being animated. */
function escape(): boolean {
  if (cancelExport()) return true;
  if (starting) starting.abort();
  else if (recording) void toggleRecording();
  else if (player?.isPlaying) stopPlayback();
  else if (busy) busy.abort();
  else return false;
  return true;
}

const togglePlay = (): void => (player?.isPlaying ? stopPlayback() : recording || finishing ? undefined : play());
const showFrame = (frame: number): void => { if (!recording && !finishing) { stopPlayback(); player.show(frame); } };

bindControls({
  openFile: (file) => void animateFile(file),
  openSample: (name) => void openSample(name),
  toggleRecording: () => void toggleRecording(),
  cancel: () => busy?.abort(),
  togglePlay,
  seek: showFrame,
  unlockAudio: () => player?.unlock(),
  setLoop: (on) => player && (player.loop = on), // (before the face is there: read once it is, in start())
  setArrows: (on) => takeView?.setArrows(on),
  repaint: () => takeView?.paint(take, engine, player.current, player.isPlaying),
  setSideBySide: (on) => { if (!takeView) return; takeView.setSideBySide(on, take); publish(); if (take) player.show(player.current); },
  pick: (at) => takeView?.pick(at) && takeView.paint(take, engine, player.current, player.isPlaying),
  setBackend: (choice) => engine && switchBackend(engine, choice === 'auto' ? autoBackend : (choice as Backend)),
  exportVideo: () => take && void exportVideoFile(view, player, take.animation.fps, take.name),
  exportGlb: () => take && engine && void exportGlbFile(take.animation, take.name, view.template, engine.unitsPerMm),
  exportRaw: () => take && exportRawFile(take.animation, take.name, view.template),
  redrawHead: redrawTakeHead,
});

bindDetailsPanel(), bindKeys({ escape, hasTake: () => take !== null, togglePlay, step: (delta) => showFrame(player.current + delta), view: () => view ?? null }); // null until drawn
for (const b of [ui.playButton, ui.recordButton]) lockWidth(b);

start().catch((e: Error) => {
  tell(`Could not start: ${e.message}`, true);
  document.body.dataset.ready = 'error';
  document.body.dataset.engine ||= 'error'; // (nothing to wait for: a file opened says the model is not loaded)
  modelSettled();
  console.error(e);
});
