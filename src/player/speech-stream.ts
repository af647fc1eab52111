/**
 * Speech that arrives in pieces (a streaming text-to-speech, a voice agent's socket or WebRTC track) animated and
 * played as it comes, the face in sync with the sound: <talking-face>'s speakStream(), and speakStream(engine, ...)
 * for a page's own scene (page-stream.ts). Each piece is played a fixed delay after the first arrived
 * (stream-playback.ts) and pushed, at the model's rate, into the engine's stream, whose frames are ready before their
 * sound plays. docs/embedding.md, "Streamed speech".
 */
import type { TalkingFaceEngine } from '../engine/engine';
import { placeFrames, type Frames } from '../engine/frames';
import type { StreamSession } from '../engine/stream';
import { StreamResampler } from '../audio/resample';
import { PcmReader, type PcmChunk } from '../audio/pcm';
import { StreamPlayback, type StreamOutput } from './stream-playback';
import { followMedia, MEDIA_PIECE_SECONDS, type MediaFollower } from '../audio/media-speech';
import type { checkedStreamOptions, StreamHost, StreamTake } from './stream-options';

/** What the delay holds besides the model's look-ahead and the first piece: time to compute the frames (s). */
export const STREAM_MARGIN_SECONDS = 0.15;
/**
 * The first piece counts for at most this long (s): pieces that come at the pace of speech each wait for the next (the
 * look-ahead reads into it), but a long first piece is a burst, and the delay grows by itself where frames come late.
 */
export const FIRST_PIECE_SECONDS = 0.25;

/** What speakStream({ media }) returns: a SpeechStream without write() (its sound comes from the MediaStream). */
export type MediaSpeechStream = Omit<SpeechStream, 'write'>;

export class SpeechStream {
  /** Resolves once everything written has played (after end()), or on stop(); rejects if the stream failed. */
  readonly done: Promise<void>;
  readonly sampleRate: number;
  /** The whole speech once it has played out (not for a MediaStream's); null until then. */
  take: StreamTake | null = null;
  private readonly reader: PcmReader;
  private pieces: Float32Array[] = [];
  private pending: Float32Array[] = []; // written before the model and the face were there
  private written = 0; // samples written, at sampleRate
  private pushed = 0; // samples pushed into the engine's stream, at the model's rate
  private ended = false;
  private ending = false; // end() waits for a MediaStream's last pieces
  private closed = false;
  private failure: Error | null = null;
  private readonly delayMs0: number | undefined; // the page's delayMs
  private session: StreamSession | null = null;
  private resampler: StreamResampler | null = null;
  private playback: StreamPlayback | null = null;
  private started: { engine: TalkingFaceEngine; output: StreamOutput } | null = null;
  private chunks: { first: number; frames: Frames }[] = [];
  private media: { stream: MediaStream; follower: MediaFollower | null } | null = null; // speakStream({ media })
  private settle: { resolve: () => void; reject: (e: Error) => void } = { resolve: () => undefined, reject: () => undefined };

  /** `options` as checkedStreamOptions gives them. */
  constructor(options: ReturnType<typeof checkedStreamOptions>, private readonly host: StreamHost) {
    this.sampleRate = options.sampleRate;
    this.reader = new PcmReader('SpeechStream.write', this.sampleRate);
    if (options.media) this.media = { stream: options.media, follower: null };
    this.delayMs0 = options.delayMs;
    this.done = new Promise((resolve, reject) => (this.settle = { resolve, reject }));
    this.done.catch(() => undefined); // deliberate: the failure is also an `error` event; a page need not await done
    host.signal.addEventListener('abort', () => this.close(), { once: true });
    void this.start();
  }

  /** Whether it may still play (not played out, stopped or failed). */
  get open(): boolean {
    return !this.closed;
  }

  /** Seconds of speech written so far. */
  get seconds(): number {
    return this.written / this.sampleRate;
  }

  /** How long a piece that starts the sound waits between its arrival and its sound (ms; it grows where frames came late); null before the first piece. */
  get delayMs(): number | null {
    return this.playback ? this.playback.delay * 1000 : null;
  }

  /**
   * Frames whose sound played before they were computed (the device behind the delay), and the times the sound paused
   * (the pieces ran dry, or the delay grew because frames came late).
   */
  get late(): { frames: number; pauses: number } {
    return { frames: this.playback?.lateFrames ?? 0, pauses: this.playback?.pauses ?? 0 };
  }

  /**
   * The next piece: mono samples at `sampleRate` (a Float32Array in -1..1, an Int16Array, or the bytes of 16-bit
   * little-endian PCM). False when the stream is over (stopped, ended or failed) and the piece was dropped; throws a
   * TypeError or RangeError for a piece that is not audio.
   */
  write(chunk: PcmChunk): boolean {
    if (this.media) throw new TypeError('SpeechStream.write: this stream follows a MediaStream; write() is for a stream opened with a sampleRate');
    return this.accept(this.closed || this.ended || this.ending ? null : this.reader.read(chunk));
  }

  /** A piece (null: the stream is over); kept for the take unless following a MediaStream. */
  private accept(samples: Float32Array | null): boolean {
    if (!samples || this.closed || this.ended) return false;
    if (samples.length === 0) return true;
    if (!this.media) this.pieces.push(samples);
    this.written += samples.length;
    if (this.started) this.feed(samples);
    else this.pending.push(samples);
    return true;
  }

  /** Stop now, as the element's stop() does (the sound stops, the face rests); `done` resolves. */
  stop(): void {
    if (this.closed) return;
    if (this.host.current()) {
      this.host.halt();
      this.host.status('Stopped.');
    }
    this.close();
  }

  /** No more pieces (a MediaStream is no longer followed): `done` resolves once the last has played. */
  end(): void {
    if (this.closed || this.ended || this.ending) return;
    const follower = this.media?.follower;
    if (follower) { // its last pieces first
      this.ending = true;
      return void follower.stop().finally(() => {
        [this.ending, this.media!.follower] = [false, null];
        this.end();
      });
    }
    this.ended = true;
    if (this.started) void this.finish();
  }

  private async start(): Promise<void> {
    let engine: TalkingFaceEngine | null, output: StreamOutput | null;
    try {
      engine = await this.host.engine;
      output = engine && (await this.host.output());
    } catch (e) {
      return this.fail(e as Error); // the model could not be loaded: load() has said so
    }
    if (this.closed || !this.host.current() || !engine) return this.close();
    if (!output) return this.fail(this.host.fail('avatar', 'there is no face to show the speech on (is the element in the page?)'));
    try {
      this.started = { engine, output };
      this.session = engine.createStream((first, frames) => this.frames(first, frames), this.host.streamOptions());
      this.resampler = new StreamResampler(this.sampleRate, engine.manifest.audio.sample_rate);
      for (const p of this.pending.splice(0)) this.feed(p);
    } catch (e) {
      return this.broken(e as Error); // (the options were checked: not expected, but `done` must settle)
    }
    if (this.ended) void this.finish();
    else if (this.media) await this.follow(this.media);
  }

  private async follow(media: { stream: MediaStream; follower: MediaFollower | null }): Promise<void> {
    try {
      media.follower = await followMedia(media.stream, (piece) => this.accept(piece), () => this.end());
    } catch (e) {
      if (this.closed || !this.host.current()) return; // stopped, or replaced, while the capture started: no failure of the work now
      return this.lost('audio', `the MediaStream's sound could not be followed: ${(e as Error).message}`);
    }
    if (this.closed || this.ended) void media.follower.stop(); // ended or stopped while the capture started
  }

  /** The delay before the first piece's sound (s): the page's, or the look-ahead, the first piece and a margin. */
  private firstDelay(first: Float32Array): number {
    if (this.delayMs0 !== undefined) return this.delayMs0 / 1000;
    const piece = this.media ? MEDIA_PIECE_SECONDS : first.length / this.sampleRate;
    return this.session!.lookAheadMs / 1000 + Math.min(FIRST_PIECE_SECONDS, piece) + STREAM_MARGIN_SECONDS;
  }

  private feed(samples: Float32Array): void {
    const { engine, output } = this.started!;
    if (!this.playback) {
      const delay = this.firstDelay(samples);
      const playing = (d: number) => this.host.playing(d, engine.backend);
      this.playback = new StreamPlayback(output, this.sampleRate, engine.fps, delay, {
        onFrame: (frame, frames, at) => this.host.frame(engine, frame, frames, at, this.playback?.lateFrames ?? 0),
        onDelay: playing, lookAhead: this.session!.lookAheadMs / 1000,
      });
      void this.playback.done.then(() => { // stopped with its output (the element's stop()), or its context closed
        if (this.playback?.contextClosed && !this.closed) this.lost('audio', 'its audio context was closed: nothing more can play on it');
        else if (!this.playback?.playedOut) this.close();
      });
      playing(delay);
    }
    let pushed: Promise<void>;
    try {
      pushed = this.push(this.resampler!.push(samples));
    } catch (e) {
      return this.broken(e as Error); // (write() checks each piece first: not expected)
    }
    this.playback.write(samples);
    pushed.catch((e: Error) => this.broken(e));
  }

  private push(samples: Float32Array): Promise<void> {
    this.pushed += samples.length;
    return this.session!.push(samples);
  }

  private frames(first: number, frames: Frames): void {
    if (this.closed) return;
    if (!this.media) this.chunks.push({ first, frames });
    this.playback?.frames(first, frames);
  }

  /** The last piece is in: the resampler's tail and the stream's last frames, then the sound plays out. */
  private async finish(): Promise<void> {
    try {
      // The resampler holds back half its kernel: zeros after the end bring the last samples out, and no more.
      const tail = this.resampler!.flush();
      const model = this.started!.engine.manifest.audio.sample_rate;
      const missing = Math.round((this.written / this.sampleRate) * model) - this.pushed;
      if (missing > 0) await this.push(tail.subarray(0, missing));
      await this.session!.end();
    } catch (e) {
      return this.broken(e as Error);
    }
    if (this.closed) return;
    if (!this.playback) return this.close(); // nothing was written: no take, no `ended` (nothing played)
    this.playback.end();
    await this.playback.done;
    if (!this.playback.playedOut || !this.host.current()) return this.close();
    if (this.media || this.chunks.length === 0) return this.over(`Played the stream's speech (${this.seconds.toFixed(1)} s).`, null);
    const total = this.chunks.at(-1)!.first + this.chunks.at(-1)!.frames.count;
    const buffer = new AudioBuffer({ length: this.written, numberOfChannels: 1, sampleRate: this.sampleRate });
    let at = 0;
    for (const p of this.pieces) {
      buffer.getChannelData(0).set(p, at);
      at += p.length;
    }
    this.pieces = [];
    this.take = { animation: placeFrames(this.chunks, total, this.started!.engine.fps), buffer };
    this.over(`Played streamed speech (${buffer.duration.toFixed(1)} s${this.playback.lateFrames ? `; ${this.playback.lateFrames} frames came late` : ''}).`, this.take);
  }

  /** Played out: say so, hand the take over (the element sends `ended`), settle `done`. */
  private over(status: string, take: StreamTake | null): void {
    this.host.status(status);
    this.host.played(take);
    this.close();
  }

  private broken(e: Error): void {
    if (this.closed || !this.host.current()) return;
    this.lost('inference', `the streamed speech could not be animated: ${e.message}`);
  }

  /** Failed while it may have begun to play: said, then the element stopped (the face rests; `ended` if the sound had begun). */
  private lost(stage: 'audio' | 'inference', message: string): void {
    const failure = this.host.fail(stage, message);
    this.host.halt();
    this.fail(failure);
  }

  private fail(e: Error): void {
    this.failure ??= e;
    this.close();
  }

  /** Over: stopped, played out or failed. The sound stops (if it still plays), the engine's work on it too, and `done` settles. */
  private close(): void {
    if (this.closed) return;
    this.closed = true;
    void this.media?.follower?.stop();
    this.session?.cancel();
    this.playback?.stop();
    [this.pending, this.pieces, this.chunks] = [[], [], []];
    if (this.failure) this.settle.reject(this.failure);
    else this.settle.resolve();
  }
}
