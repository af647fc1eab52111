/**
 * speakStream()'s options, checked before anything stops, and what a SpeechStream (speech-stream.ts) is lent by
 * what shows it: <talking-face> or a page's own scene (page-stream.ts).
 */
import type { TalkingFaceEngine } from '../engine/engine';
import type { Animation, Frames } from '../engine/frames';
import { checkedStreamRate } from '../audio/pcm';
import { mediaProblem, MEDIA_RATE } from '../audio/media-speech';
import type { StreamOutput } from './stream-playback';

/** speakStream()'s options: pieces the page writes at `sampleRate`, or a MediaStream followed (`media`). */
export type SpeechStreamOptions = WrittenSpeechOptions | MediaSpeechOptions;

export interface WrittenSpeechOptions extends StreamDelayOption {
  /** The pieces' sample rate in Hz (24000 for most speech services' 16-bit PCM). */
  sampleRate: number;
  media?: undefined;
}

export interface MediaSpeechOptions extends StreamDelayOption {
  /**
   * A MediaStream to follow (a voice agent's WebRTC track): its sound is played, with the face, from the element (or
   * the page's context: speakStream(engine, ...); leave it unplayed elsewhere: it would be heard twice) until its audio
   * ends or end() or stop() is called. Its tracks are
   * left running. No take is kept (a call may last hours).
   */
  media: MediaStream;
  sampleRate?: undefined;
}

export interface StreamDelayOption {
  /**
   * How long after the first piece arrives its sound starts (ms). Default: the model's look-ahead, the first piece's
   * length (at most 0.25 s) and 150 ms to compute in: about 0.36 s for pieces of 0.1 s. Where frames come late all the
   * same (a slow device, a busy page) it grows by itself, at the cost of a pause in the sound.
   */
  delayMs?: number;
}

/** speakStream()'s options, checked before the element stops what it does: a bad one throws a TypeError or RangeError. */
export function checkedStreamOptions(options: SpeechStreamOptions): { sampleRate: number; media: MediaStream | null; delayMs: number | undefined } {
  const { sampleRate, media, delayMs } = (options ?? {}) as Partial<WrittenSpeechOptions & MediaSpeechOptions> & { sampleRate?: number; media?: MediaStream };
  if (media !== undefined) {
    const problem = sampleRate === undefined ? mediaProblem(media) : 'give sampleRate (pieces written) or media (a MediaStream), not both';
    if (problem) throw new TypeError(`speakStream: ${problem}`);
  }
  if (delayMs !== undefined && !(delayMs >= 0 && delayMs <= 10000)) throw new RangeError(`speakStream: delayMs must be from 0 to 10000 ms; it was ${delayMs}`);
  return { sampleRate: media ? MEDIA_RATE : checkedStreamRate(sampleRate, 'speakStream'), media: media ?? null, delayMs };
}

/** A stream's whole speech once played: its frames (engine.animate's take for the same audio) and its sound. */
export interface StreamTake {
  animation: Animation;
  buffer: AudioBuffer;
}

/** What a SpeechStream is lent by what shows it: <talking-face> (talking-face.ts) or a page's own scene (page-stream.ts). */
export interface StreamHost {
  /** The engine once loaded (null: stopped meanwhile; rejects where it cannot be loaded, which the host has reported). */
  engine: Promise<TalkingFaceEngine | null>;
  /** Where the sound plays and the frames are shown, once there (null: nowhere, as an element not in the page). */
  output(): Promise<StreamOutput | null>;
  /** The engine stream's options (engine.createStream), read once the engine is there. */
  streamOptions(): { blendshapes?: boolean; headMotionScale?: number };
  /** Whether the stream is still the host's (not stopped, not replaced); `signal` aborts once it is not. */
  current(): boolean;
  signal: AbortSignal;
  status(text: string): void;
  /** The status while it plays, with the delay (s); again each time the delay grows. */
  playing(delay: number, backend: string): void;
  /** Report a failure and return it, to reject `done` with. */
  fail(stage: 'audio' | 'inference' | 'avatar', message: string): Error;
  /** The stream's frame `frame`, which is `frames`' frame `at`, was shown (by `engine`'s stream). */
  frame(engine: TalkingFaceEngine, frame: number, frames: Frames, at: number, lateFrames: number): void;
  /** Played out (null: a MediaStream's, whose speech is not kept). */
  played(take: StreamTake | null): void;
  /** Stop as stop() does (the sound, the face back to rest), what was said left as it is. */
  halt(): void;
}
