/** Resampling a stream as it comes (the microphone at the device's rate, speech written at its own rate) or a whole clip to the model's. */
import { yieldToEventLoop } from '../engine/frames';

/**
 * Linear-phase low-pass + fractional resampling, streaming: pieces in at `from` Hz, pieces out at
 * `to` Hz, continuous across pieces. A windowed-sinc kernel (cut-off just under the lower Nyquist).
 * Output n sits at input time n * from / to; where that repeats its fraction every few outputs (24 or
 * 48 kHz to 16 kHz: 2 and 1; 44.1 kHz: 160), each fraction's weights are computed once.
 */
export class StreamResampler {
  private readonly step: number; // from / g: input samples per `phases` outputs
  private readonly phases: number; // to / g: outputs before the fraction repeats
  private readonly half: number;
  private readonly cutoff: number;
  private readonly table: Float32Array | null; // phases x 2 half weights, each row summing to 1
  private history: Float32Array;
  private made = 0; // outputs so far
  private received = 0; // input samples so far

  /** `maxPhases`: the most fractions whose weights are kept (beyond it, weights are computed per output). */
  constructor(readonly from: number, readonly to: number, taps = 16, maxPhases = 1024) {
    const g = gcd(from, to);
    [this.step, this.phases] = [from / g, to / g];
    this.cutoff = Math.min(1, to / from) * 0.95;
    this.half = Math.ceil(taps / this.cutoff);
    this.history = new Float32Array(0);
    this.table = this.phases <= maxPhases ? new Float32Array(this.phases * 2 * this.half) : null;
    for (let ph = 0; this.table && ph < this.phases; ph++) this.weights(ph / this.phases, this.table.subarray(ph * 2 * this.half, (ph + 1) * 2 * this.half));
  }

  /** How long an output sample waits for input past its own time (half the kernel), in seconds. */
  get delaySeconds(): number {
    return this.half / this.from;
  }

  /** The last outputs, after the last piece: the kernel holds back half its width, which zeros past the end bring out (and a few more). */
  flush(): Float32Array {
    return this.push(new Float32Array(Math.ceil(this.delaySeconds * this.from) + 2));
  }

  push(input: Float32Array): Float32Array {
    if (this.from === this.to) return input.slice();
    // history holds input samples [received - history.length, received).
    const joined = new Float32Array(this.history.length + input.length);
    joined.set(this.history);
    joined.set(input, this.history.length);
    const base = this.received - this.history.length; // input index of joined[0]
    this.received += input.length;
    const out = new Float32Array(Math.ceil(((joined.length + 1) * this.phases) / this.step) + 1); // (at most this many come out)
    let n = 0;
    const w = this.table ? null : new Float32Array(2 * this.half);
    // Output n sits at input time centre + phase / phases; it needs inputs up to centre + half.
    for (;;) {
      const centre = Math.floor(this.made / this.phases) * this.step + Math.floor(((this.made % this.phases) * this.step) / this.phases);
      if (centre + this.half >= this.received) break;
      const phase = (this.made * this.step) % this.phases;
      const row = this.table ? this.table.subarray(phase * 2 * this.half, (phase + 1) * 2 * this.half) : this.weights(phase / this.phases, w!);
      const first = centre - this.half + 1 - base; // joined's index of the first tap
      let s = 0;
      if (first >= 0) { // every tap in joined (all but the stream's first outputs; the last tap always is)
        for (let j = 0; j < row.length; j++) s += row[j] * joined[first + j];
      } else {
        for (let j = 0, k = centre - this.half + 1; j < row.length; j++, k++) {
          const i = k - base;
          if (k >= 0 && i >= 0 && i < joined.length) s += row[j] * joined[i];
        }
      }
      out[n++] = s;
      this.made++;
    }
    const next = Math.floor(this.made / this.phases) * this.step + Math.floor(((this.made % this.phases) * this.step) / this.phases);
    const keepFrom = Math.max(0, next - this.half - base);
    this.history = joined.slice(keepFrom);
    return out.slice(0, n);
  }

  /** The kernel's weights for an output `fraction` (0..1) past its centre sample, taps centre - half + 1 .. centre + half, summing to 1. */
  private weights(fraction: number, into: Float32Array): Float32Array {
    let sum = 0;
    for (let j = 0; j < into.length; j++) {
      const x = j - this.half + 1 - fraction;
      sum += into[j] = sinc(x * this.cutoff) * hann(x / (this.half + 1));
    }
    for (let j = 0; j < into.length; j++) into[j] /= sum;
    return into;
  }
}

/** How long resampleAll works before it lets the page handle input and drawing (and checks its signal), ms. */
const SLICE_MS = 25;

/**
 * A whole clip from `from` Hz to `to` Hz through StreamResampler's low-pass (what lies above the lower Nyquist frequency
 * is removed, not folded into the band below it): round(length * to / from) samples, aligned with the input. An hour
 * takes seconds: it works a second of audio at a time, letting the page run between slices; `signal` stops it.
 */
export async function resampleAll(input: Float32Array, from: number, to: number, signal?: AbortSignal): Promise<Float32Array<ArrayBuffer>> {
  const resampler = new StreamResampler(from, to);
  const out = new Float32Array(Math.round((input.length * to) / from));
  let made = 0;
  const keep = (piece: Float32Array) => {
    const n = Math.min(piece.length, out.length - made);
    out.set(piece.subarray(0, n), made);
    made += n;
  };
  let slice = performance.now();
  for (let at = 0; at < input.length; at += from) {
    keep(resampler.push(input.subarray(at, at + from)));
    if (performance.now() - slice < SLICE_MS) continue;
    await yieldToEventLoop();
    signal?.throwIfAborted();
    slice = performance.now();
  }
  keep(resampler.flush());
  return out;
}

function gcd(a: number, b: number): number {
  return b === 0 ? a : gcd(b, a % b);
}

function sinc(x: number): number {
  if (Math.abs(x) < 1e-9) return 1;
  const y = Math.PI * x;
  return Math.sin(y) / y;
}

function hann(u: number): number {
  return Math.abs(u) >= 1 ? 0 : 0.5 + 0.5 * Math.cos(Math.PI * u);
}
