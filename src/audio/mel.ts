/**
 * Log-Mel features with meyda's melBands, framed exactly as training/src/talkingface/features.py:
 * frame k is centred on sample k * hop (zero-padded at both ends), K = floor(S / hop) + 1 frames.
 * meyda computes ln(1 + Mel energy of the power spectrum) under a symmetric Hann window.
 */
import Meyda from 'meyda';
import type { AudioConstants } from '../model/manifest';

interface MeydaState {
  bufferSize: number;
  sampleRate: number;
  melBands: number;
  windowingFunction: string;
  melFilterBank: unknown;
}

/** Each Mel band's width in FFT bins (its filter's weights summed; 0 for an empty filter), e.g. to compare bands' energy per bin. */
export function melBandWidths(a: AudioConstants): Float64Array {
  return MelBank.for(a).bandWidths;
}

/** Number of feature frames for `samples` samples. */
export function melFrameCount(samples: number, a: AudioConstants): number {
  return Math.floor(samples / a.hop) + 1;
}

function configureMeyda(a: AudioConstants): void {
  const m = Meyda as unknown as MeydaState;
  if (m.bufferSize !== a.frame_size || m.sampleRate !== a.sample_rate || m.melBands !== a.n_mels) {
    m.bufferSize = a.frame_size;
    m.sampleRate = a.sample_rate;
    m.melBands = a.n_mels;
    m.windowingFunction = 'hanning';
    // meyda does not rebuild its filter bank when sampleRate changes (platform.md): force it.
    m.melFilterBank = undefined;
  }
}

/** The frame [first + k] of the signal, zero-padded as the Python side does, into `frame`. */
function fillFrame(samples: Float32Array, a: AudioConstants, index: number, offset: number, signalLength: number, frame: Float32Array): void {
  const n = a.frame_size;
  const start = index * a.hop - n / 2;
  const end = offset + samples.length;
  for (let i = 0; i < n; i++) {
    const s = start + i;
    frame[i] = s >= offset && s < end && s < signalLength ? samples[s - offset] : 0;
  }
}

/**
 * Frames [first, first + count) of the log-Mel of `samples` (mono, at a.sample_rate), into `out`
 * (count x n_mels, row-major). `offset` is the index in the whole signal of samples[0], so a
 * streaming caller can pass only the audio around the frames it needs.
 *
 * Computed by MelBank below: meyda's window, filter bank and arithmetic (the same float32 roundings)
 * with a precomputed FFT and only the filters' non-zero bins, about 30x faster than calling
 * Meyda.extract per frame. `logMelFramesMeyda` is that call, and the tests hold the two equal.
 */
export function logMelFrames(samples: Float32Array, a: AudioConstants, first: number, count: number, out?: Float32Array, offset = 0, total?: number): Float32Array {
  const bank = MelBank.for(a);
  const result = out ?? new Float32Array(count * a.n_mels);
  const signalLength = total ?? offset + samples.length;
  for (let k = 0; k < count; k++) {
    fillFrame(samples, a, first + k, offset, signalLength, bank.frame);
    bank.compute(result, k * a.n_mels);
  }
  return result;
}

/** The same frames through Meyda.extract('melBands') itself: the reference logMelFrames is tested against. */
export function logMelFramesMeyda(samples: Float32Array, a: AudioConstants, first: number, count: number, out?: Float32Array, offset = 0, total?: number): Float32Array {
  configureMeyda(a);
  const result = out ?? new Float32Array(count * a.n_mels);
  const frame = new Float32Array(a.frame_size);
  const signalLength = total ?? offset + samples.length;
  for (let k = 0; k < count; k++) {
    fillFrame(samples, a, first + k, offset, signalLength, frame);
    const bands = Meyda.extract('melBands', frame) as unknown as number[];
    for (let b = 0; b < a.n_mels; b++) result[k * a.n_mels + b] = bands[b];
  }
  return result;
}

/**
 * meyda's melBands for one configuration, computed fast:
 *   windowed = frame * hann (float32 window, products in double, as meyda's pointwiseBufferMult)
 *   amp[j] = f32 |FFT(windowed)[j]|, pow[j] = f32 amp[j]^2   (j < n/2)
 *   band[i] = f32-accumulated sum_j f32(filter[i][j] pow[j]);  out = f32 ln(band + 1)
 * Zero filter weights add exactly nothing to a float32 sum, so only each filter's support is visited.
 */
export class MelBank {
  private static cache = new Map<string, MelBank>();
  readonly frame: Float32Array;
  private readonly window: Float32Array;
  private readonly re: Float64Array;
  private readonly im: Float64Array;
  private readonly cos: Float64Array;
  private readonly sin: Float64Array;
  private readonly bitrev: Uint32Array;
  private readonly power: Float32Array;
  private readonly acc = new Float32Array(1);
  private readonly filterStart: Int32Array;
  private readonly filterWeights: Float64Array[];
  /** Each band's width: the sum of its filter's weights over the FFT bins (0 for an empty filter). */
  readonly bandWidths: Float64Array;

  static for(a: AudioConstants): MelBank {
    const key = `${a.frame_size}/${a.sample_rate}/${a.n_mels}`;
    let bank = MelBank.cache.get(key);
    if (!bank) MelBank.cache.set(key, (bank = new MelBank(a)));
    return bank;
  }

  private constructor(private readonly a: AudioConstants) {
    const n = a.frame_size;
    if ((n & (n - 1)) !== 0) throw new Error(`frame_size ${n} must be a power of two (meyda's requirement)`);
    this.frame = new Float32Array(n);
    this.window = new Float32Array(n);
    for (let i = 0; i < n; i++) this.window[i] = 0.5 - 0.5 * Math.cos((2 * Math.PI * i) / (n - 1)); // meyda's hanning()
    this.re = new Float64Array(n);
    this.im = new Float64Array(n);
    this.cos = new Float64Array(n / 2);
    this.sin = new Float64Array(n / 2);
    for (let k = 0; k < n / 2; k++) {
      this.cos[k] = Math.cos((2 * Math.PI * k) / n);
      this.sin[k] = -Math.sin((2 * Math.PI * k) / n);
    }
    const bits = Math.log2(n);
    this.bitrev = new Uint32Array(n);
    for (let i = 0; i < n; i++) {
      let r = 0;
      for (let b = 0; b < bits; b++) r |= ((i >> b) & 1) << (bits - 1 - b);
      this.bitrev[i] = r;
    }
    this.power = new Float32Array(n / 2);
    // meyda's own filter bank (built on first use of melBands), reduced to each filter's non-zero bins.
    configureMeyda(a);
    Meyda.extract('melBands', new Float32Array(n));
    const bank = (Meyda as unknown as MeydaState).melFilterBank as ArrayLike<number>[];
    this.filterStart = new Int32Array(a.n_mels);
    this.filterWeights = [];
    this.bandWidths = new Float64Array(a.n_mels);
    for (let i = 0; i < a.n_mels; i++) {
      const row = bank[i];
      let lo = 0, hi = n / 2;
      while (lo < hi && row[lo] === 0) lo++;
      while (hi > lo && row[hi - 1] === 0) hi--;
      this.filterStart[i] = lo;
      this.filterWeights.push(Float64Array.from({ length: hi - lo }, (_, j) => row[lo + j]));
      this.bandWidths[i] = this.filterWeights[i].reduce((sum, v) => sum + v, 0);
    }
  }

  /** log-Mel of this.frame into out[at .. at + n_mels). */
  compute(out: Float32Array, at: number): void {
    const n = this.a.frame_size;
    const { re, im, frame, window, bitrev, cos, sin, power, acc } = this;
    for (let i = 0; i < n; i++) {
      re[bitrev[i]] = frame[i] * window[i];
      im[bitrev[i]] = 0;
    }
    for (let size = 2; size <= n; size *= 2) {
      const half = size / 2, step = n / size;
      for (let s = 0; s < n; s += size) {
        for (let k = 0; k < half; k++) {
          const c = cos[k * step], w = sin[k * step];
          const p = s + k, q = p + half;
          const tr = re[q] * c - im[q] * w;
          const ti = re[q] * w + im[q] * c;
          re[q] = re[p] - tr;
          im[q] = im[p] - ti;
          re[p] += tr;
          im[p] += ti;
        }
      }
    }
    for (let j = 0; j < n / 2; j++) {
      acc[0] = Math.sqrt(re[j] * re[j] + im[j] * im[j]); // float32 amplitude, as meyda stores it
      power[j] = acc[0] * acc[0];
    }
    for (let i = 0; i < this.filterWeights.length; i++) {
      const w = this.filterWeights[i], j0 = this.filterStart[i];
      acc[0] = 0;
      for (let j = 0; j < w.length; j++) acc[0] += Math.fround(w[j] * power[j0 + j]);
      out[at + i] = Math.log(acc[0] + 1);
    }
  }
}

/** The whole clip's log-Mel: (K x n_mels). */
export function logMel(samples: Float32Array, a: AudioConstants): Float32Array {
  return logMelFrames(samples, a, 0, melFrameCount(samples.length, a));
}
