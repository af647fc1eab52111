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

/**
 * Frames [first, first + count) of the log-Mel of `samples` (mono, at a.sample_rate), into `out`
 * (count x n_mels, row-major). `offset` is the index in the whole signal of samples[0], so a
 * streaming caller can pass only the audio around the frames it needs.
 */
export function logMelFrames(samples: Float32Array, a: AudioConstants, first: number, count: number, out?: Float32Array, offset = 0, total?: number): Float32Array {
  configureMeyda(a);
  const n = a.frame_size;
  const half = n / 2;
  const result = out ?? new Float32Array(count * a.n_mels);
  const frame = new Float32Array(n);
  const end = offset + samples.length;
  const signalLength = total ?? end;
  for (let k = 0; k < count; k++) {
    const start = (first + k) * a.hop - half;
    for (let i = 0; i < n; i++) {
      const s = start + i;
      frame[i] = s >= offset && s < end && s < signalLength ? samples[s - offset] : 0;
    }
    const bands = Meyda.extract('melBands', frame) as unknown as number[];
    for (let b = 0; b < a.n_mels; b++) result[k * a.n_mels + b] = bands[b];
  }
  return result;
}

/** The whole clip's log-Mel: (K x n_mels). */
export function logMel(samples: Float32Array, a: AudioConstants): Float32Array {
  return logMelFrames(samples, a, 0, melFrameCount(samples.length, a));
}
