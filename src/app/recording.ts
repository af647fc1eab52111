/**
 * The demo's microphone take: the face follows the voice live while recording; on stop, the streamed frames
 * become the take (or the whole take is animated again if frames were skipped to keep up; cancelled, the take keeps
 * the live frames, each skipped one holding the frame before it).
 */
import type { TalkingFaceEngine, Animation, Frames } from '../engine/engine';
import type { LiveSession } from '../engine/live';
import { placeFrames } from '../engine/frames';
import { stopTracks } from '../audio/capture';
import { audioNotes } from '../player/audio-notes';

export interface FinishedTake {
  animation: Animation;
  buffer: AudioBuffer;
  samples: Float32Array;
  seconds: number;
  computeMs: number;
  /** Frames of the take that hold the one before them: skipped live, and their animation cancelled (else 0). */
  heldFrames: number;
  /** What was noticed about its sound (silent: the microphone muted?, no speech, clipped), the most important first. */
  notes: string[];
}

export class Recording {
  private readonly frames: { first: number; frames: Frames }[] = [];
  private toldSlow = false;
  private finishing = false;

  private constructor(private readonly engine: TalkingFaceEngine, readonly live: LiveSession,
    /** Whether a warning was told (slowNote then stays quiet: the warning is what the status line should keep). */
    private readonly warned: () => boolean) {}

  /**
   * Open the microphone (`open`) and animate it live; `onFrames` shows each chunk, `tell` says what went wrong (the
   * live animation failed, or the microphone stopped sending sound). Where listening cannot start, the microphone is
   * let go (the browser's recording indicator goes off). `signal` cancels the start, even while the browser still
   * asks for the microphone: this rejects with its reason at once, and a microphone given after that is let go.
   */
  static async start(engine: TalkingFaceEngine, open: () => Promise<MediaStream>, onFrames: (frames: Frames) => void,
    tell: (text: string, isError: boolean) => void, signal?: AbortSignal): Promise<Recording> {
    const media = await untilCancelled(open(), signal);
    engine.resetTimes();
    let recording: Recording | null = null;
    const pending: { first: number; frames: Frames }[] = [];
    let warned = false;
    const warn = (text: string): void => {
      warned = true;
      tell(text, true);
    };
    const live = await engine.listen(media, (first, frames) => {
      if (signal?.aborted) return; // cancelled while listening started: let go below
      (recording?.frames ?? pending).push({ first, frames });
      onFrames(frames);
    }, {
      onError: (e) => warn(`Live animation stopped: ${e.message}`),
      onInterrupted: (e) => warn(`Recording, but ${e.message}. Stop recording keeps what was heard.`),
    }).catch((e: unknown) => {
      stopTracks(media);
      throw e;
    });
    if (signal?.aborted) {
      await live.stop(); // which lets the microphone go
      signal.throwIfAborted();
    }
    recording = new Recording(engine, live, () => warned);
    recording.frames.push(...pending);
    return recording;
  }

  /**
   * Once, when the device first falls behind live (frames skipped to keep up), the status line that says so; else null.
   * A visitor sees a face that moves in jumps, and is told why, not only in the details. Null after a warning (the
   * microphone stopped sending sound, say): that stays on the status line; the skipped frames are in the details.
   */
  slowNote(): string | null {
    if (this.toldSlow || this.warned() || !this.live.stream.skippedFrames) return null;
    this.toldSlow = true;
    return 'Recording: this device is slower than real time, so the face skips frames to keep up (the take is animated whole when you stop). Stop recording or Escape stops.';
  }

  /** Until finish(), every quarter second: `show` describe()'s line, and `tell` the slow note when there is one. */
  follow(show: (line: string) => void, tell: (text: string) => void): void {
    if (this.finishing) return;
    show(this.describe());
    const slow = this.slowNote();
    if (slow) tell(slow);
    setTimeout(() => this.follow(show, tell), 250);
  }

  /** One line on the live state: seconds, decoder, latency, frames skipped. */
  describe(): string {
    const lat = this.live.stream.latency;
    return `Recording ${this.live.seconds.toFixed(1)} s: the face follows your voice. Decoder ${this.engine.backend}, ` +
      `latency ${Number.isFinite(lat.p50Ms) ? Math.round(lat.p50Ms) : '…'} ms (look-ahead ${Math.round(this.live.stream.lookAheadMs)} ms)` +
      (this.live.stream.skippedFrames ? `, ${this.live.stream.skippedFrames} frames skipped to keep up` : '') + '.';
  }

  /**
   * Stop and return the take, or null when it is too short to animate (under 0.1 s). When frames were skipped live,
   * the whole take is animated again: `onReanimate` is told its progress (frames done of all), and `signal` cancels
   * that: the take is then the live frames, the skipped ones held (`heldFrames`), not lost.
   */
  async finish(onReanimate: (done: number, total: number) => void, signal?: AbortSignal): Promise<FinishedTake | null> {
    const take = await this.animation(onReanimate, signal);
    if (!take) return null;
    const speech = await this.engine.restUnlessSpeech(take.animation); // (a take with no speech: the face at rest)
    const notes = audioNotes(take.samples, take.seconds, { speech }).map((n) => n.replace('the audio is silent', 'the take is silent (is the microphone muted?)'));
    return { ...take, notes };
  }

  /** The take's frames: the live ones, or the whole take animated again (finish). */
  private async animation(onReanimate: (done: number, total: number) => void, signal?: AbortSignal): Promise<Omit<FinishedTake, 'notes'> | null> {
    this.finishing = true;
    const e = this.engine;
    const samples = await this.live.stop();
    const rate = e.manifest.audio.sample_rate;
    if (samples.length < rate / 10) return null;
    const buffer = new AudioBuffer({ length: samples.length, sampleRate: rate, numberOfChannels: 1 });
    buffer.copyToChannel(new Float32Array(samples), 0);
    const spent = () => Object.values(e.times).reduce((sum: number, ms: number) => sum + ms, 0);
    let computeMs = spent(); // the live stream's
    const total = e.frameCount(samples.length);
    const streamed = this.frames.reduce((s, c) => s + c.frames.count, 0);
    if (this.live.stream.skippedFrames === 0 && streamed === total)
      return { animation: placeFrames(this.frames, total, e.fps), buffer, samples, seconds: samples.length / rate, computeMs, heldFrames: 0 };
    // The device fell behind while live (frames were skipped to stay live): animate the take again, whole.
    let animation: Animation, heldFrames = 0;
    onReanimate(0, total);
    try {
      e.resetTimes();
      animation = await e.animate(samples, { unposed: true, signal, onProgress: onReanimate });
      computeMs = spent(); // the whole take's, once: what its speed figure is of
    } catch (err) {
      if (!signal?.aborted || streamed === 0) throw err; // (no live frame to keep)
      [animation, heldFrames] = [placeFrames(this.frames, total, e.fps), total - streamed]; // (not made before: a long take's frames are large)
    }
    return { animation, buffer, samples, seconds: samples.length / rate, computeMs, heldFrames };
  }
}

/** The microphone `opening` gives, or `signal`'s reason as soon as it aborts (a microphone given later is let go). */
function untilCancelled(opening: Promise<MediaStream>, signal?: AbortSignal): Promise<MediaStream> {
  if (!signal) return opening;
  return new Promise((resolve, reject) => {
    const abort = (): void => reject(signal.reason);
    if (signal.aborted) abort();
    else signal.addEventListener('abort', abort, { once: true });
    opening.then((media) => {
      signal.removeEventListener('abort', abort);
      if (signal.aborted) stopTracks(media);
      else resolve(media);
    }, (e: unknown) => {
      signal.removeEventListener('abort', abort);
      reject(e);
    });
  });
}
