/**
 * joinFrames (src/engine/frames.ts): streamed chunks become one animation, every array in order; placeFrames: chunks
 * with gaps between them (frames skipped live) placed at their frames, each gap holding the frame before it.
 */
import { describe, expect, it } from 'vitest';
import { emptyBlendshapes, joinFrames, placeFrames, slicer, yieldToEventLoop, type Frames } from '../../../src/engine/frames';

const chunk = (first: number, count: number, n: number): Frames => ({
  count,
  vertices: Float32Array.from({ length: count * n * 3 }, (_, i) => first * n * 3 + i),
  unposed: Float32Array.from({ length: count * n * 3 }, (_, i) => -(first * n * 3 + i)),
  pose: Float32Array.from({ length: count * 6 }, (_, i) => first * 6 + i),
  phones: Uint8Array.from({ length: count }, (_, i) => first + i),
  tongue: Float32Array.from({ length: count }, (_, i) => (first + i) / 10),
  speech: Float32Array.from({ length: count }, (_, i) => (first + i) / 100),
});

describe('placeFrames', () => {
  it('places chunks at their frames and holds the frame before each gap', () => {
    // Frames 0-2 and 6-7 streamed, 3-5 skipped, 8-9 not reached; the chunks out of order.
    const a = placeFrames([{ first: 6, frames: chunk(6, 2, 1) }, { first: 0, frames: chunk(0, 3, 1) }], 10, 30);
    expect(a.frames).toBe(10);
    expect(Array.from(a.phones)).toEqual([0, 1, 2, 2, 2, 2, 6, 7, 7, 7]);
    expect(Array.from(a.vertices.subarray(3 * 3, 4 * 3))).toEqual([6, 7, 8]); // frame 3 holds frame 2
    expect(Array.from(a.unposed!.subarray(6 * 3, 7 * 3))).toEqual([-18, -19, -20]);
    expect(Array.from(a.pose.subarray(9 * 6, 10 * 6))).toEqual([42, 43, 44, 45, 46, 47]); // frame 9 holds frame 7
    // Consecutive chunks from 0: the same as joinFrames.
    const chunks = [chunk(0, 3, 2), chunk(3, 4, 2)];
    expect(placeFrames(chunks.map((frames, i) => ({ first: i * 3, frames })), 7, 30)).toEqual(joinFrames(chunks, 30));
  });
});

describe('joinFrames', () => {
  it('concatenates chunks of any size', () => {
    const a = joinFrames([chunk(0, 3, 2), chunk(3, 1, 2), chunk(4, 5, 2)], 30);
    expect(a.frames).toBe(9);
    expect(a.fps).toBe(30);
    expect(Array.from(a.vertices)).toEqual(Array.from({ length: 9 * 6 }, (_, i) => i));
    expect(Array.from(a.unposed!)).toEqual(Array.from({ length: 9 * 6 }, (_, i) => -i));
    expect(Array.from(a.pose)).toEqual(Array.from({ length: 9 * 6 }, (_, i) => i));
    expect(Array.from(a.phones)).toEqual([0, 1, 2, 3, 4, 5, 6, 7, 8]);
    expect(Array.from(a.tongue)).toEqual(Array.from({ length: 9 }, (_, i) => Math.fround(i / 10)));
    expect(Array.from(a.speech, (p) => Math.round(p * 100))).toEqual([0, 1, 2, 3, 4, 5, 6, 7, 8]);
  });

  it('joins the blend-shape output too, when every chunk carries it', () => {
    const withWeights = (first: number, count: number): Frames => {
      const c = chunk(first, count, 2);
      const b = emptyBlendshapes(count);
      for (let f = 0; f < count; f++) { b.arkit[f * 52] = first + f; b.visemes[f * 15] = first + f; b.headRotation[f * 3] = first + f; }
      return { ...c, blendshapes: b };
    };
    const a = joinFrames([withWeights(0, 2), withWeights(2, 3)], 30);
    expect(Array.from({ length: 5 }, (_, f) => a.blendshapes!.arkit[f * 52])).toEqual([0, 1, 2, 3, 4]);
    expect(Array.from({ length: 5 }, (_, f) => a.blendshapes!.visemes[f * 15])).toEqual([0, 1, 2, 3, 4]);
    expect(Array.from({ length: 5 }, (_, f) => a.blendshapes!.headRotation[f * 3])).toEqual([0, 1, 2, 3, 4]);
    expect(joinFrames([withWeights(0, 2), chunk(2, 3, 2)], 30).blendshapes).toBeUndefined();
  });

  it('no chunks make an empty animation', () => {
    expect(joinFrames([], 30).frames).toBe(0);
  });

  it('yieldToEventLoop resolves after timers already due (a new task, not a microtask)', async () => {
    const order: string[] = [];
    setTimeout(() => order.push('timer'), 0);
    await new Promise((r) => setTimeout(r, 5));
    const p = yieldToEventLoop().then(() => order.push('yield'));
    void Promise.resolve().then(() => order.push('microtask'));
    await p;
    expect(order).toEqual(['timer', 'microtask', 'yield']);
  });

  it('slicer: long work yields between slices, says how far it is, and stops when aborted', async () => {
    const spin = (ms: number) => { const end = performance.now() + ms; while (performance.now() < end); };
    const seen: number[] = [];
    let timerRan = false;
    setTimeout(() => (timerRan = true), 0);
    const step = slicer(20, { onProgress: (d) => seen.push(d) }, 10);
    for (let i = 0; i < 20; i++) {
      spin(4);
      await step();
    }
    expect(timerRan, 'a timer due during the work ran before it ended').toBe(true);
    expect(seen.length).toBeGreaterThanOrEqual(4);
    expect(seen.every((d, i) => d > 0 && d <= 1 && (i === 0 || d > seen[i - 1]))).toBe(true);
    // Aborted meanwhile: the next yield throws the signal's reason.
    const controller = new AbortController();
    const stopping = slicer(100, { signal: controller.signal }, 1);
    let units = 0;
    const work = (async () => {
      for (; units < 100; units++) {
        spin(2);
        await stopping();
      }
    })();
    setTimeout(() => controller.abort(new Error('cancelled by the visitor')), 0);
    await expect(work).rejects.toThrow('cancelled by the visitor');
    expect(units).toBeLessThan(100);
  });
});
