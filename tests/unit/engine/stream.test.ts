/**
 * StreamSession (src/engine/stream.ts) against a stand-in pipeline that records what it is asked for: frames are
 * emitted exactly when their receptive field has arrived, in order, each once; end() flushes the rest; a slow
 * device skips to the newest frames only when a lag limit is set. (The real pipeline's streaming = offline
 * equality is tested in the browser: tests/e2e/live.spec.ts.)
 */
import { describe, expect, it } from 'vitest';
import { StreamSession } from '../../../src/engine/stream';
import { joinFrames, type Frames } from '../../../src/engine/frames';
import type { Pipeline } from '../../../src/engine/pipeline';

const RATE = 1000; // samples per second of the stand-in
const FPS = 10;
const LOOK_AHEAD = 250; // samples a frame waits for beyond its own instant

/** A pipeline whose frame f needs samples up to f * 100 + 250, and whose frames carry their own index. */
function standIn(calls: [number, number, number][]): Pipeline {
  return {
    manifest: { audio: { sample_rate: RATE } },
    fps: FPS,
    newState: () => ({}),
    frameCount: (samples: number) => Math.max(1, Math.round((samples / RATE) * FPS)),
    samplesNeeded: (f: number) => f * (RATE / FPS) + LOOK_AHEAD,
    samplesBehind: () => 0,
    produce: async (_state: unknown, f0: number, f1: number, samples: Float32Array, offset: number, total: number): Promise<Frames> => {
      calls.push([f0, f1, Number.isFinite(total) ? total : -1]);
      expect(offset + samples.length).toBeGreaterThanOrEqual(Number.isFinite(total) ? total : (f1 - 1) * (RATE / FPS) + LOOK_AHEAD);
      const count = f1 - f0;
      return { count, vertices: Float32Array.from({ length: count }, (_, i) => f0 + i), unposed: new Float32Array(count), pose: new Float32Array(count * 6), phones: new Uint8Array(count), tongue: new Float32Array(count), speech: new Float32Array(count) };
    },
  } as unknown as Pipeline;
}

describe('StreamSession', () => {
  it('emits each frame once, in order, as soon as its samples have arrived; end() emits the rest', async () => {
    const calls: [number, number, number][] = [];
    const got: Frames[] = [];
    const stream = new StreamSession(standIn(calls), (_first, frames) => got.push(frames));
    await stream.push(new Float32Array(300)); // frame 0 needs 250 samples: ready; frame 1 needs 350
    expect(stream.framesProduced).toBe(1);
    await stream.push(new Float32Array(149)); // 449 samples: frames 1 (350) ready, 2 (450) not yet
    expect(stream.framesProduced).toBe(2);
    for (let i = 0; i < 10; i++) await stream.push(new Float32Array(55)); // pieces of any size
    await stream.end();
    const all = joinFrames(got, FPS);
    expect(all.frames).toBe(Math.round((999 / RATE) * FPS));
    expect(Array.from(all.vertices)).toEqual(Array.from({ length: all.frames }, (_, i) => i));
    expect(calls[calls.length - 1][2]).toBe(999); // the last run knows the clip's end
    expect(() => stream.push(new Float32Array(1))).toThrow(/after end/);
  });

  it('cancel() stops the work under way: no frame of it is emitted, and nothing more is taken', async () => {
    const calls: [number, number, number][] = [];
    const got: number[] = [];
    const stream = new StreamSession(standIn(calls), (first) => got.push(first));
    await stream.push(new Float32Array(300));
    expect(got).toEqual([0]);
    const pushed = stream.push(new Float32Array(5000)); // 50 frames ready: computed in chunks
    stream.cancel();
    await pushed;
    expect(got).toEqual([0]);
    expect(calls.length).toBeLessThanOrEqual(2); // at most the chunk under way
    expect(() => stream.push(new Float32Array(1))).toThrow(/push\(\) after cancel\(\)/);
    expect(() => stream.end()).toThrow(/end\(\) after cancel\(\)/);
  });

  it('with a lag limit, a device that falls behind skips to the newest frames and counts what it skipped', async () => {
    const calls: [number, number, number][] = [];
    const firsts: number[] = [];
    const stream = new StreamSession(standIn(calls), (first) => firsts.push(first), 4);
    await stream.push(new Float32Array(3000)); // 28 frames ready at once, more than 4
    expect(stream.skippedFrames).toBeGreaterThan(0);
    expect(firsts[0]).toBe(stream.skippedFrames);
    expect(stream.framesProduced).toBe(28);
  });

  it('empty pushes keep nothing and start no drain: a page that pushes whatever arrives does not grow the session', async () => {
    const calls: [number, number, number][] = [];
    const stream = new StreamSession(standIn(calls), () => undefined);
    for (let i = 0; i < 1000; i++) await stream.push(new Float32Array(0));
    expect((stream as unknown as { arrivals: unknown[] }).arrivals.length).toBe(0);
    await stream.push(new Float32Array(600));
    await stream.end();
    expect(stream.framesProduced).toBe(6);
  });
});
