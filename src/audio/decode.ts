/**
 * Audio in: any file the browser can decode (wav, mp3, ogg/opus, webm, m4a where supported), a Blob,
 * or an AudioBuffer -> mono Float32Array at the model's sample rate. Mixing and resampling are done by
 * an OfflineAudioContext (down-mix to one channel, then the browser's resampler). Library code: Web Audio,
 * no DOM.
 */

export class AudioDecodeError extends Error {
  override name = 'AudioDecodeError';
}

export interface DecodedAudio {
  samples: Float32Array; // mono, at `sampleRate`
  sampleRate: number;
  /** The decoded original, for playback at full quality. */
  buffer: AudioBuffer;
  /** What the input was, for messages: channels and duration (decodeAudioData resamples to its context's
   * rate, so the file's own rate is not known here; decodedRate is that context rate). */
  source: { decodedRate: number; channels: number; seconds: number };
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
    decodeNow(input, sampleRate).then(resolve, reject).finally(() => signal.removeEventListener('abort', stop));
  });
}

async function decodeNow(input: ArrayBuffer | Blob | AudioBuffer, sampleRate: number): Promise<DecodedAudio> {
  let buffer: AudioBuffer;
  if (input instanceof AudioBuffer) buffer = input;
  else {
    const bytes = input instanceof Blob ? await input.arrayBuffer() : input;
    if (bytes.byteLength === 0) throw new AudioDecodeError('the file is empty');
    // decodeAudioData needs a context; a one-sample offline context decodes without touching the speakers.
    const ctx = new OfflineAudioContext(1, 1, 44100);
    try {
      buffer = await ctx.decodeAudioData(bytes.slice(0));
    } catch (e) {
      throw new AudioDecodeError(`this browser cannot decode the file (unsupported format or corrupt data): ${(e as Error).message || 'decode failed'}`);
    }
  }
  if (buffer.length === 0) throw new AudioDecodeError('the audio has no samples');
  const source = { decodedRate: buffer.sampleRate, channels: buffer.numberOfChannels, seconds: buffer.duration };
  if (buffer.numberOfChannels === 1 && buffer.sampleRate === sampleRate) {
    return { samples: buffer.getChannelData(0).slice(), sampleRate, buffer, source };
  }
  const frames = Math.max(1, Math.round(buffer.duration * sampleRate));
  const offline = new OfflineAudioContext(1, frames, sampleRate);
  const node = offline.createBufferSource();
  node.buffer = buffer;
  node.connect(offline.destination); // one output channel: the browser down-mixes (speakers rule, (L + R) / 2)
  node.start();
  const rendered = await offline.startRendering();
  return { samples: rendered.getChannelData(0).slice(), sampleRate, buffer, source };
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
