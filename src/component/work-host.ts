/** What <talking-face> lends the work it starts (a stream of speech, the microphone): its model, player, status line and events. */
import type { TalkingFaceEngine } from '../engine/engine';
import type { Player } from '../player/player';
import type { TalkingFaceErrorDetail } from './events';

export interface WorkHost {
  /** The engine, once loaded (null: stopped meanwhile; rejects when it cannot be loaded, which the element has reported). */
  engine: Promise<TalkingFaceEngine | null>;
  /** The player of the face or avatar being shown now, or null. */
  player(): Player | null;
  /** The player once the view being made is there (an avatar still loading is waited for); null where it failed. */
  settled(): Promise<Player | null>;
  /** Whether this work is still the element's (not stopped, not replaced). */
  current(): boolean;
  /** Aborted when the work is stopped or replaced. */
  signal: AbortSignal;
  element: Element;
  status(text: string): void;
  /** The status line while it plays (shown again once a gesture lets the sound start: autoplay rules). */
  playing(text: string): void;
  /** Report a failure (the status line, an `error` event) and return it to reject with. */
  fail(stage: TalkingFaceErrorDetail['stage'], message: string): Error;
  dispatch(event: Event): void;
  /** Stop the element as stop() does (the sound, the face back to rest, `ended` once it had begun to play), its status line left as it is. */
  halt(): void;
}
