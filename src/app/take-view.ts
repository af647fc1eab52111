/**
 * What the demo shows about the current take besides the face: the ground truth beside it, the lip timeline,
 * the scrubber and time, the painted maps, and E_vl against a sample's truth.
 */
import { FaceView } from '../render/face-view';
import { lipMask as lipMaskOf, type FaceTemplate } from '../template/face-template';
import { innerLipGaps } from '../template/lip-gap';
import type { TalkingFaceEngine, Animation, Backend } from '../engine/engine';
import { LipTimeline, headDegrees } from './timeline';
import { Painter, type PaintMode } from './paint';
import { clipLipError, onTruthFace, type Truth } from './samples';
import { announce, headScaleText, showLegend, showStatus, tell, ui, type HeadChange } from './controls';
import { isolated } from './names';
import { audioNotes } from '../player/audio-notes';
import { raiseIfQuiet } from '../audio/decode';

export interface Take {
  animation: Animation;
  buffer: AudioBuffer;
  /** The audio at the model's rate (for attention maps). */
  samples: Float32Array;
  name: string;
  seconds: number;
  computeMs: number;
  /** A recording's frames that hold the one before them (skipped live, their animation cancelled): no speed figure. */
  heldFrames?: number;
  backend: Backend;
  truth?: Truth;
  /** E_vl of the whole take against its ground truth (mm), computed once. */
  lipError?: number;
  /** What was noticed about its audio (silent, no speech found, clipped, short), the most important first. */
  notes?: string[];
}

export class TakeView {
  truthView: FaceView | null = null;
  private readonly timeline = new LipTimeline(ui.timeline);
  private readonly painter: Painter;
  private readonly lipMask: Uint8Array;
  private picked: number | null = null;
  private lipRing: number[] | null = null;

  constructor(private readonly view: FaceView) {
    this.painter = new Painter(view, showLegend, (mode) => (document.body.dataset.painted = mode), announce);
    this.lipMask = lipMaskOf(view.template);
    addEventListener('resize', () => this.timeline.redraw());
    this.setArrows(ui.arrowsCheck.checked); // as ticked while the face loaded, or as the browser restored the page
    this.setSideBySide(ui.sideCheck.checked, null, false);
  }

  /** Frame f of a take as drawn: on the sample subject's own face when there is ground truth. */
  drawn(take: Take): (f: number, unposed: Float32Array) => Float32Array {
    return take.truth ? onTruthFace(take.truth, this.view.template.positions) : (_f, u) => u;
  }

  /** E_vl of a sample take (mm), computed once; NaN without ground truth. */
  lipError(take: Take, engine: TalkingFaceEngine): number {
    if (!take.truth) return NaN;
    const shape = this.drawn(take);
    const n3 = this.view.template.vertexCount * 3;
    const frame = (f: number) => shape(f, take.animation.unposed!.subarray(f * n3, (f + 1) * n3));
    return (take.lipError ??= clipLipError(frame, take.animation.frames, take.truth, this.lipMask, 1 / engine.unitsPerMm));
  }

  /** The lip timeline of a take: predicted gap and heard phones, and the truth's for a sample clip. */
  showTimeline(take: Take, engine: TalkingFaceEngine): void {
    const a = take.animation;
    if (!a.unposed) return this.timeline.clear();
    const { lips_inner_upper: upper, lips_inner_lower: lower } = this.view.template.regions;
    const gap = innerLipGaps(a.unposed, a.frames, this.view.template.vertexCount, upper, lower).map((g) => g / engine.unitsPerMm);
    const truth = take.truth;
    this.timeline.show({
      fps: a.fps, gap, heard: Array.from(a.phones, (k) => engine.manifest.content_phones[k]), truthGap: truth?.lipGapMm, truthPhones: truth?.phones,
      head: headDegrees(a.pose, a.frames), truthHead: truth ? headDegrees(truth.pose, truth.frames) : undefined,
    });
  }

  /** After the player shows frame f: the truth beside it, the timeline, scrubber and time, the paint. */
  frameShown(take: Take, engine: TalkingFaceEngine, f: number, playing: boolean): void {
    const n = this.view.template.vertexCount;
    const truth = take.truth;
    if (truth && this.truthView) {
      const g = Math.min(f, truth.frames - 1);
      this.truthView.setVertices(truth.unposed.subarray(g * n * 3, (g + 1) * n * 3));
      const q = truth.pose;
      this.truthView.setPose(q[g * 6], q[g * 6 + 1], q[g * 6 + 2], q[g * 6 + 3], q[g * 6 + 4], q[g * 6 + 5]);
    }
    this.timeline.setPlayhead(f);
    ui.scrub.value = String(f);
    const fps = take.animation.fps;
    ui.timeLabel.textContent = `${(f / fps).toFixed(2)} s`; // not a live region: it changes every frame
    ui.scrub.setAttribute('aria-valuetext', `${(f / fps).toFixed(2)} s of ${(take.animation.frames / fps).toFixed(2)} s`);
    this.paint(take, engine, f, playing);
  }

  paint(take: Take | null, engine: TalkingFaceEngine | null, f: number, playing: boolean): void {
    if (!take || !engine) return this.painter.paint(null);
    const n3 = this.view.template.vertexCount * 3;
    const u = take.animation.unposed!.subarray(f * n3, (f + 1) * n3);
    this.painter.paint({
      mode: ui.paintSelect.value as PaintMode, engine, samples: take.samples, frame: f, truth: take.truth, lipMask: this.lipMask, playing,
      predicted: this.drawn(take)(f, u), clipError: () => this.lipError(take, engine), vertex: this.picked,
    });
  }

  /**
   * Choose the vertex whose attention is painted: the one under a click at client coordinates, or by keyboard the
   * next (1) or previous (-1) vertex round the lips' outline, anticlockwise seen from the front; true when one was chosen.
   */
  pick(at: { x: number; y: number } | number): boolean {
    let v: number | null;
    if (typeof at === 'number') {
      const ring = (this.lipRing ??= lipOutline(this.view.template));
      const upper = this.view.template.regions.lips_outer_upper;
      const i = ring.indexOf(this.picked ?? upper[Math.floor(upper.length / 2)]); // the default shown (paint.ts)
      // From a vertex off the outline (a click elsewhere), ] goes to the outline's first vertex and [ to its last.
      v = ring[i < 0 ? (at > 0 ? 0 : ring.length - 1) : (i + at + ring.length) % ring.length] ?? null;
    } else v = this.view.pickVertex(at.x, at.y);
    if (v !== null) this.picked = v;
    return v !== null;
  }

  setArrows(on: boolean): void {
    this.view.showPoseArrows(on);
    this.truthView?.showPoseArrows(on);
  }

  /** Show or hide the ground truth beside the prediction; says so when the take has none. */
  /**
   * The truth beside the prediction, when asked for (`on`) and the take has one: a take without ground truth (a file,
   * a recording) hides the pane rather than show another clip's truth, and `say` tells the visitor why.
   */
  setSideBySide(on: boolean, take: Take | null, say = true): void {
    const shown = on && Boolean(take?.truth);
    ui.gtView.hidden = !shown;
    if (shown && !this.truthView) {
      this.truthView = new FaceView(ui.gtCanvas, this.view.template, { life: false }); // the truth exactly as recorded
      this.truthView.showPoseArrows(ui.arrowsCheck.checked);
    }
    if (on && !shown && say) tell('Side by side needs a sample clip (it has ground truth): choose one under Sample.');
  }
}

/** The head-motion slider at `scale`, and the page's record of the seed (the e2e tests read it). */
function showHead(seed: number | null, scale: number): void {
  document.body.dataset.headSeed = String(seed);
  ui.headScale.value = String(scale);
  ui.headScale.setAttribute('aria-valuetext', headScaleText(scale));
}

/**
 * The take with the head's own motion drawn again (the lips and eyes do not change): with the next seed, and / or
 * at a new scale (the slider).
 */
export async function redrawHead(e: TalkingFaceEngine, t: Take, signal: AbortSignal, change: HeadChange): Promise<Take> {
  const shown = { seed: e.headMotionSeed, scale: e.headMotionScale };
  // Stopped or replaced before it is drawn, the seed and scale go back to the take's that stays shown, the slider
  // with them, at once (before whatever replaced it draws): the next New head motion then shows the seed after it
  // instead of skipping one never seen, and the slider says what is shown.
  const undo = () => {
    [e.headMotionSeed, e.headMotionScale] = [shown.seed, shown.scale];
    showHead(shown.seed, shown.scale);
  };
  if (change.nextSeed) e.headMotionSeed = (shown.seed ?? 0) + 1;
  if (change.scale !== undefined) e.headMotionScale = change.scale;
  signal.addEventListener('abort', undo, { once: true });
  showHead(e.headMotionSeed, e.headMotionScale);
  showStatus(`Drawing the head's motion again${change.scale !== undefined ? ` at ${headScaleText(e.headMotionScale)}` : ''}…`);
  try {
    const t0 = performance.now();
    const { animation } = await e.animateSpeech(t.samples, { // (a take with no speech stays at rest)
      unposed: true,
      signal,
      onProgress: (done, total) => showStatus(`Drawing the head's motion again: frame ${done} of ${total}…`),
    });
    return { ...t, animation, computeMs: performance.now() - t0, lipError: undefined, heldFrames: undefined }; // (all its frames made anew)
  } finally {
    signal.removeEventListener('abort', undo);
  }
}

/**
 * Animate decoded audio with progress in the status line (a quiet clip raised first: `samples` returns what was
 * animated, the take's); where no speech is found the face stays at rest. `statedSeconds`: a file cut short's
 * length as its header states it (DecodedAudio), for the notes.
 */
export async function animateAudio(e: TalkingFaceEngine, name: string, given: Float32Array, seconds: number, signal: AbortSignal,
  statedSeconds: number | null = null) {
  const { samples, gainDb } = raiseIfQuiet(given);
  const early = audioNotes(given, seconds, { raisedDb: gainDb, animating: true, statedSeconds });
  e.resetTimes();
  const t0 = performance.now();
  const { animation, speech } = await e.animateSpeech(samples, {
    unposed: true,
    signal,
    onProgress: (done, total) => showStatus(`Animating ${isolated(name)}: frame ${done} of ${total}…` + (early.length ? ` Note: ${early.join('; ')}.` : '')),
  });
  const computeMs = performance.now() - t0;
  return { animation, computeMs, samples, notes: audioNotes(given, seconds, { speech, raisedDb: gainDb, statedSeconds }) };
}

/** The lips' outer outline, ordered by angle round its centre (seen from the front): where [ and ] go. */
function lipOutline(t: FaceTemplate): number[] {
  const ring = t.regions.lips_outer;
  const p = t.positions;
  let cx = 0, cy = 0;
  for (const v of ring) [cx, cy] = [cx + p[v * 3] / ring.length, cy + p[v * 3 + 1] / ring.length];
  const angle = (v: number) => Math.atan2(p[v * 3 + 1] - cy, p[v * 3] - cx);
  return [...ring].sort((a, b) => angle(a) - angle(b));
}
