/**
 * speakStream(engine, options) for a page's own scene (src/player/page-stream.ts), on a stand-in engine and audio
 * clock: the sound goes to the page's context and destination, each frame to its show() in order as its sound plays,
 * back to rest (speaking false) at the end and on stop(); its options are checked; a show() that throws is the
 * page's error and the playback goes on.
 */
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { speakStream } from '../../../src/player/page-stream';
import { AUTOPLAY_WAIT_MS } from '../../../src/player/autoplay';
import type { Frames } from '../../../src/engine/frames';
import { drawAt, FakeContext, installAudioClock } from '../helpers/audio-clock';
import { FPS, RATE, standIn, streamOptions } from '../helpers/stream-engine';

class FakeNode {
  constructor(readonly context: unknown) {}
}
const connected: unknown[] = [];

beforeEach(() => {
  installAudioClock();
  Object.assign(globalThis, { AudioNode: FakeNode });
  connected.length = 0;
  streamOptions.length = 0;
});
afterEach(() => vi.restoreAllMocks());

/** A context of the page's: its sources' connect() recorded in `connected`. */
function pageContext(): { context: AudioContext; destination: AudioNode } {
  const context = new FakeContext();
  const make = context.createBufferSource.bind(context);
  context.createBufferSource = () => Object.assign(make(), { connect: (n: unknown) => connected.push(n) });
  return { context: context as unknown as AudioContext, destination: new FakeNode(context) as unknown as AudioNode };
}
const tick = () => new Promise((r) => setTimeout(r, 5));

describe('speakStream(engine, options)', () => {
  it("plays on the page's context and destination, showing each frame as its sound plays, then rests", async () => {
    const shown: [number, boolean][] = [];
    const { context, destination } = pageContext();
    const show = (frames: Frames, f: number, speaking: boolean) => shown.push([frames.unposed[f * 3], speaking]);
    const speech = speakStream(standIn({ samples: 0, produced: 0 }), { sampleRate: RATE, context, destination, show });
    for (let i = 0; i < 10; i++) speech.write(new Float32Array(RATE / 10).fill(0.1)); // 1 s
    speech.end();
    for (let t = 0; t < 3 && speech.open; t += 0.02) {
      await tick();
      drawAt(t);
    }
    await speech.done;
    expect(streamOptions).toEqual([{ blendshapes: true, headMotionScale: undefined }]); // what an avatar needs
    expect(connected.length).toBeGreaterThan(0);
    expect(connected.every((n) => n === destination)).toBe(true);
    const frames = shown.map(([f]) => f);
    expect(frames.every((f, i) => i === 0 || f >= frames[i - 1])).toBe(true); // in order
    expect(frames[0]).toBeLessThanOrEqual(1);
    expect(shown.at(-1)).toEqual([FPS - 1, false]); // the last frame, at rest
    expect(shown.slice(0, -1).every(([, speaking]) => speaking)).toBe(true);
    expect(speech.take!.animation.frames).toBe(FPS);
  });

  it('stop() stops the sound at once, shows the face at rest from where it was, and resolves done', async () => {
    const shown: [number, boolean][] = [];
    const { context, destination } = pageContext();
    const speech = speakStream(standIn({ samples: 0, produced: 0 }), { sampleRate: RATE, context, destination,
      show: (frames, f, speaking) => shown.push([frames.unposed[f * 3], speaking]) });
    speech.write(new Float32Array(2 * RATE));
    for (let t = 0; t < 1; t += 0.02) {
      await tick();
      drawAt(t);
    }
    const before = shown.length;
    expect(before).toBeGreaterThan(5);
    speech.stop();
    await speech.done;
    expect(shown.length).toBe(before + 1);
    expect(shown.at(-1)).toEqual([shown[before - 1][0], false]);
    expect(FakeContext.last.sources.every((s) => s.stopped)).toBe(true);
    expect([speech.open, speech.write(new Float32Array(10))]).toEqual([false, false]);
  });

  it("says what is wrong with its options; a show() that throws is the page's error, and the playback goes on", async () => {
    const engine = standIn({ samples: 0, produced: 0 });
    const show = () => undefined;
    expect(() => speakStream({} as never, { sampleRate: RATE, show })).toThrow(/the first argument must be a TalkingFaceEngine/);
    expect(() => speakStream(engine, { sampleRate: RATE } as never)).toThrow(/options.show must be a function/);
    expect(() => speakStream(engine, { sampleRate: RATE, show, context: {} as AudioContext })).toThrow(/options.context must be an AudioContext/);
    const other = pageContext();
    const closed = Object.assign(pageContext().context, { state: 'closed' });
    const { context } = pageContext(); // (the clock drawAt moves: the last made)
    expect(() => speakStream(engine, { sampleRate: RATE, show, context, destination: other.destination })).toThrow(/destination must be an AudioNode of options.context/);
    expect(() => speakStream(engine, { sampleRate: 5, show })).toThrow(/sampleRate must be/);
    expect(() => speakStream(engine, { sampleRate: RATE, show, headMotionScale: 5 })).toThrow(RangeError); // at once: before, a stream that never started
    expect(() => speakStream(engine, { sampleRate: RATE, show, context: closed })).toThrow(/options.context is closed/);
    const reported: unknown[] = [];
    vi.stubGlobal('reportError', (e: unknown) => reported.push(e));
    let calls = 0;
    const speech = speakStream(engine, { sampleRate: RATE, context, show: () => {
      calls++;
      throw new Error('the page broke');
    } });
    speech.write(new Float32Array(RATE / 2));
    speech.end();
    for (let t = 0; t < 2 && speech.open; t += 0.02) {
      await tick();
      drawAt(t);
    }
    await speech.done;
    expect(calls).toBeGreaterThan(3);
    expect(reported.length).toBe(calls);
    expect(speech.take).not.toBeNull();
  });

  it('a context the browser holds back plays from the next click: onBlocked says so, and nothing is shown until then', async () => {
    vi.stubGlobal('document', new EventTarget());
    FakeContext.heldBack = true;
    const { context, destination } = pageContext();
    const shown: boolean[] = [];
    const onBlocked = vi.fn();
    const speech = speakStream(standIn({ samples: 0, produced: 0 }), { sampleRate: RATE, context, destination, onBlocked,
      show: (_frames, _f, speaking) => shown.push(speaking) });
    speech.write(new Float32Array(RATE / 2));
    speech.end();
    await new Promise((r) => setTimeout(r, AUTOPLAY_WAIT_MS + 50));
    expect(onBlocked).toHaveBeenCalledTimes(1);
    expect([context.state, shown.length, speech.open]).toEqual(['suspended', 0, true]);
    const resumes = FakeContext.last.resumes;
    document.dispatchEvent(new Event('pointerdown')); // the next click: resumed, by the stream
    expect(FakeContext.last.resumes).toBe(resumes + 1);
    FakeContext.last.allow(); // (the browser lets it run)
    for (let t = 0; t < 2 && speech.open; t += 0.02) {
      await tick();
      drawAt(t);
    }
    await speech.done;
    expect(shown.length).toBeGreaterThan(5);
    vi.unstubAllGlobals();
  });

  it('a context closed while the speech plays fails the stream: done rejects, the face rests, nothing waits', async () => {
    const { context, destination } = pageContext();
    const shown: boolean[] = [];
    const speech = speakStream(standIn({ samples: 0, produced: 0 }), { sampleRate: RATE, context, destination,
      show: (_frames, _f, speaking) => shown.push(speaking) });
    speech.write(new Float32Array(2 * RATE));
    for (let t = 0; t < 1; t += 0.02) {
      await tick();
      drawAt(t);
    }
    expect(shown.length).toBeGreaterThan(5);
    void context.close();
    await expect(speech.done).rejects.toThrow('speakStream: its audio context was closed: nothing more can play on it');
    expect(shown.at(-1)).toBe(false);
    expect(speech.open).toBe(false);
    // Closed before its first piece (the stream made while it was open): refused as soon as a piece comes.
    const late = pageContext();
    const again = speakStream(standIn({ samples: 0, produced: 0 }), { sampleRate: RATE, ...late, show: () => undefined });
    void late.context.close();
    expect(again.write(new Float32Array(RATE))).toBe(true); // (taken: the stream starts with the engine)
    await expect(again.done).rejects.toThrow(/audio context was closed/);
  });
});
