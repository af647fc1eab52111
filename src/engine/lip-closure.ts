/**
 * Lip closure on the face's own lips (training/src/talkingface/model/lip_closure.py, step by step): at every x
 * across the mouth the model's closing motion is read as a fraction c of the gap it closes by (the manifest's
 * reference gap, spread over the mouth as the face's own gap profile is), and the lips are brought together by c of
 * the face's own gap instead, with the rig's lip fields. A face whose lips part by more than the model closes gets
 * its lips together on /p b m/; one whose lips part by less is not pressed through itself; a face that opens does
 * not change:
 *
 *   gap' = g - c g        c = clamp(-(du - dl) / g_ref, 0, 1)        g_ref(x) = g(x) * reference / lipGap(face)
 *
 * Where the face's lips already touch (g <= MIN_GAP_MM: a face modelled with its mouth shut, or beyond the corners)
 * every closing is a full one: the model's closing is taken out there and the lips stay touching (it pressed them
 * through each other by its whole closing, 6.4 mm in silence); an opening is the model's.
 *
 * Before that, the mouth's amplitude: the model's offsets on the lips' tissue and the jaw are scaled by the
 * manifest's mouth gain, fading to 1 with the rig's fields (a regression opens the mouth by about three quarters of
 * the truth's motion).
 *
 * Library code: no DOM. The fields are the avatar basis's (avatar/fields.ts), solved once per template.
 */
import { faceFields } from '../avatar/fields';
import { innerLipGaps } from '../template/lip-gap';
import type { FaceTemplate } from '../template/face-template';

/** Below this the face's lips already touch at that x (mm): the model's closing is taken out there (MIN_GAP_MM). */
const MIN_GAP_MM = 0.05;

/** Where x falls on an ascending contour: its two neighbours and the weight of the second (np.interp's rule). */
function bracket(x: number, xs: number[]): [number, number] {
  let k = 0;
  while (k < xs.length - 2 && xs[k + 1] <= x) k++;
  const t = (x - xs[k]) / Math.max(xs[k + 1] - xs[k], 1e-12);
  return [k, Math.min(1, Math.max(0, t))];
}

export class LipClosure {
  /** The vertices it moves (the lips' tissue: where they part, and where they touch), and per vertex: the two upper-
   * and lower-contour vertices around its x and weights. */
  private readonly moved: Int32Array;
  private readonly up: Int32Array;
  private readonly lo: Int32Array;
  private readonly tUp: Float64Array;
  private readonly tLo: Float64Array;
  private readonly gap: Float64Array;
  private readonly ref: Float64Array;
  private readonly field: Float64Array;
  /** The vertices the mouth gain scales, and their factors. */
  private readonly scaled: Int32Array;
  private readonly factor: Float64Array;
  /** The neutral face's inner-lip gap (mm), as training measures it. */
  readonly faceGap: number;

  constructor(template: FaceTemplate, readonly referenceGapMm: number, readonly mouthGain = 1) {
    const f = faceFields(template);
    const scaled: number[] = [], factor: number[] = [];
    for (let i = 0; i < f.n && mouthGain !== 1; i++) {
      const m = Math.min(1, Math.max(0, Math.max(f.wJaw[i], f.wLips[i])));
      if (m > 0) {
        scaled.push(i);
        factor.push(1 + (mouthGain - 1) * m);
      }
    }
    this.scaled = Int32Array.from(scaled);
    this.factor = Float64Array.from(factor);
    const v = f.rest;
    const X = (i: number) => v[3 * i], Y = (i: number) => v[3 * i + 1];
    const ux = f.upperLip.map(X), lx = f.lowerLip.map(X);
    const upper = Uint32Array.from(template.regions.lips_inner_upper);
    const lower = Uint32Array.from(template.regions.lips_inner_lower);
    this.faceGap = innerLipGaps(Float32Array.from(v), 1, f.n, upper, lower)[0];
    const scale = referenceGapMm / Math.max(this.faceGap, 1e-6);
    const rows: { i: number; ku: number; tu: number; kl: number; tl: number; g: number; w: number }[] = [];
    for (let i = 0; i < f.n; i++) {
      const w = 0.5 * (f.wLower[i] - f.wUpper[i]);
      const [ku, tu] = bracket(X(i), ux);
      const [kl, tl] = bracket(X(i), lx);
      const yu = (1 - tu) * Y(f.upperLip[ku]) + tu * Y(f.upperLip[ku + 1]);
      const yl = (1 - tl) * Y(f.lowerLip[kl]) + tl * Y(f.lowerLip[kl + 1]);
      const g = Math.max(yu - yl, 0);
      if (w !== 0) rows.push({ i, ku, tu, kl, tl, g, w });
    }
    this.moved = Int32Array.from(rows, (r) => r.i);
    this.up = Int32Array.from(rows.flatMap((r) => [f.upperLip[r.ku], f.upperLip[r.ku + 1]]));
    this.lo = Int32Array.from(rows.flatMap((r) => [f.lowerLip[r.kl], f.lowerLip[r.kl + 1]]));
    this.tUp = Float64Array.from(rows, (r) => r.tu);
    this.tLo = Float64Array.from(rows, (r) => r.tl);
    this.gap = Float64Array.from(rows, (r) => (r.g > MIN_GAP_MM ? r.g : 0)); // 0: the lips touch there
    this.ref = Float64Array.from(rows, (r) => r.g * scale);
    this.field = Float64Array.from(rows, (r) => r.w);
  }

  /** Vertices it can move (the lips' tissue). */
  get vertexCount(): number {
    return this.moved.length;
  }

  /** `offsets` (frames x N x 3, mm), the model's displacement: the mouth's amplitude scaled and the lips closed by
   * the face's own gap, in place. */
  apply(offsets: Float32Array, frames: number, n: number): void {
    const m = this.moved.length;
    const dy = new Float64Array(m);
    for (let fr = 0; fr < frames; fr++) {
      for (let k = 0; k < this.scaled.length; k++) {
        const o = fr * n * 3 + 3 * this.scaled[k];
        for (let j = 0; j < 3; j++) offsets[o + j] *= this.factor[k];
      }
      const base = fr * n * 3 + 1;
      const y = (v: number) => offsets[base + 3 * v];
      // Every vertex reads the model's offsets before any is moved (the contours are among the moved vertices).
      for (let k = 0; k < m; k++) {
        const du = (1 - this.tUp[k]) * y(this.up[2 * k]) + this.tUp[k] * y(this.up[2 * k + 1]);
        const dl = (1 - this.tLo[k]) * y(this.lo[2 * k]) + this.tLo[k] * y(this.lo[2 * k + 1]);
        if (this.gap[k] === 0) {
          dy[k] = Math.min(du - dl, 0) * this.field[k];
          continue;
        }
        const c = Math.min(1, Math.max(0, -(du - dl) / this.ref[k]));
        dy[k] = c * (this.gap[k] - this.ref[k]) * this.field[k];
      }
      for (let k = 0; k < m; k++) offsets[base + 3 * this.moved[k]] += dy[k];
    }
  }
}
