/**
 * The strip under the face (issue 14): the predicted inner-lip gap over the clip, the phones the content
 * encoder heard, and for sample clips the truth's gap and aligned phones; a playhead follows playback.
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
}

const BILABIALS = new Set(['P', 'B', 'M']);
const CLOSED_MM = 1; // as the articulation measures (training/src/talkingface/train/articulation.py)
const COLOURS = { back: '#161a23', grid: '#2a3142', pred: '#8fb3ff', truth: '#9aa3b5', bilabial: '#ff8f7a', text: '#c8cedc' };

export class LipTimeline {
  private readonly offscreen = document.createElement('canvas');
  private data: TimelineData | null = null;
  private frames = 0;

  constructor(private readonly canvas: HTMLCanvasElement) {
    this.clear();
  }

  show(data: TimelineData): void {
    this.data = data;
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
    this.setPlayhead(0);
  }

  setPlayhead(frame: number): void {
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
    const bottom = h - labelRow;
    const maxGap = Math.max(8, ...d.gap, ...(d.truthGap ? Array.from(d.truthGap) : []));
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
    // Heard phones: one label per run of two frames or more, /p b m/ in red.
    for (let f = 0; f < d.heard.length;) {
      let g = f;
      while (g < d.heard.length && d.heard[g] === d.heard[f]) g++;
      const p = d.heard[f];
      if (g - f >= 2 && p !== 'SIL' && p !== '<blank>') this.label(ctx, p, (this.x(f, w) + this.x(g - 1, w)) / 2, h - labelRow / 2);
      f = g;
    }
    for (const [p, a, b] of d.truthPhones ?? []) {
      if (p !== 'SIL') this.label(ctx, p, this.x(((a + b) / 2) * d.fps, w), labelRow / 2);
    }
  }

  private label(ctx: CanvasRenderingContext2D, phone: string, x: number, y: number): void {
    ctx.fillStyle = BILABIALS.has(phone) ? COLOURS.bilabial : COLOURS.text;
    ctx.textAlign = 'center';
    ctx.fillText(phone.toLowerCase(), x, y);
  }
}
