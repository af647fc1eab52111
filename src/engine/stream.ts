/**
 * Streaming inference: audio pushed in pieces of any size (an AudioWorklet's 128-sample quanta, a
 * network stream), frames emitted as soon as every sample of their receptive field has arrived, so
 * the output equals the offline animation of the same audio. `lookAheadMs` is the audio a frame
 * waits for beyond its own time; processing time comes on top.
 */
import { DEFAULT_CHUNK_FRAMES, type Pipeline, type ProducerState, type StateOptions } from './pipeline';
import { yieldToEventLoop, type Frames } from './frames';
import { checkedSamples } from './checks';

export class StreamSession {
  private buffer = new Float32Array(1 << 16);
  private offset = 0; // signal index of buffer[0]
  private received = 0; // samples received so far
  private next = 0; // next frame to produce
  private ended = false;
  private cancelled = false;
  private readonly state: ProducerState;
  private busy: Promise<void> = Promise.resolve();
  /** Arrival of recent pushes: the stream's sample count after the push, and the time (ms) it came. */
  private arrivals: { end: number; time: number }[] = [];
  private pending: Promise<void> | null = null;
  private latencies: number[] = [];

  /** Frames skipped to catch up (see maxLagFrames). */
  skippedFrames = 0;

  constructor(
    private readonly pipeline: Pipeline,
    private readonly onFrames: (first: number, frames: Frames) => void,
    /**
     * Live use: when more than this many frames are ready but not yet computed (the device is slower
     * than real time), skip to the newest ones instead of falling further behind; the skipped frames
     * are never emitted (`first` jumps) and `skippedFrames` counts them. Default: never skip, so the
     * output equals the offline animation.
     */
    private readonly maxLagFrames = Infinity,
    /** `blendshapes`: the frames also carry ARKit weights, visemes and head rotations (Frames.blendshapes); `headMotionScale`. */
    options: StateOptions = {},
  ) {
    this.state = pipeline.newState(options);
  }

  get lookAheadMs(): number {
    return ((this.pipeline.samplesNeeded(0) / this.pipeline.manifest.audio.sample_rate) * 1000);
  }

  get framesProduced(): number {
    return this.next;
  }

  get sampleRate(): number {
    return this.pipeline.manifest.audio.sample_rate;
  }

  /**
   * Measured latency of the frames emitted so far (the last 300): for each frame, the time from the
   * arrival of the audio sample at the frame's own instant to the frame's emission, in ms. It holds
   * the look-ahead, the size of the pieces pushed, and processing; not the audio hardware's own input
   * latency (an AudioContext's baseLatency), which comes before the samples reach push().
   */
  get latency(): { frames: number; lastMs: number; p50Ms: number; p95Ms: number } {
    const v = [...this.latencies].sort((a, b) => a - b);
    const at = (q: number) => (v.length ? v[Math.min(v.length - 1, Math.floor(q * v.length))] : NaN);
    return { frames: this.latencies.length, lastMs: this.latencies[this.latencies.length - 1] ?? NaN, p50Ms: at(0.5), p95Ms: at(0.95) };
  }

  /** Append mono samples at the model's rate; resolves when every frame they make ready has been emitted. */
  push(samples: Float32Array): Promise<void> {
    if (this.ended) throw new Error(`StreamSession: push() after ${this.cancelled ? 'cancel' : 'end'}()`);
    this.append(checkedSamples(samples, 'StreamSession.push'));
    if (samples.length === 0) return this.pending ?? Promise.resolve(); // (nothing new: no arrival kept, no drain)
    this.arrivals.push({ end: this.received, time: performance.now() });
    // Pushes that come while a drain runs share one follow-up drain: at most one waits, however fast
    // the pieces come. Each drain first yields to the event loop, so a page stays responsive (promise
    // continuations alone would starve input, rendering and timers).
    this.pending ??= this.schedule(async () => {
      await yieldToEventLoop();
      this.pending = null;
      await this.drain(false);
    });
    return this.pending;
  }

  /**
   * Nothing more is wanted: the frames under way are not emitted, and no more are computed (a push or end() after it
   * throws, as after end()).
   */
  cancel(): void {
    this.ended = this.cancelled = true;
  }

  /** No more audio: emit the remaining frames (the end of the clip is zero-padded, as offline). */
  end(): Promise<void> {
    if (this.cancelled) throw new Error('StreamSession: end() after cancel()');
    this.ended = true;
    return this.schedule(() => this.drain(true));
  }

  private schedule(job: () => Promise<void>): Promise<void> {
    const run = this.busy.then(job);
    // Deliberate: the caller receives the run's error through `run`; `busy` only orders the runs.
    this.busy = run.catch(() => undefined); // the caller gets the error through `run`; `busy` only orders runs
    return run;
  }

  private append(samples: Float32Array): void {
    const used = this.received - this.offset;
    if (used + samples.length > this.buffer.length) {
      const bigger = new Float32Array(Math.max(2 * this.buffer.length, used + samples.length));
      bigger.set(this.buffer.subarray(0, used));
      this.buffer = bigger;
    }
    this.buffer.set(samples, used);
    this.received += samples.length;
  }

  private async drain(final: boolean): Promise<void> {
    const e = this.pipeline;
    const total = final ? this.received : Infinity;
    const last = final ? e.frameCount(this.received) : Infinity;
    let f1 = this.next;
    while (f1 < last && (final || e.samplesNeeded(f1) <= this.received)) f1++;
    if (!final && f1 - this.next > this.maxLagFrames) {
      const resume = f1 - Math.max(1, Math.floor(this.maxLagFrames / 4));
      this.skippedFrames += resume - this.next;
      this.next = resume;
    }
    for (let f0 = this.next; f0 < f1 && !this.cancelled; f0 += DEFAULT_CHUNK_FRAMES) {
      const to = Math.min(f1, f0 + DEFAULT_CHUNK_FRAMES);
      const view = this.buffer.subarray(0, this.received - this.offset);
      const out = await e.produce(this.state, f0, to, view, this.offset, total);
      if (this.cancelled) return;
      this.next = to;
      if (!final) this.measure(f0, to);
      this.onFrames(f0, out);
    }
    this.trim();
  }

  /** Record frames [f0, f1)'s latency: now minus the moment the sample at each frame's instant arrived. */
  private measure(f0: number, f1: number): void {
    const now = performance.now();
    const rate = this.pipeline.manifest.audio.sample_rate;
    for (let f = f0; f < f1; f++) {
      const sample = Math.round((f / this.pipeline.fps) * rate);
      while (this.arrivals.length > 1 && this.arrivals[0].end <= sample) this.arrivals.shift();
      const a = this.arrivals[0];
      if (!a || a.end <= sample) continue;
      // Pieces arrive when their last sample has been captured: the frame's sample came (end - sample) samples earlier.
      const captured = a.time - ((a.end - sample) / rate) * 1000;
      this.latencies.push(now - captured);
    }
    if (this.latencies.length > 300) this.latencies.splice(0, this.latencies.length - 300);
  }

  /** Forget audio no future frame can read: its content window's first frame, less the encoder's look-back. */
  private trim(): void {
    const keepFrom = this.pipeline.samplesBehind(this.next);
    if (keepFrom - this.offset > this.buffer.length / 2) {
      const drop = keepFrom - this.offset;
      this.buffer.copyWithin(0, drop, this.received - this.offset);
      this.offset = keepFrom;
    }
  }
}
