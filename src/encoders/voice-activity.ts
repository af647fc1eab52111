/**
 * Is anyone speaking? Per frame: the content encoder's belief that it hears a phone rather than silence
 * (1 - P(SIL)), where the signal is loud enough to hold speech at all and its spectrum is not flat like noise's (the
 * encoder hears white noise as silence, but the same noise after a browser has resampled it as "M"). Per clip: speech
 * is found when enough frames are speech-like and they are not one steady sound (the encoder hears a tone or a chord
 * as one long "L" or "M", where speech changes phone every few frames).
 */

/** Below this RMS (about -50 dBFS) a frame is taken as silence whatever the encoder hears. */
export const SPEECH_LEVEL = 0.003;
/** Above this spectral flatness a frame is noise (white noise: 0.7-0.8; resampled: 0.3-0.6; speech: below 0.1 mostly). */
export const NOISE_FLATNESS = 0.25;
/** A frame is speech-like when its speech probability exceeds this. */
export const SPEECH_PROBABILITY = 0.5;
/** Live frames without speech after which a face goes back to rest (the player's, an avatar driver's): a breath between words does not. */
export const LIVE_REST_FRAMES = 12;
/** A clip holds speech when it has this many seconds of speech-like frames ... */
export const MIN_SPEECH_SECONDS = 0.15;
/** ... and no single heard phone takes more than this share of them (a steady sound is not speech). */
export const MAX_ONE_PHONE_SHARE = 0.7;

/** RMS of `frameSize` samples centred at sample `centre` of a signal of which `samples` holds [offset, ...). */
export function levelAt(samples: Float32Array, offset: number, centre: number, frameSize: number): number {
  const lo = Math.max(0, centre - frameSize / 2 - offset);
  const hi = Math.min(samples.length, centre + frameSize / 2 - offset);
  let sum = 0;
  for (let i = lo; i < hi; i++) sum += samples[i] * samples[i];
  return hi > lo ? Math.sqrt(sum / (hi - lo)) : 0;
}

/**
 * Spectral flatness of one log-Mel frame (ln(1 + energy) per band): the geometric over the arithmetic mean of each
 * band's energy per FFT bin (`widths`: melBandWidths). Near 1 for white noise, near 0 for voiced speech and tones.
 */
export function melFlatness(melRow: Float32Array, widths: Float64Array): number {
  let logSum = 0, sum = 0, bands = 0;
  for (let b = 0; b < melRow.length; b++) {
    if (!(widths[b] > 0)) continue;
    const e = Math.expm1(melRow[b]) / widths[b] + 1e-12;
    logSum += Math.log(e);
    sum += e;
    bands++;
  }
  return bands ? Math.exp(logSum / bands) / (sum / bands) : 0;
}

/**
 * Per frame: 1 - P(SIL) at its content position (row `rows[i]` of the posteriors), and 0 where the frame's `level`
 * (RMS) is below SPEECH_LEVEL or its `flatness` above NOISE_FLATNESS.
 */
export function speechProbabilities(post: Float32Array, classes: number, silence: number, rows: number[], level: number[], flatness: number[]): Float32Array {
  return Float32Array.from(rows, (row, i) => (level[i] < SPEECH_LEVEL || flatness[i] > NOISE_FLATNESS ? 0 : 1 - post[row * classes + silence]));
}

/** Whether a clip holds speech, from its frames' speech probabilities and heard phones (Animation.speech, .phones). */
export function speechFound(speech: Float32Array, phones: Uint8Array, fps: number): boolean {
  const counts = new Map<number, number>();
  let n = 0;
  for (let f = 0; f < speech.length; f++) {
    if (speech[f] <= SPEECH_PROBABILITY) continue;
    n++;
    counts.set(phones[f], (counts.get(phones[f]) ?? 0) + 1);
  }
  if (n < MIN_SPEECH_SECONDS * fps) return false;
  return Math.max(...counts.values()) / n <= MAX_ONE_PHONE_SHARE;
}
