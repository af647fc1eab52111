/**
 * Audio in: any file the browser can decode (wav, mp3, ogg/opus, webm, m4a where supported), a Blob,
 * or an AudioBuffer -> mono Float32Array at the model's sample rate. The browser decodes (at 44.1 kHz, or the
 * AudioBuffer's rate); the channels are mixed (mixToMono) and brought to the model's rate (resampleAll) here. A file the browser cannot decode gets a reason from its
 * first bytes where they tell one (sniff.ts). Library code: Web Audio, no DOM.
 */
import { CONVERT, statedSecondsIfCut, undecodableReason } from './sniff';
import { resampleAll } from './resample';

export class AudioDecodeError extends Error {
  override name = 'AudioDecodeError';
}

export interface DecodedAudio {
  samples: Float32Array; // mono, at `sampleRate`
  sampleRate: number;
  /** The decoded original, for playback at full quality. */
  buffer: AudioBuffer;
  /** What the input was, for messages: channels and duration (decodeAudioData resamples to its context's
   * rate, so the file's own rate is not known here; decodedRate is that context rate); statedSeconds: where a
   * WAV's header states more than the file holds (cut short), how long it says, else null. */
  source: { decodedRate: number; channels: number; seconds: number; statedSeconds: number | null };
}

/**
 * `input` decoded to mono at `sampleRate`. `signal`: an abort rejects at once (an AbortError), although the browser
 * goes on decoding in the background (decodeAudioData cannot be stopped; its result is dropped): a long file's
 * Cancel does not wait for it.
 */
export function decodeAudio(input: ArrayBuffer | Blob | AudioBuffer, sampleRate: number, signal?: AbortSignal): Promise<DecodedAudio> {
  if (!signal) return decodeNow(input, sampleRate);
  if (signal.aborted) return Promise.reject(signal.reason);
  return new Promise((resolve, reject) => {
    const stop = () => reject(signal.reason);
    signal.addEventListener('abort', stop, { once: true });
    decodeNow(input, sampleRate, signal).then(resolve, reject).finally(() => signal.removeEventListener('abort', stop));
  });
}

async function decodeNow(input: ArrayBuffer | Blob | AudioBuffer, sampleRate: number, signal?: AbortSignal): Promise<DecodedAudio> {
  let buffer: AudioBuffer;
  let statedSeconds: number | null = null;
  if (input instanceof AudioBuffer) buffer = input;
  else {
    const bytes = input instanceof Blob ? await input.arrayBuffer() : input;
    statedSeconds = statedSecondsIfCut(bytes);
    if (bytes.byteLength === 0) throw new AudioDecodeError('the file is empty');
    // decodeAudioData needs a context; a one-sample offline context decodes without touching the speakers.
    const ctx = new OfflineAudioContext(1, 1, 44100);
    try {
      buffer = await ctx.decodeAudioData(bytes.slice(0));
    } catch (e) {
      throw new AudioDecodeError(undecodableReason(bytes)
        ?? `this browser cannot decode the file (${(e as Error).message || 'decode failed'}): if it plays elsewhere, ${CONVERT}`);
    }
  }
  if (buffer.length === 0) throw new AudioDecodeError('the audio has no samples');
  const source = { decodedRate: buffer.sampleRate, channels: buffer.numberOfChannels, seconds: buffer.duration, statedSeconds };
  const channels = Array.from({ length: buffer.numberOfChannels }, (_, c) => buffer.getChannelData(c));
  if (buffer.sampleRate === sampleRate) return { samples: mixToMono(channels), sampleRate, buffer, source };
  // Not a Web Audio source node into a context at the model's rate: Chromium's interpolates with no low-pass, and a
  // fricative's hiss above the model's band came out folded into it (training resamples with sox's low-pass).
  const mono = channels.length > 1 ? mixToMono(channels) : channels[0]; // (one channel is not copied first)
  return { samples: await resampleAll(mono, buffer.sampleRate, sampleRate, signal), sampleRate, buffer, source };
}

/** 5.1's channels (L, R, C, LFE, SL, SR) in Web Audio's down-mix to mono: the centre, the front pair, the surrounds. */
const SURROUND_51 = [Math.SQRT1_2, Math.SQRT1_2, 1, 0, 0.5, 0.5];

/**
 * One channel (a new array) from a clip's: their mean, or for six channels (5.1) Web Audio's weights scaled to sum
 * to one, so that speech on every channel keeps its level. (Web Audio's own down-mix sums 5.1 to 3.4 times a
 * channel's level, which clips, and keeps only the first channel of counts with no speaker layout: 3, 5, 7 ...)
 */
export function mixToMono(channels: readonly Float32Array[]): Float32Array<ArrayBuffer> {
  if (channels.length === 1) return new Float32Array(channels[0]);
  const weights = channels.length === 6 ? SURROUND_51 : channels.map(() => 1);
  const total = weights.reduce((a, b) => a + b, 0);
  const out = new Float32Array(channels[0].length);
  channels.forEach((x, c) => {
    const g = weights[c] / total;
    if (g) for (let i = 0; i < out.length; i++) out[i] += g * x[i];
  });
  return out;
}

/** Peak level and the share of samples at full scale, for warnings about silence and clipping. */
export function levels(samples: Float32Array): { peak: number; rms: number; clipped: number } {
  let peak = 0;
  let sum = 0;
  let clipped = 0;
  for (let i = 0; i < samples.length; i++) {
    const a = Math.abs(samples[i]);
    peak = Math.max(peak, a);
    sum += a * a;
    if (a >= 0.999) clipped++;
  }
  return { peak, rms: Math.sqrt(sum / Math.max(1, samples.length)), clipped: clipped / Math.max(1, samples.length) };
}

/** Below this peak (-30 dBFS) a clip is quiet: raised for the model (raiseIfQuiet). */
const QUIET_PEAK = 0.0316;
/** Below this peak a clip is silent (-60 dBFS): left as it is, and said so. */
export const SILENT_PEAK = 1e-3;
const RAISED_PEAK = 0.5;

/**
 * A quiet clip (peak between SILENT_PEAK and QUIET_PEAK) raised to a peak of -6 dBFS, for the model, with the gain in
 * dB; any other as it is (gain 0). Quiet speech otherwise falls below the voice detector's level (a frame RMS of
 * about -50 dBFS, encoders/voice-activity.ts) and is taken for no speech: the mouth would stay shut.
 */
export function raiseIfQuiet(samples: Float32Array): { samples: Float32Array; gainDb: number } {
  const { peak } = levels(samples);
  if (peak < SILENT_PEAK || peak >= QUIET_PEAK) return { samples, gainDb: 0 };
  const gain = RAISED_PEAK / peak;
  return { samples: samples.map((x) => x * gain), gainDb: 20 * Math.log10(gain) };
}
