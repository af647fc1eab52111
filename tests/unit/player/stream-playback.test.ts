/**
 * Streamed speech with the face in sync (src/player/stream-playback.ts), on a stand-in audio clock and view: each
 * piece is scheduled after the one before it, the frame shown is the one whose sound plays, a frame not computed in
 * time is counted late, a stall rests the face, end() plays out, stop() silences at once.
 */
import { beforeEach, describe, expect, it } from 'vitest';
import { Player } from '../../../src/player/player';
import { StreamPlayback, GROW_MARGIN, REST_AFTER_SECONDS } from '../../../src/player/stream-playback';
import type { Frames } from '../../../src/engine/frames';
import { drawAt, FakeContext, installAudioClock } from '../helpers/audio-clock';

const RATE = 1000; // the pieces' samples per second
const FPS = 10;

beforeEach(installAudioClock);

/** Frames first .. first + count - 1 of one vertex whose x is the frame's index; speech everywhere unless `quiet`. */
function frames(first: number, count: number, quiet = false): Frames {
  return { count, vertices: new Float32Array(count * 3), pose: new Float32Array(count * 6), phones: new Uint8Array(count),
    unposed: Float32Array.from({ length: count * 3 }, (_, i) => (i % 3 ? 0 : first + i / 3)),
    tongue: new Float32Array(count), speech: new Float32Array(count).fill(quiet ? 0 : 1) };
}

function stage() {
  const shown: number[] = [];
  const speaking: boolean[] = [];
  const view = { setVertices: (v: Float32Array) => shown.push(v[0]), setPose: () => undefined, setSpeaking: (on: boolean) => speaking.push(on) };
  return { player: new Player(view, 1), shown, speaking };
}

describe('StreamPlayback', () => {
  it('plays a span `delay` after its first piece, the pieces after it back to back, and shows the frame whose sound plays', async () => {
    const { player, shown } = stage();
    const events: [number, number][] = [];
    const p = new StreamPlayback(player, RATE, FPS, 0.3, { onFrame: (f, fr, at) => events.push([f, fr.unposed[at * 3]]) });
    expect(player.isPlaying).toBe(true);
    p.write(new Float32Array(500)); // 0.5 s, frames 0-4
    expect(FakeContext.last.sources).toHaveLength(0); // its first frame has not come
    p.frames(0, frames(0, 5));
    drawAt(0.2);
    p.write(new Float32Array(500)); // the next 0.5 s, frames 5-9: follows on
    p.write(new Float32Array(200));
    expect(FakeContext.last.sources.map((s) => s.at)).toEqual([0.3, 0.8, 1.3].map((t) => expect.closeTo(t, 9)));
    p.frames(5, frames(5, 7));
    for (const [t, f] of [[0.3, 0], [0.41, 1], [0.55, 2], [0.89, 5], [1.29, 9], [1.51, 11]]) {
      drawAt(t);
      expect(shown.at(-1), `at ${t} s`).toBe(f);
    }
    expect(events).toEqual([[0, 0], [1, 1], [2, 2], [5, 5], [9, 9], [11, 11]]);
    expect([p.lateFrames, p.pauses, p.delay]).toEqual([0, 0, 0.3]);
    p.end();
    drawAt(1.51);
    await p.done;
    expect(p.playedOut).toBe(true);
    expect(player.isPlaying).toBe(false);
  });

  it('shows the frame of the sound being heard: the clock less the output\'s latency', () => {
    const { player, shown } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.3, {});
    p.write(new Float32Array(1000));
    p.frames(0, frames(0, 10));
    const ctx = FakeContext.last as unknown as { baseLatency: number; outputLatency: number };
    [ctx.baseLatency, ctx.outputLatency] = [0.01, 0.2];
    drawAt(0.95); // rendering 0.65 s into the span, heard 0.44 s in: frame 4, not 6
    expect(shown.at(-1)).toBe(4);
    p.stop();
  });

  it('does not start the sound before the frame of its first sample has come', () => {
    const { player } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.1);
    p.write(new Float32Array(300));
    drawAt(0.5);
    expect(FakeContext.last.sources).toHaveLength(0);
    p.frames(0, frames(0, 1));
    expect(FakeContext.last.sources.map((s) => s.at)).toEqual([0.52]); // now, and the margin
  });

  it('shows the newest frame and counts it late when the sound is ahead; the next piece then waits as long as they were late', () => {
    const { player, shown } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.1);
    p.write(new Float32Array(1000));
    p.frames(0, frames(0, 3)); // at 0: scheduled at 0.1 (the delay)
    drawAt(0.1 + 0.55); // frame 5's sound; frames 0-2 computed
    expect(shown.at(-1)).toBe(2);
    expect(p.lateFrames).toBe(1);
    drawAt(0.1 + 0.65);
    expect(p.lateFrames).toBe(1); // still frame 2: not counted again
    p.frames(3, frames(3, 5)); // frame 3's sound began at 0.4: 0.35 s late
    drawAt(0.1 + 0.75);
    expect(shown.at(-1)).toBe(7);
    // At 0.85 a piece that would follow on at 1.1 waits instead for the delay the late frames needed: the span's 0.1 s,
    // the 0.35 s they were late, and GROW_MARGIN.
    p.write(new Float32Array(100));
    expect(p.delay).toBeCloseTo(0.45 + GROW_MARGIN, 9);
    p.frames(8, frames(8, 3));
    expect(FakeContext.last.sources.at(-1)!.at).toBeCloseTo(0.85 + 0.45 + GROW_MARGIN, 9);
    expect(p.pauses).toBe(1);
    drawAt(1.42);
    p.frames(11, frames(11, 1)); // on time: the delay stays, and the next piece follows on
    p.write(new Float32Array(100));
    expect([p.delay, p.pauses]).toEqual([expect.closeTo(0.45 + GROW_MARGIN, 9), 1]);
    expect(FakeContext.last.sources.at(-1)!.at).toBeCloseTo(0.85 + 0.45 + GROW_MARGIN + 0.1, 9); // right after the piece before
  });

  it('is over once its last sound is heard, not when it is rendered', async () => {
    const { player } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.3, {});
    p.write(new Float32Array(500)); // plays 0.3 .. 0.8 on the rendering clock
    p.frames(0, frames(0, 5));
    p.end();
    const ctx = FakeContext.last as unknown as { baseLatency: number; outputLatency: number };
    [ctx.baseLatency, ctx.outputLatency] = [0, 0.2];
    drawAt(0.85); // rendered, not yet heard (0.65)
    expect(p.playedOut).toBe(false);
    drawAt(1.01);
    await p.done;
    expect(p.playedOut).toBe(true);
  });

  it('keeps only the frames it may still show while nothing is drawn (a hidden tab), however long the stream', () => {
    const { player } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.3, {});
    for (let second = 0; second < 60; second++) { // a minute of speech, one piece and its frames a second, no frame drawn
      FakeContext.last.currentTime = second;
      p.write(new Float32Array(RATE));
      p.frames(second * FPS, frames(second * FPS, FPS));
    }
    const kept = (p as unknown as { chunks: unknown[] }).chunks.length;
    expect(kept).toBeLessThanOrEqual(3);
    p.stop();
  });

  it('shows the oldest frame it kept when the output\'s latency grows mid-stream (headphones switched on), and draws on', () => {
    const { player, shown } = stage();
    const events: number[] = [];
    const p = new StreamPlayback(player, RATE, FPS, 0.3, { onFrame: (f, fr, at) => events.push(fr.unposed[at * 3]) });
    for (let k = 0; k < 40; k++) { // 4 s in pieces of 0.1 s, one frame each
      p.write(new Float32Array(RATE / FPS));
      p.frames(k, frames(k, 1));
    }
    drawAt(3.3); // heard 3.0 s in: frame 30; the frames more than LIVE_REST_FRAMES before it are forgotten
    expect(shown.at(-1)).toBe(30);
    (FakeContext.last as unknown as { outputLatency: number }).outputLatency = 2; // heard now: frame 10, long forgotten
    drawAt(3.31);
    const oldest = shown.at(-1)!;
    expect(oldest).toBeGreaterThan(10);   // the oldest frame kept, not one out of its chunk
    expect(oldest).toBeLessThanOrEqual(30);
    expect(events.at(-1)).toBe(oldest);   // and what onFrame reports
    drawAt(5.52); // 3.22 s into the stream heard: the clock caught up, the face follows it
    expect(shown.at(-1)).toBe(32);
    p.stop();
  });

  it('never cuts a delay the page chose longer than the growth\'s ceiling (MAX_DELAY)', () => {
    const { player } = stage();
    const told: number[] = [];
    const p = new StreamPlayback(player, RATE, FPS, 5, { onDelay: (d) => told.push(d) });
    p.write(new Float32Array(500));
    p.frames(0, frames(0, 1)); // the sound starts at 5 s
    drawAt(5.35);
    p.frames(1, frames(1, 4)); // frames 1-4, due from 5.1 s: late
    p.write(new Float32Array(100)); // a new span: the delay would grow here
    expect(p.delay).toBe(5);
    expect(told).toEqual([]);
    p.stop();
  });

  it('does not grow the delay for frames that waited for the sound after a pause (the next sentence), only for slow ones', () => {
    const { player } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.2, { lookAhead: 0.25 });
    p.write(new Float32Array(500)); // the first sentence: plays 0.2 .. 0.7
    p.frames(0, frames(0, 3)); // frames 3 and 4 read 0.25 s past their time: they wait for the next sentence
    drawAt(1.5);
    p.write(new Float32Array(500)); // the next sentence, 0.8 s after the sound ran out
    p.frames(3, frames(3, 5)); // frames 3-4 (their sound long played) and 5-7
    p.write(new Float32Array(100));
    expect(p.delay).toBe(0.2);
    expect(FakeContext.last.sources.map((s) => s.at)).toEqual([0.2, 1.7, 2.2].map((t) => expect.closeTo(t, 9)));
    // The same frames late with their sound in time: computed slowly. That grows it.
    const slow = new StreamPlayback(stage().player, RATE, FPS, 0.2, { lookAhead: 0.25 }); // (a player of its own: its clock at 0)
    slow.write(new Float32Array(1000)); // plays 0.2 .. 1.2
    slow.frames(0, frames(0, 3));
    drawAt(0.8); // frame 6's sound
    slow.frames(3, frames(3, 5)); // frame 3's sound began at 0.5: 0.3 s late, its input in since 0
    slow.write(new Float32Array(100));
    expect(slow.delay).toBeCloseTo(0.2 + 0.3 + GROW_MARGIN, 9);
  });

  it('rests the face while the stream has run dry, and plays on with the delay when it comes back', () => {
    const { player, shown, speaking } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.2);
    p.write(new Float32Array(300));
    p.frames(0, frames(0, 3)); // plays 0.2 .. 0.5
    drawAt(0.45);
    expect([shown.at(-1), speaking.at(-1)]).toEqual([2, true]);
    drawAt(0.5 + REST_AFTER_SECONDS + 0.01); // quiet for longer than REST_AFTER_SECONDS
    expect([shown.at(-1), speaking.at(-1)]).toEqual([2, false]);
    p.write(new Float32Array(200)); // arrives at 0.76: plays at 0.96
    p.frames(3, frames(3, 2));
    expect(FakeContext.last.sources[1].at).toBeCloseTo(0.96, 9);
    expect(p.pauses).toBe(1);
    drawAt(1.07);
    expect([shown.at(-1), speaking.at(-1)]).toEqual([4, true]);
  });

  it('rests the face after frames without speech, as live', () => {
    const { player, speaking } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0);
    p.write(new Float32Array(3000));
    p.frames(0, frames(0, 2));
    p.frames(2, frames(2, 28, true));
    drawAt(0.05);
    expect(speaking.at(-1)).toBe(true);
    drawAt(1.25); // frame 12: speech 11 frames ago
    expect(speaking.at(-1)).toBe(true);
    drawAt(1.45); // frame 14: none in the last 12
    expect(speaking.at(-1)).toBe(false);
  });

  it('plays out a last piece too short for a frame of its own once ended', async () => {
    const { player } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0);
    p.write(new Float32Array(100));
    p.frames(0, frames(0, 1));
    drawAt(0.5);
    p.write(new Float32Array(5)); // frame 1 would be its frame: none will come
    p.end();
    drawAt(0.6);
    drawAt(0.7);
    await p.done;
    expect(p.playedOut).toBe(true);
  });

  it('ends without animation frames too (a background tab gets none), once its sound has played', async () => {
    const { player, shown } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0.1);
    p.write(new Float32Array(200)); // plays 0.1 .. 0.3
    p.frames(0, frames(0, 2));
    p.end();
    FakeContext.last.currentTime = 0.35; // no draw meanwhile
    await p.done;
    expect(p.playedOut).toBe(true);
    expect(shown).toEqual([1]); // the last frame, at rest
  });

  it('stops at once: every piece silenced, done resolved, and nothing scheduled after', async () => {
    const { player } = stage();
    const p = new StreamPlayback(player, RATE, FPS, 0);
    p.write(new Float32Array(500));
    p.frames(0, frames(0, 5));
    p.write(new Float32Array(500));
    player.stop(); // as the element's stop() does
    await p.done;
    expect(p.playedOut).toBe(false);
    expect(FakeContext.last.sources.map((s) => s.stopped)).toEqual([true, true]);
    p.write(new Float32Array(500));
    expect(FakeContext.last.sources).toHaveLength(2);
    expect(player.isPlaying).toBe(false);
  });
});
