/** What <talking-face> lends the work it starts (a stream of speech, the microphone): its model, player, status line and events. */
import type { TalkingFaceEngine } from '../engine/engine';
import type { Player } from '../player/player';
import type { StreamHost, StreamTake } from '../player/stream-options';
import { frameOptions } from './attributes';
import { streamFrameDetail, type FrameDetail, type TalkingFaceErrorDetail } from './events';

/** Why work that needs the face cannot be shown: the element is not in the page (or its avatar failed, which it has said). */
export const NO_FACE = 'there is no face to show it on (is the element in the page?)';

export interface WorkHost {
  /** The engine, once loaded (null: stopped meanwhile; rejects when it cannot be loaded, which the element has reported). */
  engine: Promise<TalkingFaceEngine | null>;
  /** The player of the face or avatar being shown now, or null. */
  player(): Player | null;
  /** The player once the view being made is there (an avatar still loading is waited for); null where it failed. */
  settled(): Promise<Player | null>;
  /** Why the face could not be made (its avatar failed), or null. */
  faceError(): string | null;
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

/** What a speakStream() of the element is lent: `host`'s, its frames and end sent as events; `keep`: a take played out. */
export function elementStreamHost(host: WorkHost, keep: (take: StreamTake) => void): StreamHost {
  return {
    engine: host.engine, signal: host.signal, current: host.current, status: host.status, fail: host.fail, halt: host.halt,
    output: host.settled,
    streamOptions: () => frameOptions(host.element),
    playing: (delay, backend) => host.playing(`Playing streamed speech (${Math.round(delay * 1000)} ms behind it, ${backend}).`),
    frame: (engine, frame, frames, at, lateFrames) => host.dispatch(new CustomEvent<FrameDetail>('frame',
      { detail: streamFrameDetail(engine, frame, frames, at, lateFrames) })),
    played: (take) => {
      if (take) keep(take);
      host.dispatch(new CustomEvent('ended'));
    },
  };
}
