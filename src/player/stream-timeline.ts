/**
 * When each piece of streamed speech plays, on the audio clock, and which of its samples plays at a given moment.
 * The sound is a row of spans: within a span the pieces play back to back; a new span begins where the stream ran
 * dry (a stall on the network, a pause between sentences) or where the player chose to wait (player/stream-playback.ts).
 */
export interface TimelineSpan {
  /** Clock time (s) at which `sample` plays. */
  time: number;
  /** The first stream sample of the span, and the one after its last. */
  sample: number;
  end: number;
}

/**
 * The clock time of the sound being heard now: `currentTime` is that of the next block the context renders, which
 * reaches the ear its base latency and the output's latency later (a few tens of ms wired, 0.15-0.3 s on Bluetooth
 * headphones): frames chosen by it would move the mouth before its sound. (outputLatency is not known everywhere,
 * Safari: 0 there.)
 */
export function heardTime(context: BaseAudioContext): number {
  const c = context as AudioContext;
  return c.currentTime - (c.baseLatency || 0) - (c.outputLatency || 0);
}

/** How close to now a piece may be scheduled and still play whole (s). */
export const SCHEDULE_MARGIN = 0.02;

export class StreamTimeline {
  private spans: TimelineSpan[] = [];
  private written = 0;

  /** `rate`: the pieces' sample rate. */
  constructor(readonly rate: number) {}

  /** When a piece placed now would play, right after the last one; null if that is too soon (or nothing plays yet). */
  follows(now: number): number | null {
    const end = this.endTime;
    return end >= now + SCHEDULE_MARGIN ? end : null;
  }

  /** The next `length` samples play from clock time `start` (the end of the last span, or later: a new span). */
  place(length: number, start: number): void {
    const last = this.spans.at(-1);
    const time = Math.max(start, this.endTime);
    if (last && time - this.endTime < 1e-9) last.end += length;
    else this.spans.push({ time, sample: this.written, end: this.written + length });
    this.written += length;
  }

  /** Samples placed so far. */
  get samples(): number {
    return this.written;
  }

  /** When the last sample placed has played (-Infinity before any). */
  get endTime(): number {
    const last = this.spans.at(-1);
    return last ? last.time + (last.end - last.sample) / this.rate : -Infinity;
  }

  /** The clock time at which stream sample `sample` plays (null: not placed yet). */
  timeOf(sample: number): number | null {
    for (let k = this.spans.length - 1; k >= 0; k--) {
      const s = this.spans[k];
      if (sample >= s.sample && sample < s.end) return s.time + (sample - s.sample) / this.rate;
    }
    return null;
  }

  /**
   * What plays at clock `time`: the sample (fractional), or in a gap between spans the last sample played and how long
   * the gap has lasted; null before the first span starts.
   */
  at(time: number): { sample: number; quietFor: number } | null {
    let k = this.spans.length - 1;
    while (k >= 0 && this.spans[k].time > time) k--;
    if (k < 0) return null;
    const s = this.spans[k];
    const sample = s.sample + (time - s.time) * this.rate;
    if (sample < s.end) return { sample, quietFor: 0 };
    return { sample: s.end - 1, quietFor: time - (s.time + (s.end - s.sample) / this.rate) };
  }

  /** Forget spans that ended before clock `time` (all but the last). */
  forget(time: number): void {
    while (this.spans.length > 1 && this.spans[1].time <= time) this.spans.shift();
  }
}
