/**
 * Streamed speech played with the face in sync. Pieces of sound are scheduled on the output's audio clock (the
 * element's Player, or a page's own) in spans (StreamTimeline): a span starts `delay` seconds after its first piece
 * arrived, and not before the frame of its first sound has been computed; the pieces after it play back to back. Each animation frame shows the frame whose sound
 * is playing. Where the engine falls behind all the same (frames computed after their sound began: a slow device, a
 * busy page), the delay grows by how late they came and the next piece starts a new span that much later: the sound
 * pauses once, and the face is in sync again.
 */
import type { Frames } from '../engine/frames';
import { LIVE_REST_FRAMES, SPEECH_PROBABILITY } from '../encoders/voice-activity';
import { heardTime, SCHEDULE_MARGIN, StreamTimeline } from './stream-timeline';

/** A pause in the sound longer than this (s) brings the face back to rest until the sound goes on. */
export const REST_AFTER_SECONDS = 0.25;
/** Frames this late (s) or less do not move the delay (a display shows them a frame later at worst). */
export const LATE_TOLERANCE = 0.04;
/** Where the delay grows, it grows this much (s) beyond what the late frames needed, so that it need not grow again soon. */
export const GROW_MARGIN = 0.1;
/** The delay never grows beyond this (s). */
export const MAX_DELAY = 3;
/** Spans of sound over for longer than this (s) are forgotten: frames that late still count as late. */
const FORGET_AFTER = 2 * MAX_DELAY;

/**
 * Where streamed speech plays and shows: the element's Player, or a page's own audio context and avatar
 * (page-stream.ts). One stream at a time: beginStream() stops the one before.
 */
export interface StreamOutput {
  /** A stream begins (`stop` ends it: called by stop(), or when another begins): the audio context it plays on. */
  beginStream(stop: () => void): AudioContext;
  /** Connect a source of the stream's sound to where it is heard. */
  output(node: AudioNode): void;
  /** Show frame `f` of `frames`; `speaking` false: the face goes back to rest (a pause in the sound, the end). */
  showFrame(frames: Frames, f: number, speaking: boolean): void;
  /** The stream `stop` is over (played out, or stopped). */
  streamDone(stop: () => void): void;
  /** Stop the stream playing (its `stop`). */
  stop(): void;
}

export interface StreamPlaybackOptions {
  /** Called for each frame shown: the stream's frame `frame`, which is `frames`' frame `at`. */
  onFrame?: (frame: number, frames: Frames, at: number) => void;
  /** Called when the delay grows (its new value, s). */
  onDelay?: (delay: number) => void;
  /**
   * How far past its own time a frame reads the sound (s: the model's look-ahead). A frame computed late only because
   * that sound came late (the pieces paused: between sentences, a stall) does not make the delay grow.
   */
  lookAhead?: number;
}

export class StreamPlayback {
  /** Resolves when every piece written has played and its frames shown after end(), or when stopped. */
  readonly done: Promise<void>;
  /** Frames shown after their sound had begun (the newest computed frame shown in their place). */
  lateFrames = 0;
  /** Times the sound paused: the stream ran dry, or the delay grew. */
  pauses = 0;
  /** Set when it ended by playing everything out (not by stop()). */
  playedOut = false;
  /** Set when it ended because its audio context was closed (nothing can play on it any more). */
  contextClosed = false;
  private readonly timeline: StreamTimeline;
  private readonly context: AudioContext;
  private readonly sources = new Set<AudioBufferSourceNode>();
  private waiting: Float32Array[] = []; // pieces of a span that has not started
  private waitingSince = 0; // clock time its first piece arrived
  private spanDelay = 0; // the span playing: seconds from its first piece's arrival to its sound
  private needed = 0; // the delay the frames of the span playing needed (0: none came late)
  private chunks: { first: number; frames: Frames }[] = [];
  private arrivals: { end: number; time: number }[] = []; // recent pieces: the sample after each, and when it came
  private computed = 0; // frames [0, computed) have come
  private ended = false;
  private over = false;
  private tick = 0;
  private shown = -1;
  private resting = false; // the sound has paused long enough for the face to rest
  private finish: () => void = () => undefined;
  private endTimer: ReturnType<typeof setTimeout> | undefined;
  private readonly stopper = () => this.close();

  /** `rate`: the pieces' sample rate; `fps`: the frames'; `delay`: seconds from a span's first piece arriving to its sound. */
  constructor(private readonly out: StreamOutput, readonly rate: number, private readonly fps: number, public delay: number,
    private readonly options: StreamPlaybackOptions = {}) {
    this.timeline = new StreamTimeline(rate);
    this.done = new Promise((resolve) => (this.finish = resolve));
    this.context = out.beginStream(this.stopper);
    this.context.addEventListener('statechange', this.watchContext);
    this.tick = requestAnimationFrame(this.draw);
    this.watchContext();
  }

  /** A closed context plays nothing more and its clock stops: the playback is over (`contextClosed`). */
  private readonly watchContext = (): void => {
    if (this.context.state !== 'closed' || this.over) return;
    this.contextClosed = true;
    this.close();
  };

  /** The next piece of sound (mono, at `rate`): it plays after the pieces before it. */
  write(samples: Float32Array): void {
    if (this.over || this.ended || samples.length === 0) return;
    const now = this.context.currentTime;
    const follows = this.timeline.follows(now);
    this.arrivals.push({ end: this.timeline.samples + this.waiting.reduce((n, w) => n + w.length, 0) + samples.length, time: now });
    if (this.needed > this.delay) { // and this piece starts a new span
      const grown = Math.max(this.delay, Math.min(MAX_DELAY, this.needed)); // (a page's longer delay is never cut)
      if (grown !== this.delay) {
        this.delay = grown;
        this.options.onDelay?.(grown);
      }
    } else if (follows !== null && this.waiting.length === 0) return this.schedule(samples, follows);
    this.needed = 0;
    if (this.waiting.length === 0) this.waitingSince = now;
    this.waiting.push(samples);
    this.release();
  }

  /** Frames `first` .. computed by the engine from the pieces written (in order, from frame 0). */
  frames(first: number, frames: Frames): void {
    if (this.over || frames.count === 0) return;
    this.chunks.push({ first, frames });
    this.computed = first + frames.count;
    this.forgetPast(); // (as draw() does: a hidden tab draws nothing, and a call may last hours)
    const late = this.lateness(first, frames.count);
    if (late > LATE_TOLERANCE) this.needed = Math.max(this.needed, this.spanDelay + late + GROW_MARGIN);
    this.release();
  }

  /**
   * How late frames [first, first + count) came, just in, for want of time to compute them: after their sound began,
   * the sound they read (their look-ahead) having come before. Frames whose sound has not begun, and frames that read
   * sound which came only after their own had begun (the pieces paused: no delay would have helped), do not count.
   */
  private lateness(first: number, count: number): number {
    const now = this.context.currentTime;
    const lookAhead = this.options.lookAhead ?? 0;
    let ready = Infinity; // the earliest time one of them could have been shown in time
    for (let f = first; f < first + count; f++) {
      const due = this.timeline.timeOf(Math.round((f / this.fps) * this.rate));
      if (due === null) continue; // its sound is still to be placed: not late
      const needs = Math.round((f / this.fps + lookAhead) * this.rate);
      const came = this.arrivals.find((a) => a.end >= needs)?.time ?? this.arrivals.at(-1)?.time ?? now; // (past the end: the last piece)
      if (came <= due) ready = Math.min(ready, due); // (else its sound had begun before what it reads came: no delay helps)
    }
    while (this.arrivals.length > 1 && this.arrivals[1].end < Math.round((first / this.fps) * this.rate)) this.arrivals.shift();
    return heardTime(this.context) - ready; // (late once heard without it; -Infinity where none is placed yet: not late)
  }

  /** No more pieces, and every frame of them has come: once the last has played, the playback is over. */
  end(): void {
    this.ended = true;
    this.release(); // a last piece too short for a frame of its own
    this.endLater();
  }

  /** Stop the sound now; `done` resolves. */
  stop(): void {
    if (!this.over) this.out.stop(); // calls close(), as the output's own stop() does (the element's stop())
  }

  private schedule(samples: Float32Array, at: number): void {
    const buffer = new AudioBuffer({ length: samples.length, numberOfChannels: 1, sampleRate: this.rate });
    buffer.getChannelData(0).set(samples);
    const source = this.context.createBufferSource();
    source.buffer = buffer;
    this.out.output(source);
    source.onended = () => this.sources.delete(source);
    source.start(at);
    this.sources.add(source);
    this.timeline.place(samples.length, at);
  }

  /** Schedule the waiting span once the frame of its first sound is there: `delay` after its first piece came, or later. */
  private release(): void {
    if (this.waiting.length === 0) return;
    const firstFrame = Math.floor((this.timeline.samples / this.rate) * this.fps);
    // (Once ended, every frame is in: a last piece too short for a frame of its own waits no longer.)
    if (this.computed <= firstFrame && !this.ended) return;
    let at = Math.max(this.context.currentTime + SCHEDULE_MARGIN, this.waitingSince + this.delay, this.timeline.endTime);
    if (at > this.timeline.endTime + 1e-6 && this.timeline.samples > 0) this.pauses++; // a gap in the sound
    this.spanDelay = at - this.waitingSince;
    for (const piece of this.waiting.splice(0)) {
      this.schedule(piece, at);
      at += piece.length / this.rate;
    }
    if (this.ended) this.endLater();
  }

  /**
   * Look for the end once the sound has played, on a timer as well as on animation frames: a page in a background tab
   * gets none, and its voice agent still waits for `done` to listen again.
   */
  private endLater(): void {
    clearTimeout(this.endTimer);
    const wait = Math.max(0, this.timeline.endTime - heardTime(this.context));
    this.endTimer = setTimeout(() => this.over || this.ending(heardTime(this.context)) || this.endLater(), 1000 * (wait + SCHEDULE_MARGIN));
  }

  /** Over once ended, nothing waits, the sound has been heard (`now`: heardTime) and the last frame was shown (or none can be): true then. */
  private ending(now: number): boolean {
    if (!this.ended || this.waiting.length > 0 || now < this.timeline.endTime) return false;
    if (this.computed > 0) this.show(this.computed - 1, false, this.computed - 1 !== this.shown); // over: the face back to rest
    this.playedOut = true;
    this.close();
    return true;
  }

  private close(): void {
    if (this.over) return;
    this.over = true;
    this.context.removeEventListener('statechange', this.watchContext);
    cancelAnimationFrame(this.tick);
    clearTimeout(this.endTimer);
    for (const s of this.sources) {
      s.onended = null;
      s.stop();
    }
    this.sources.clear();
    this.out.streamDone(this.stopper);
    this.finish();
  }

  private draw = (): void => {
    this.tick = 0;
    if (this.over) return;
    this.release();
    const now = heardTime(this.context); // what is heard now (the sound is rendered ahead of it)
    const at = this.timeline.at(now);
    if (at && this.computed > 0) {
      const f = Math.floor((at.sample / this.rate) * this.fps);
      const late = f >= this.computed;
      // Never before the oldest frame kept: the heard clock steps back when the output's latency grows mid-stream
      // (headphones switched on), further than the frames forget() keeps.
      const shown = late ? this.computed - 1 : Math.max(f, this.chunks[0].first);
      const resting = at.quietFor > REST_AFTER_SECONDS;
      if (shown !== this.shown || resting !== this.resting) {
        if (late && shown !== this.shown) this.lateFrames++;
        this.show(shown, !resting, shown !== this.shown);
        [this.shown, this.resting] = [shown, resting];
      }
    }
    if (this.ending(now)) return;
    this.tick = requestAnimationFrame(this.draw);
  };

  /** Forget the frames before `f` that showing it no longer needs, and the spans of sound long over. */
  private forget(f: number): void {
    while (this.chunks.length > 1 && this.chunks[1].first <= f - LIVE_REST_FRAMES) this.chunks.shift();
    this.timeline.forget(this.context.currentTime - FORGET_AFTER);
  }

  /** forget() up to the frame heard now. */
  private forgetPast(): void {
    const at = this.timeline.at(heardTime(this.context));
    if (at) this.forget(Math.min(Math.floor((at.sample / this.rate) * this.fps), this.computed - 1));
  }

  /** Show frame `f`; `sounding` false (the stream paused): the face rests. `report`: tell onFrame. */
  private show(f: number, sounding: boolean, report = true): void {
    this.forget(f);
    let k = this.chunks.length - 1;
    while (k > 0 && this.chunks[k].first > f) k--;
    const { first, frames } = this.chunks[k];
    this.out.showFrame(frames, f - first, sounding && this.spoken(f));
    if (report) this.options.onFrame?.(f, frames, f - first);
  }

  /** Whether speech was heard within the last LIVE_REST_FRAMES frames up to `f` (else the face rests, as live). */
  private spoken(f: number): boolean {
    for (const { first, frames } of this.chunks) {
      for (let i = Math.max(0, f - LIVE_REST_FRAMES + 1 - first); i < frames.count && first + i <= f; i++) {
        if (frames.speech[i] > SPEECH_PROBABILITY) return true;
      }
    }
    return false;
  }
}
