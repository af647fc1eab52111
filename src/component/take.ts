/**
 * What <talking-face>'s speak() makes of its audio before playing it: the clip decoded, animated and checked for
 * speech, with the notes a visitor reads about it (too short, clipped, no speech found, raised from quiet).
 */
import type { Animation, TalkingFaceEngine } from '../engine/engine';
import { decodeAudio, raiseIfQuiet, type DecodedAudio } from '../audio/decode';
import { audioInput, frameOptions } from './attributes';
import { audioNotes, SHORT_CLIP_SECONDS } from '../player/audio-notes';
import type { TalkingFaceErrorDetail } from './events';

export interface ElementTake {
  decoded: DecodedAudio;
  animation: Animation;
  seconds: number;
  computeMs: number;
  /** The status line while it plays. */
  playing: string;
}

/** A step of the take failed: `stage` is the error event's, the message is written for a person. */
export class TakeError extends Error {
  constructor(readonly stage: TalkingFaceErrorDetail['stage'], message: string) {
    super(message);
  }
}

/** Decode and animate `audio` for `el` (its attributes choose the frames' options); `status` tells the steps. */
export async function makeTake(engine: TalkingFaceEngine, audio: Blob | AudioBuffer | URL | string, el: Element, signal: AbortSignal,
  status: (text: string, announce: boolean) => void): Promise<ElementTake> {
  let decoded: DecodedAudio;
  try {
    status('Decoding audio…', true);
    decoded = await decodeAudio(await audioInput(audio, signal), engine.manifest.audio.sample_rate, signal); // (stop() ends a download too)
  } catch (e) {
    throw new TakeError('audio', `the audio could not be read: ${(e as Error).message}`);
  }
  signal.throwIfAborted();
  const seconds = decoded.samples.length / engine.manifest.audio.sample_rate;
  const t0 = performance.now();
  const quiet = raiseIfQuiet(decoded.samples); // quiet speech would be taken for none
  status('Animating…', true);
  let animation: Animation, computeMs: number, speech: boolean;
  try {
    ({ animation, speech } = await engine.animateSpeech(quiet.samples, { // silence, noise, music, a tone: the face at rest
      unposed: true,
      ...frameOptions(el),
      signal,
      onProgress: (done, total) => !signal.aborted && status(`Animating: frame ${done} of ${total}…`, false),
    }));
    computeMs = performance.now() - t0;
  } catch (e) {
    throw new TakeError('inference', `animation failed: ${(e as Error).message}`);
  }
  signal.throwIfAborted();
  const notes = audioNotes(decoded.samples, seconds, { speech, raisedDb: quiet.gainDb, statedSeconds: decoded.source.statedSeconds });
  const speed = seconds < SHORT_CLIP_SECONDS ? '' : `, ${(seconds / (computeMs / 1000)).toFixed(1)}x real time`;
  const playing = notes.length ? `Playing: ${notes.join('; ')}.` : `Playing (${animation.frames} frames${speed} on ${engine.backend}).`;
  return { decoded, animation, seconds, computeMs, playing };
}
