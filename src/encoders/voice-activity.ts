/**
 * Is anyone speaking? Per frame: the content encoder's belief that it hears a phone rather than silence
 * (1 - P(SIL)), where the signal is loud enough to hold speech at all. Per clip: speech is found when enough frames
 * are speech-like and they are not one steady sound (the encoder hears a tone or a chord as one long "L" or "M",
 * where speech changes phone every few frames). Noise needs no special case: the encoder hears it as silence.
 */

/** Below this RMS (about -50 dBFS) a frame is taken as silence whatever the encoder hears. */
export const SPEECH_LEVEL = 0.003;
/** A frame is speech-like when its speech probability exceeds this. */
export const SPEECH_PROBABILITY = 0.5;
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

/** Per frame: 1 - P(SIL) at its content position (posteriors: content frames from `lo`), zero where `level` is below SPEECH_LEVEL. */
export function speechProbabilities(post: Float32Array, classes: number, silence: number, rows: number[], level: number[]): Float32Array {
  return Float32Array.from(rows, (row, i) => (level[i] < SPEECH_LEVEL ? 0 : 1 - post[row * classes + silence]));
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
