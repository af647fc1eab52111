/**
 * speakStream(engine, options): speech that arrives in pieces (a streaming text-to-speech, a voice agent's socket or
 * WebRTC track) played on the page's own audio context, each frame handed to the page's own avatar as its sound plays:
 * <talking-face>'s speakStream() for a page that draws its own scene. docs/embedding.md, "Your own avatar in your own
 * three.js scene". Library code of the engine's entry: no element, no renderer.
 */
import { checkedScale } from '../pose/head-motion';
import { resumeOnGesture } from './autoplay';
import type { TalkingFaceEngine } from '../engine/engine';
import type { Frames } from '../engine/frames';
import { SpeechStream, type MediaSpeechStream } from './speech-stream';
import { checkedStreamOptions, type MediaSpeechOptions, type StreamHost, type WrittenSpeechOptions } from './stream-options';
import type { StreamOutput } from './stream-playback';

export interface PageStreamOptions {
  /**
   * Show frame `frame` of `frames` (their `blendshapes`, `pose`, `unposed`), called as its sound plays; `speaking`
   * false: back to rest (a pause in the sound, the end, stop()). AvatarDriver's show(frames, frame, speaking) takes it.
   */
  show: (frames: Frames, frame: number, speaking: boolean) => void;
  /**
   * The audio context the sound plays on (default: one the library makes). Where the browser holds its sound back
   * (autoplay rules: no click or key press on the page yet), it is resumed at the next one; until then nothing plays,
   * no frame is shown and `done` waits. Closed while the speech plays: the stream fails (`done` rejects).
   */
  context?: AudioContext;
  /** Called when the browser holds the sound back until a click or a key press (to ask for one). */
  onBlocked?: () => void;
  /** Where the sound goes (default: the context's destination). */
  destination?: AudioNode;
  /** Each frame's blend-shape weights, `frames.blendshapes` (default true: what an avatar needs). */
  blendshapes?: boolean;
  /** The head's motion, 0-3 (default 1), as animate()'s. */
  headMotionScale?: number;
}

let shared: AudioContext | null = null; // the default context, made once

/**
 * Speech written in pieces (`sampleRate`) or followed from a MediaStream (`media`), played on `options.context` with
 * the frame of the sound playing shown through `options.show`, a short delay behind the pieces' arrival (as the
 * element's). Options are checked first: a bad one throws a TypeError or RangeError.
 */
export function speakStream(engine: TalkingFaceEngine, options: WrittenSpeechOptions & PageStreamOptions): SpeechStream;
export function speakStream(engine: TalkingFaceEngine, options: (WrittenSpeechOptions | MediaSpeechOptions) & PageStreamOptions): MediaSpeechStream;
export function speakStream(engine: TalkingFaceEngine, options: (WrittenSpeechOptions | MediaSpeechOptions) & PageStreamOptions): SpeechStream {
  const { show, context, destination, blendshapes = true, headMotionScale, onBlocked } = options ?? {};
  if (typeof (engine as Partial<TalkingFaceEngine> | null)?.createStream !== 'function') throw new TypeError('speakStream: the first argument must be a TalkingFaceEngine (await TalkingFaceEngine.load())');
  if (typeof show !== 'function') throw new TypeError('speakStream: options.show must be a function (frames, frame, speaking) => ...: it shows each frame on your avatar');
  if (onBlocked !== undefined && typeof onBlocked !== 'function') throw new TypeError('speakStream: options.onBlocked must be a function');
  if (context !== undefined && !(context instanceof AudioContext)) throw new TypeError('speakStream: options.context must be an AudioContext');
  if (context?.state === 'closed') throw new TypeError('speakStream: options.context is closed: nothing can play on it');
  if (destination !== undefined && (!(destination instanceof AudioNode) || (context && destination.context !== context))) {
    throw new TypeError('speakStream: options.destination must be an AudioNode of options.context');
  }
  checkedScale(headMotionScale); // a RangeError now, not a stream that never starts
  const checked = checkedStreamOptions(options);
  const audio = context ?? (destination?.context as AudioContext | undefined) ?? (shared ??= new AudioContext());
  if (!(audio instanceof AudioContext) || audio.state === 'closed') throw new TypeError('speakStream: options.destination must belong to an open AudioContext: nothing can play on it');
  const output = new PageOutput(audio, destination ?? audio.destination, show, onBlocked);
  const host: StreamHost = {
    engine: Promise.resolve(engine), output: async () => output, streamOptions: () => ({ blendshapes, headMotionScale }),
    current: () => true, signal: new AbortController().signal, // (nothing replaces it: the page stops it with stop())
    status: () => undefined, playing: () => undefined, frame: () => undefined, played: () => undefined,
    fail: (_stage, message) => new Error(`speakStream: ${message}`),
    halt: () => output.stop(),
  };
  return new SpeechStream(checked, host);
}

/** The page's context, destination and avatar as a stream's output; stopped, the avatar is shown at rest. */
class PageOutput implements StreamOutput {
  private stopper: (() => void) | null = null;
  private last: { frames: Frames; f: number } | null = null;
  private forgetGesture: () => void = () => undefined; // the listeners waiting for a gesture to resume the context

  constructor(private readonly context: AudioContext, private readonly destination: AudioNode,
    private readonly show: PageStreamOptions['show'], private readonly onBlocked: (() => void) | undefined) {}

  beginStream(stop: () => void): AudioContext {
    this.stopper = stop;
    const resumed = this.context.resume().catch(() => undefined); // deliberate: rejects only on a closed context, which the playback reports
    this.forgetGesture();
    this.forgetGesture = resumeOnGesture(this.context, resumed, () => this.stopper === stop, { onBlocked: this.onBlocked });
    return this.context;
  }

  output(node: AudioNode): void {
    node.connect(this.destination);
  }

  showFrame(frames: Frames, f: number, speaking: boolean): void {
    this.last = { frames, f };
    this.call(frames, f, speaking);
  }

  /** The page's show(); an error it throws is the page's (reported as uncaught), and the playback goes on. */
  private call(frames: Frames, f: number, speaking: boolean): void {
    try {
      this.show(frames, f, speaking);
    } catch (e) {
      reportError(e);
    }
  }

  streamDone(stop: () => void): void {
    if (this.stopper !== stop) return;
    this.stopper = null;
    this.forgetGesture();
  }

  stop(): void {
    const stop = this.stopper;
    this.stopper = null;
    this.forgetGesture();
    stop?.();
    if (this.last) this.call(this.last.frames, this.last.f, false); // back to rest from where it was
    this.last = null;
  }
}
