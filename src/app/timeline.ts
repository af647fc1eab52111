/**
 * The strip under the face: the predicted inner-lip gap over the clip, the phones the content encoder heard
 * (issue 14), and below them the head's rotation about its three axes (issue 15); for sample clips the truth's
 * gap, aligned phones and head rotation beside them. A playhead follows playback.
 * The curves are drawn once per clip into an offscreen canvas; moving the playhead only copies it back.
 */
export interface TimelineData {
  fps: number;
  /** Predicted inner-lip gap per frame, mm. */
  gap: Float32Array;
  /** The phone the encoder heard most at each frame (names, e.g. "M", "SIL", "<blank>"). */
  heard: string[];
  /** The truth for sample clips: its gap per frame (mm) and its aligned phones [phone, start s, end s]. */
  truthGap?: ArrayLike<number>;
  truthPhones?: [string, number, number][];
  /** The head's rotation per frame, degrees (frames x 3: pitch, yaw, roll), and the truth's for sample clips. */
  head?: Float32Array;
  truthHead?: Float32Array;
}

/** Head rotation per frame in degrees (frames x 3) from poses (frames x 6: rotation vector in radians, translation). */
export function headDegrees(pose: Float32Array, frames: number): Float32Array {
  const out = new Float32Array(frames * 3);
  for (let f = 0; f < frames; f++) for (let k = 0; k < 3; k++) out[3 * f + k] = (pose[6 * f + k] * 180) / Math.PI;
  return out;
}

const BILABIALS = new Set(['P', 'B', 'M']);
const CLOSED_MM = 1; // as the articulation measures (training/src/talkingface/train/articulation.py)
const COLOURS = { back: '#161a23', grid: '#2a3142', pred: '#8fb3ff', truth: '#9aa3b5', bilabial: '#ff8f7a', text: '#c8cedc' };
/** Pitch, yaw, roll. */
const AXIS_COLOURS = ['#ffb86b', '#7ee0a1', '#d59bff'];

export class LipTimeline {
  private readonly offscreen = document.createElement('canvas');
  private data: TimelineData | null = null;
  private frames = 0;
  private playhead = 0; // the frame the playhead is at (a redraw after a resize keeps it)

  constructor(private readonly canvas: HTMLCanvasElement) {
    this.clear();
  }

  show(data: TimelineData): void {
    this.data = data;
    this.playhead = 0;
    this.frames = data.gap.length;
    this.redraw();
  }

  /** No clip: an empty strip (it keeps its place, so the face above never resizes). */
  clear(): void {
    this.data = null;
    const { width, height } = this.size();
    this.canvas.width = width;
    this.canvas.height = height;
    const ctx = this.canvas.getContext('2d')!;
    ctx.fillStyle = COLOURS.back;
    ctx.fillRect(0, 0, width, height);
  }

  /** Draw everything again (after a resize: the backing store follows the element's size). */
  redraw(): void {
    if (!this.data) return this.clear();
    const { width, height } = this.size();
    this.offscreen.width = width;
    this.offscreen.height = height;
    this.drawCurves(this.offscreen.getContext('2d')!, width, height, this.data);
    this.setPlayhead(this.playhead);
  }

  setPlayhead(frame: number): void {
    this.playhead = frame;
    if (!this.data) return;
    const ctx = this.canvas.getContext('2d')!;
    const { width, height } = this.size();
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    ctx.drawImage(this.offscreen, 0, 0);
    const x = this.x(frame, width);
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(Math.round(x), 0, Math.max(1, Math.round(devicePixelRatio)), height);
  }

  private size(): { width: number; height: number } {
    const r = this.canvas.getBoundingClientRect();
    return { width: Math.max(1, Math.round(r.width * devicePixelRatio)), height: Math.max(1, Math.round(r.height * devicePixelRatio)) };
  }

  private x(frame: number, width: number): number {
    return (frame / Math.max(1, this.frames - 1)) * (width - 1);
  }

  private drawCurves(ctx: CanvasRenderingContext2D, w: number, h: number, d: TimelineData): void {
    const dpr = devicePixelRatio;
    const labelRow = 14 * dpr;
    const top = d.truthPhones ? labelRow : 2 * dpr;
    const headBand = d.head ? Math.round(0.38 * h) : 0;
    const bottom = h - labelRow - headBand;
    const maxGap = gapScale(d.gap, d.truthGap);
    const y = (mm: number) => bottom - (Math.max(0, mm) / maxGap) * (bottom - top);
    ctx.fillStyle = COLOURS.back;
    ctx.fillRect(0, 0, w, h);
    ctx.fillStyle = COLOURS.grid;
    ctx.fillRect(0, Math.round(y(CLOSED_MM)), w, dpr); // the closure threshold
    ctx.font = `${10 * dpr}px system-ui, sans-serif`;
    ctx.textBaseline = 'middle';
    const curve = (values: ArrayLike<number>, colour: string, width: number) => {
      ctx.strokeStyle = colour;
      ctx.lineWidth = width * dpr;
      ctx.beginPath();
      for (let f = 0; f < values.length; f++) {
        if (f === 0) ctx.moveTo(this.x(f, w), y(values[f]));
        else ctx.lineTo(this.x(f, w), y(values[f]));
      }
      ctx.stroke();
    };
    if (d.truthGap) curve(d.truthGap, COLOURS.truth, 1);
    curve(d.gap, COLOURS.pred, 1.5);
    // Heard phones: one label per run of two frames or more, /p b m/ in red, just under the lip curves.
    const heard: [string, number][] = [];
    for (let f = 0; f < d.heard.length;) {
      let g = f;
      while (g < d.heard.length && d.heard[g] === d.heard[f]) g++;
      const p = d.heard[f];
      if (g - f >= 2 && p !== 'SIL' && p !== '<blank>') heard.push([p, (this.x(f, w) + this.x(g - 1, w)) / 2]);
      f = g;
    }
    this.labels(ctx, heard, bottom + labelRow / 2);
    this.labels(ctx, (d.truthPhones ?? []).filter(([p]) => p !== 'SIL')
      .map(([p, a, b]): [string, number] => [p, this.x(((a + b) / 2) * d.fps, w)]), labelRow / 2);
    if (d.head) this.drawHead(ctx, w, h - headBand, h, d);
  }

  /** The head's three angles in the band [top, bottom): predicted solid, truth thin; the scale is symmetric about 0. */
  private drawHead(ctx: CanvasRenderingContext2D, w: number, top: number, bottom: number, d: TimelineData): void {
    const dpr = devicePixelRatio;
    let max = 2;
    for (const v of [d.head!, d.truthHead ?? new Float32Array(0)]) for (const x of v) max = Math.max(max, Math.abs(x));
    const mid = (top + bottom) / 2;
    const y = (deg: number) => mid - (deg / max) * ((bottom - top) / 2 - dpr);
    ctx.fillStyle = COLOURS.grid;
    ctx.fillRect(0, top, w, dpr);
    ctx.fillRect(0, Math.round(mid), w, dpr);
    const curve = (values: Float32Array, k: number, width: number, alpha: number) => {
      ctx.strokeStyle = AXIS_COLOURS[k];
      ctx.globalAlpha = alpha;
      ctx.lineWidth = width * dpr;
      ctx.beginPath();
      for (let f = 0; f < values.length / 3; f++) {
        if (f === 0) ctx.moveTo(this.x(f, w), y(values[3 * f + k]));
        else ctx.lineTo(this.x(f, w), y(values[3 * f + k]));
      }
      ctx.stroke();
      ctx.globalAlpha = 1;
    };
    for (let k = 0; k < 3; k++) {
      if (d.truthHead) curve(d.truthHead, k, 1, 0.45);
      curve(d.head!, k, 1.5, 1);
    }
    ctx.fillStyle = COLOURS.text;
    ctx.textAlign = 'left';
    ctx.fillText(`head ±${max.toFixed(1)}°: pitch, yaw, roll`, 4 * dpr, top + 7 * dpr);
  }

  /** One row of phone labels centred on their x, those that would overlap another left out (labelsThatFit). */
  private labels(ctx: CanvasRenderingContext2D, phones: [string, number][], y: number): void {
    ctx.textAlign = 'center';
    const sized = phones.map(([p, x]) => ({ x, width: ctx.measureText(p.toLowerCase()).width, first: BILABIALS.has(p) }));
    for (const i of labelsThatFit(sized, 3 * devicePixelRatio)) {
      const [phone, x] = phones[i];
      ctx.fillStyle = BILABIALS.has(phone) ? COLOURS.bilabial : COLOURS.text;
      ctx.fillText(phone.toLowerCase(), x, y);
    }
  }
}

/** The top of the gap curves' scale, mm: the widest gap of either, at least 8 (a loop: spread as arguments, an hour's frames overflow the stack). */
export function gapScale(gap: ArrayLike<number>, truthGap?: ArrayLike<number>): number {
  let most = 8;
  for (const gaps of truthGap ? [gap, truthGap] : [gap]) for (let i = 0; i < gaps.length; i++) most = Math.max(most, gaps[i]);
  return most;
}

/**
 * Which labels of a row to draw so that none overlaps another (a narrow timeline, a phone's, has less room than a
 * clip has phones): those marked `first` (/p b m/, what the row is there to show) before the others, each left to
 * right, and a label that would come within `gap` of one already kept left out. Labels are centred on their x.
 * -> the indices kept, in order.
 */
export function labelsThatFit(labels: readonly { x: number; width: number; first: boolean }[], gap: number): number[] {
  const order = labels.map((_, i) => i)
    .sort((a, b) => Number(labels[b].first) - Number(labels[a].first) || labels[a].x - labels[b].x);
  const taken: [number, number][] = [];
  const kept: number[] = [];
  for (const i of order) {
    const left = labels[i].x - labels[i].width / 2, right = labels[i].x + labels[i].width / 2;
    if (taken.some(([l, r]) => left < r + gap && l < right + gap)) continue;
    taken.push([left, right]);
    kept.push(i);
  }
  return kept.sort((a, b) => a - b);
}
