/** When streamed pieces play (src/player/stream-timeline.ts): spans of pieces back to back, and what plays when. */
import { describe, expect, it } from 'vitest';
import { SCHEDULE_MARGIN, StreamTimeline } from '../../../src/player/stream-timeline';

describe('StreamTimeline', () => {
  it('joins a piece placed at the end of the last into its span, and says which sample plays when', () => {
    const t = new StreamTimeline(1000);
    expect(t.follows(0)).toBeNull(); // nothing plays yet
    expect(t.at(5)).toBeNull();
    t.place(100, 10.3); // 0.1 s at 1 kHz
    expect(t.follows(10.01)).toBeCloseTo(10.4, 9);
    t.place(100, t.follows(10.01)!);
    t.place(500, t.follows(10.2)!);
    expect(t.endTime).toBeCloseTo(11.0, 9);
    expect(t.samples).toBe(700);
    expect(t.at(10.29)).toBeNull(); // not started
    expect(t.at(10.35)!.sample).toBeCloseTo(50, 6);
    expect(t.at(10.75)).toEqual({ sample: expect.closeTo(450, 6), quietFor: 0 });
    expect(t.timeOf(450)).toBeCloseTo(10.75, 9);
    expect(t.timeOf(700)).toBeNull(); // not placed
    expect(t.follows(11.0 - SCHEDULE_MARGIN / 2)).toBeNull(); // too late to follow on
  });

  it('starts a new span after a gap, and says what played last and for how long it has been quiet', () => {
    const t = new StreamTimeline(1000);
    t.place(100, 0.3); // 0.3 .. 0.4
    t.place(100, 0.69); // a gap of 0.29 s
    const gap = t.at(0.5)!;
    expect(gap.sample).toBe(99);
    expect(gap.quietFor).toBeCloseTo(0.1, 9);
    expect(t.at(0.72)!.sample).toBeCloseTo(130, 6);
    expect(t.timeOf(150)).toBeCloseTo(0.74, 9);
    t.place(10, 0.5); // never before the end of the last span
    expect(t.timeOf(200)).toBeCloseTo(0.79, 9);
    t.forget(0.75); // the first span is over
    expect(t.at(0.72)!.sample).toBeCloseTo(130, 6);
    expect(t.at(0.35)).toBeNull();
    t.forget(5);
    expect(t.at(5)).toEqual({ sample: 209, quietFor: expect.closeTo(5 - 0.8, 9) }); // the last span is kept
  });
});
