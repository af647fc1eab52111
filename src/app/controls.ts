/** The demo page's elements and their events: what each control asks for, handed to main.ts as plain calls. */

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;

export const ui = {
  status: $<HTMLParagraphElement>('status'),
  canvas: $<HTMLCanvasElement>('face-canvas'),
  fileInput: $<HTMLInputElement>('file-input'),
  recordButton: $<HTMLButtonElement>('record-button'),
  microphoneSelect: $<HTMLSelectElement>('microphone-select'),
  cancelButton: $<HTMLButtonElement>('cancel-button'),
  backendSelect: $<HTMLSelectElement>('backend-select'),
  playButton: $<HTMLButtonElement>('play-button'),
  loopCheck: $<HTMLInputElement>('loop-check'),
  scrub: $<HTMLInputElement>('scrub'),
  timeLabel: $<HTMLSpanElement>('time-label'),
  clipInfo: $<HTMLParagraphElement>('clip-info'),
  setupInfo: $<HTMLParagraphElement>('setup-info'),
  takeInfo: $<HTMLParagraphElement>('take-info'),
  exportInfo: $<HTMLParagraphElement>('export-info'),
  announcer: $<HTMLParagraphElement>('announce'),
  sampleSelect: $<HTMLSelectElement>('sample-select'),
  arrowsCheck: $<HTMLInputElement>('arrows-check'),
  paintSelect: $<HTMLSelectElement>('paint-select'),
  sideCheck: $<HTMLInputElement>('side-check'),
  gtView: $<HTMLElement>('gt-view'),
  gtCanvas: $<HTMLCanvasElement>('gt-canvas'),
  legend: $<HTMLParagraphElement>('legend'),
  exportGlbButton: $<HTMLButtonElement>('export-glb'),
  exportVideoButton: $<HTMLButtonElement>('export-video'),
  exportRawButton: $<HTMLButtonElement>('export-raw'),
  headRerollButton: $<HTMLButtonElement>('head-reroll'),
  headScale: $<HTMLInputElement>('head-scale'),
  stage: $<HTMLElement>('stage'),
  dropHint: $<HTMLParagraphElement>('drop-hint'),
  timeline: $<HTMLCanvasElement>('timeline'),
  details: $<HTMLDetailsElement>('details'),
  detailsBody: $<HTMLDivElement>('details-body'),
};

/** What changes when the head's own motion is drawn again: the next seed (New head motion), or its scale (the slider). */
export type HeadChange = { nextSeed?: boolean; scale?: number };

/** What the take's controls depend on: a take shown, a clip being animated (and whether it is the head being redrawn), the microphone. */
export interface ControlsState { take: boolean; busy: boolean; headRedraw: boolean; recording: boolean; headMotion: boolean }

/**
 * Which controls work now. Playing, scrubbing and exporting need a take, and not the microphone driving the face
 * (recording, or its take being finished); the head's controls redraw the take, so not while another clip is being
 * animated (it would replace it); Record not while a clip is animated; Cancel only then; the microphone's choice
 * not while one is recording.
 */
export function enableControls(s: ControlsState): void {
  const playable = s.take && !s.recording;
  for (const b of [ui.playButton, ui.exportVideoButton, ui.exportGlbButton, ui.exportRawButton, ui.scrub]) b.disabled = !playable;
  ui.headRerollButton.disabled = ui.headScale.disabled = !playable || !s.headMotion || (s.busy && !s.headRedraw);
  ui.recordButton.disabled = s.busy && !s.recording; // while a take is finished it keeps the focus (aria-disabled)
  ui.microphoneSelect.disabled = s.recording;
  // Cancel hides once the work ends: its focus goes to what comes next, not to the page's start.
  if (!s.busy && document.activeElement === ui.cancelButton) (playable ? ui.playButton : ui.recordButton).focus();
  ui.cancelButton.hidden = !s.busy;
}

/** The head-motion slider's value in words, for screen readers and the details. */
export function headScaleText(scale: number): string {
  return scale === 1 ? '1 times, as learnt' : scale === 0 ? '0: the head keeps its mean pose' : `${scale} times, ${scale < 1 ? 'calmer' : 'livelier'}`;
}

/** The status line: one short sentence of what happened and what to do next (the full text also on hover). */
export function showStatus(text: string, isError = false): void {
  ui.status.textContent = text;
  ui.status.title = text;
  ui.status.classList.toggle('error', isError);
}

/** The same news within this long is one change told twice: announced once. */
const REPEAT_MS = 1000;
let announced = { text: '', at: -Infinity };

/**
 * Tell screen readers of a change of state, once: the live region hears of ready, playing, recording, errors, never of
 * progress. The same news again later (a second export saved) is heard again: the region is emptied, then refilled.
 */
export function announce(text: string): void {
  const at = performance.now();
  const again = text === announced.text;
  if (again && at - announced.at < REPEAT_MS) return;
  announced = { text, at };
  ui.announcer.textContent = again ? '' : text;
  if (again) setTimeout(() => { if (announced.text === text) ui.announcer.textContent = text; }, 60); // (unless other news came)
}

/** A change of state: the status line says it and the live region announces it. */
export function tell(text: string, isError = false): void {
  showStatus(text, isError);
  announce(text);
}

/** Fix a button's width to that of its widest label (data-labels="Play|Pause"), so changing its label moves nothing. */
export function lockWidth(button: HTMLButtonElement): void {
  const labels = (button.dataset.labels ?? '').split('|');
  const shown = button.textContent;
  let widest = 0;
  for (const label of labels) {
    button.textContent = label;
    widest = Math.max(widest, button.getBoundingClientRect().width);
  }
  button.textContent = shown;
  button.style.minWidth = `${Math.ceil(widest)}px`;
}

/** Show a legend line (HTML: it may hold the colour ramp), or hide it with null. */
export function showLegend(html: string | null): void {
  ui.legend.hidden = html === null;
  if (html !== null) ui.legend.innerHTML = html;
}

export interface ControlActions {
  openFile(file: File): void;
  openSample(name: string): void;
  toggleRecording(): void;
  cancel(): void;
  togglePlay(): void;
  seek(frame: number): void;
  unlockAudio(): void;
  setLoop(on: boolean): void;
  setArrows(on: boolean): void;
  repaint(): void;
  setSideBySide(on: boolean): void;
  /** When painting one vertex's attention: a click on the face (client coordinates), or [ / ] (-1, 1) by keyboard. */
  pick(at: { x: number; y: number } | number): void;
  setBackend(choice: string): void;
  exportVideo(): void;
  exportGlb(): void;
  exportRaw(): void;
  /** Draw the head's own motion again: with another seed, or scaled (1: as learnt). */
  redrawHead(change: HeadChange): void;
}

export function bindControls(a: ControlActions): void {
  ui.sampleSelect.addEventListener('change', () => {
    a.unlockAudio(); // a choice is a gesture (by mouse or keyboard): the sample may play once animated
    if (ui.sampleSelect.value) a.openSample(ui.sampleSelect.value);
  });
  ui.arrowsCheck.addEventListener('change', () => a.setArrows(ui.arrowsCheck.checked));
  ui.paintSelect.addEventListener('change', () => a.repaint());
  ui.sideCheck.addEventListener('change', () => a.setSideBySide(ui.sideCheck.checked));
  ui.loopCheck.addEventListener('change', () => a.setLoop(ui.loopCheck.checked));
  ui.canvas.addEventListener('click', (ev) => {
    if (ui.paintSelect.value === 'vertex-attention') a.pick({ x: ev.clientX, y: ev.clientY });
  });
  ui.canvas.addEventListener('keydown', (ev) => {
    if (ui.paintSelect.value !== 'vertex-attention' || (ev.key !== '[' && ev.key !== ']')) return;
    ev.preventDefault();
    a.pick(ev.key === ']' ? 1 : -1);
  });
  ui.exportVideoButton.addEventListener('click', () => a.exportVideo());
  ui.exportGlbButton.addEventListener('click', () => a.exportGlb());
  ui.exportRawButton.addEventListener('click', () => a.exportRaw());
  ui.headRerollButton.addEventListener('click', () => a.redrawHead({ nextSeed: true }));
  ui.headScale.addEventListener('input', () => ui.headScale.setAttribute('aria-valuetext', headScaleText(Number(ui.headScale.value))));
  ui.headScale.addEventListener('change', () => a.redrawHead({ scale: Number(ui.headScale.value) }));
  ui.fileInput.addEventListener('change', () => {
    const file = ui.fileInput.files?.[0];
    if (file) a.openFile(file);
    ui.fileInput.value = '';
  });
  ui.recordButton.addEventListener('click', () => a.toggleRecording());
  // The browser may take a view's WebGL context (a GPU reset, too many 3D views open) and give it back later
  // (three.js then draws again): the page says so, instead of showing a blank face under its last message.
  for (const canvas of [ui.canvas, ui.gtCanvas]) {
    canvas.addEventListener('webglcontextlost', () => tell('The face can no longer be drawn: the browser took its WebGL context (a GPU reset, or too many 3D views open). It is drawn again when the browser gives it back; reloading the page brings it back too.', true));
    canvas.addEventListener('webglcontextrestored', () => tell('The face is drawn again.'));
  }
  // Opening or dropping a file is a gesture: the audio output is unlocked then, so the take can play once animated.
  ui.fileInput.addEventListener('click', () => a.unlockAudio());
  ui.cancelButton.addEventListener('click', () => a.cancel());
  ui.playButton.addEventListener('click', () => a.togglePlay());
  ui.scrub.addEventListener('input', () => a.seek(Number(ui.scrub.value)));
  ui.backendSelect.addEventListener('change', () => a.setBackend(ui.backendSelect.value));
  // Files dropped anywhere on the page (the browser would otherwise open a file dropped beside the face in place of
  // the page); the face shows where it goes while files are dragged over the page.
  let over = 0; // dragenter less dragleave: entering a child leaves its parent
  const dragging = (on: boolean) => {
    ui.stage.classList.toggle('dragging', on);
    ui.dropHint.hidden = !on;
  };
  const files = (e: DragEvent) => e.dataTransfer?.types.includes('Files') ?? false;
  document.addEventListener('dragenter', (e) => files(e) && dragging(++over > 0));
  document.addEventListener('dragleave', (e) => files(e) && dragging(--over > 0));
  document.addEventListener('dragover', (e) => files(e) && e.preventDefault());
  document.addEventListener('drop', (e) => {
    if (!files(e)) return;
    e.preventDefault();
    over = 0;
    dragging(false);
    const all = [...(e.dataTransfer?.files ?? [])];
    const file = all.find((f) => /^(audio|video)\//.test(f.type)) ?? all[0]; // of several, the first audio (or video) file
    a.unlockAudio();
    if (file) a.openFile(file);
  });
}
