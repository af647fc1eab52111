/** What is worth telling a person about a clip's audio: silence, no speech, raised from quiet, clipping, length. */
import { SILENT_PEAK, levels } from '../audio/decode';

/** Longer clips get a note: they take a while, and their take's memory grows with them (40-50 MB a minute in the demo). */
export const LONG_CLIP_SECONDS = 120;
/** Shorter clips get a note, and no speed figure (a few frames measure start-up, not speed). */
export const SHORT_CLIP_SECONDS = 0.5;

/** What audioNotes knows besides the samples. */
export interface NoteOptions {
  /** Whether speech was found (the engine's hasSpeech, once animated; default true). */
  speech?: boolean;
  /** The gain a quiet clip was raised by for the model (raiseIfQuiet; default 0). */
  raisedDb?: number;
  /** Notes while it is being animated: a long clip says it can be cancelled (default false). */
  animating?: boolean;
  /** How long the file's header says it is, where it holds less (DecodedAudio's source.statedSeconds; default null). */
  statedSeconds?: number | null;
}

/**
 * Notes for a person about a clip's audio, the most important first: the file cut short, silent, no speech in it,
 * raised because it was quiet, clipped, very short; long (while animating). Empty when there is nothing to say.
 */
export function audioNotes(samples: Float32Array, seconds: number, { speech = true, raisedDb = 0, animating = false, statedSeconds = null }: NoteOptions = {}): string[] {
  const lv = levels(samples);
  const notes: string[] = [];
  if (statedSeconds !== null && statedSeconds > seconds) notes.push(`the file ends early: it holds ${seconds.toFixed(1)} s of the ${statedSeconds.toFixed(1)} s its header states (cut short while copying or recording?)`);
  if (lv.peak < SILENT_PEAK) notes.push('the audio is silent, so the mouth stays closed');
  else if (!speech) notes.push('no speech was found in it (noise, music or a tone?), so the mouth stays at rest');
  if (lv.peak >= SILENT_PEAK && raisedDb > 0) notes.push(`very quiet (peak ${(20 * Math.log10(lv.peak)).toFixed(0)} dBFS): raised by ${raisedDb.toFixed(0)} dB to animate it`);
  if (lv.clipped > 0.01) notes.push(`${(100 * lv.clipped).toFixed(1)}% of the samples are clipped (distorted); the motion may be less accurate`);
  if (seconds < SHORT_CLIP_SECONDS) notes.push(`a very short clip (${seconds.toFixed(2)} s): too short to show much`);
  if (animating && seconds > LONG_CLIP_SECONDS) notes.push(`a long clip (${(seconds / 60).toFixed(1)} min): it takes a while, and the page's memory grows with its length; Cancel stops it`);
  return notes;
}
