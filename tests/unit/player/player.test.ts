/**
 * The shared player (src/player/player.ts) on a stand-in face view and audio clock: which frame it shows, where
 * the pose goes, the shape mapping, play / stop / end / loop.
 */
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { Player } from '../../../src/player/player';
import type { FaceView } from '../../../src/render/face-view';
import { emptyBlendshapes, type Animation } from '../../../src/engine/frames';
import type { BlendshapeFrames } from '../../../src/avatar/weights';

/** A face view that records what it was given. */
function fakeView() {
  const shown: { vertices: number[]; pose: number[] }[] = [];
  const speaking: boolean[] = [];
  let last: number[] = [];
  const view = {
    setVertices: (v: Float32Array) => (last = Array.from(v)),
    setPose: (...p: number[]) => shown.push({ vertices: last, pose: p }),
    setTongue: () => undefined,
    setSpeaking: (on: boolean) => speaking.push(on),
  } as unknown as FaceView;
  return { view, shown, speaking };
}

/** Two vertices, `frames` frames: vertex values f, poses f (rotation) and 10 f (mm). */
function animation(frames: number): Animation {
  return {
    fps: 10, frames,
    vertices: new Float32Array(frames * 6),
    unposed: Float32Array.from({ length: frames * 6 }, (_, i) => Math.floor(i / 6)),
    pose: Float32Array.from({ length: frames * 6 }, (_, i) => (i % 6 < 3 ? Math.floor(i / 6) : 10 * Math.floor(i / 6))),
    phones: new Uint8Array(frames),
    tongue: new Float32Array(frames),
    speech: new Float32Array(frames),
  };
}

/** An AudioContext whose clock the test moves, and requestAnimationFrame driven by the test. */
class FakeContext extends EventTarget {
  static last: FakeContext;
  currentTime = 0;
  destination = {};
  sources: { onended: (() => void) | null; started: number[]; stopped: boolean; to: unknown[] }[] = [];
  gains: { gain: { value: number }; to: unknown[] }[] = [];
  constructor() {
    super();
    FakeContext.last = this;
  }
  resume() { return Promise.resolve(); }
  close() { return Promise.resolve(); }
  createGain() {
    const g = { gain: { value: 1 }, to: [] as unknown[], connect(n: unknown) { g.to.push(n); } };
    this.gains.push(g);
    return g;
  }
  createBufferSource() {
    const s = { buffer: null, onended: null as (() => void) | null, started: [] as number[], stopped: false, to: [] as unknown[],
      connect(n: unknown) { s.to.push(n); }, start(...a: number[]) { s.started = a; }, stop() { s.stopped = true; } };
    this.sources.push(s);
    return s;
  }
}
/** A player of `frames` frames, playing: the frames it showed, its ended count, and play()'s promise. */
function playing(frames: number) {
  const { view } = fakeView();
  const seen: number[] = [];
  const ended = { count: 0 };
  const p = new Player(view, 1, { onFrame: (f) => seen.push(f), onEnded: () => ended.count++ });
  p.load(animation(frames), {} as AudioBuffer);
  return { p, seen, ended, done: p.play() };
}

let frameCallbacks: (() => void)[] = [];
const tick = () => {
  const cbs = frameCallbacks;
  frameCallbacks = [];
  for (const cb of cbs) cb();
};

beforeEach(() => {
  Object.assign(globalThis, { AudioContext: FakeContext, requestAnimationFrame: (cb: () => void) => frameCallbacks.push(cb), cancelAnimationFrame: () => undefined });
});
afterEach(() => {
  frameCallbacks = [];
});

describe('Player', () => {
  it('shows a frame (clamped) with its pose, translations in the template units', () => {
    const { view, shown } = fakeView();
    const seen: number[] = [];
    const p = new Player(view, 0.1, { onFrame: (f) => seen.push(f) });
    p.load(animation(5), {} as AudioBuffer);
    p.show(3);
    p.show(99);
    expect(seen).toEqual([3, 4]);
    expect(shown[0]).toEqual({ vertices: [3, 3, 3, 3, 3, 3], pose: [3, 3, 3, 3, 3, 3] }); // 30 mm x 0.1 units per mm
    expect(p.current).toBe(4);
  });

  it("hands a view that draws blend shapes (an avatar) the frame's weights, offline and live", () => {
    const got: [number, number][] = [];
    const view = { setVertices: () => undefined, setPose: () => undefined,
      setBlendshapes: (b: BlendshapeFrames, f: number) => got.push([f, b.arkit[f * 52]]) };
    const a = animation(4);
    a.blendshapes = emptyBlendshapes(4);
    a.blendshapes.arkit.set([0.5], 2 * 52);
    const p = new Player(view, 1);
    p.load(a, {} as AudioBuffer);
    p.show(2);
    expect(got).toEqual([[2, 0.5]]);
    p.showLive({ count: 3, vertices: new Float32Array(18), unposed: new Float32Array(18), pose: new Float32Array(18), phones: new Uint8Array(3), tongue: new Float32Array(3), speech: new Float32Array(3), blendshapes: a.blendshapes }, 10);
    const now = vi.spyOn(performance, 'now').mockReturnValue(performance.now() + 1000);
    tick();
    now.mockRestore();
    expect(got[1]).toEqual([2, 0.5]); // all three due: the last shown
    p.load(animation(4), {} as AudioBuffer); // a take without blend shapes: nothing to hand over
    p.show(1);
    expect(got).toHaveLength(2);
  });

  it('plays a batch of live frames out one by one at the frame rate, drops a backlog, and stop() clears it', () => {
    const { view, shown } = fakeView();
    const p = new Player(view, 1);
    const live = (from: number, count: number) => {
      const a = animation(from + count);
      const n = count * 6;
      return { count, vertices: a.vertices.slice(from * 6, from * 6 + n), unposed: a.unposed!.slice(from * 6, from * 6 + n),
        pose: a.pose.slice(from * 6, from * 6 + n), phones: a.phones.slice(from, from + count), tongue: a.tongue.slice(from, from + count),
        speech: a.speech.slice(from, from + count) };
    };
    let t = 1000;
    const now = vi.spyOn(performance, 'now').mockImplementation(() => t);
    const at = (ms: number) => {
      t = 1000 + ms;
      tick();
      return shown.at(-1)?.vertices[0];
    };
    // 10 fps: frames 80 ms apart (a little under 100, so a backlog drains).
    p.showLive(live(0, 3), 10);
    expect([at(0), at(50), at(90), at(170), at(500)]).toEqual([0, 0, 1, 2, 2]);
    expect(shown).toHaveLength(3);
    // Twenty at once: only the last ones within 250 ms of now are kept, the first of them shown at once.
    p.showLive(live(3, 20), 10);
    expect([at(500), at(580), at(660), at(740), at(2000)]).toEqual([19, 20, 21, 22, 22]);
    p.showLive(live(23, 3), 10);
    p.stop();
    expect(at(3000)).toBe(22); // nothing more shown
    now.mockRestore();
  });

  it('draws through the shape mapping when given one', () => {
    const { view, shown } = fakeView();
    const p = new Player(view, 1);
    p.load(animation(3), {} as AudioBuffer, (f, u) => Float32Array.from(u, (v) => v + 100 * f));
    p.show(2);
    expect(shown[0].vertices).toEqual([202, 202, 202, 202, 202, 202]);
  });

  it('plays in sync with the audio clock, stops, and reports the natural end', async () => {
    const { p, seen, done, ended } = playing(20);
    const ctx = FakeContext.last;
    expect(p.isPlaying).toBe(true);
    ctx.currentTime = 0.05 + 0.75; // 0.75 s after the scheduled start: frame 7
    tick();
    expect(seen[seen.length - 1]).toBe(7);
    ctx.sources[0].onended!();
    await done;
    expect(ended.count).toBe(1);
    expect(seen[seen.length - 1]).toBe(19); // the last frame is left on screen
    expect(p.isPlaying).toBe(false);
    // Play again from frame 5; stop() resolves it without an end.
    const again = p.play(5);
    expect(ctx.sources[1].started).toEqual([ctx.currentTime + 0.05, 0.5]);
    p.stop();
    await again;
    expect(ctx.sources[1].stopped).toBe(true);
    expect(ended.count).toBe(1);
  });

  it('shows the frame of the sound being heard: the clock less the output\'s latency (Bluetooth headphones: 0.2 s)', () => {
    const { p, seen } = playing(20);
    const ctx = FakeContext.last as FakeContext & { baseLatency: number; outputLatency: number };
    [ctx.baseLatency, ctx.outputLatency] = [0.01, 0.2];
    ctx.currentTime = 0.05 + 0.75; // rendered 0.75 s in, heard 0.54 s in: frame 5, not 7
    tick();
    expect(seen[seen.length - 1]).toBe(5);
    // Recorded (the sound tapped as it is rendered, into the video): the frame of what goes into the recording.
    const track = { stopped: false, stop() { this.stopped = true; } };
    Object.assign(ctx, { createMediaStreamDestination: () => ({ stream: { getTracks: () => [track] }, disconnect: () => undefined }) });
    p.tap();
    ctx.currentTime = 0.05 + 0.85;
    tick();
    expect(seen[seen.length - 1]).toBe(8);
    p.untap();
    expect(track.stopped, 'the recording\'s track is stopped with it').toBe(true);
    p.stop();
  });

  it('ends once its last sound is heard, not when it is rendered: the last frames are shown until then', async () => {
    vi.useFakeTimers({ toFake: ['setTimeout', 'clearTimeout'] }); // (the animation frames stay the test's)
    const { p, seen, done, ended } = playing(20);
    const ctx = FakeContext.last as FakeContext & { baseLatency: number; outputLatency: number };
    [ctx.baseLatency, ctx.outputLatency] = [0, 0.2];
    ctx.currentTime = 0.05 + 2; // all 2 s rendered, 1.8 s heard
    ctx.sources[0].onended!();
    tick();
    expect([seen.at(-1), ended.count, p.isPlaying]).toEqual([18, 0, true]);
    ctx.currentTime += 0.2;
    await vi.advanceTimersByTimeAsync(200);
    await done;
    expect([seen.at(-1), ended.count, p.isPlaying]).toEqual([19, 1, false]);
    vi.useRealTimers();
  });

  it('once disposed, refuses to play or be recorded (no new audio context for a face that is gone)', async () => {
    const { view } = fakeView();
    const p = new Player(view, 1);
    p.load(animation(4), {} as AudioBuffer);
    p.dispose();
    const made = FakeContext.last;
    await expect(p.play()).rejects.toThrow(/the face it played on is gone/);
    expect(() => p.tap()).toThrow(/the face it played on is gone/);
    expect(FakeContext.last).toBe(made);
  });

  it('loops when asked', async () => {
    const { view } = fakeView();
    let ended = 0;
    const p = new Player(view, 1, { onEnded: () => ended++ });
    p.loop = true;
    p.load(animation(4), {} as AudioBuffer);
    void p.play();
    const ctx = FakeContext.last;
    ctx.sources[0].onended!();
    expect(ctx.sources.length).toBe(2); // started again from the start
    expect(ctx.sources[1].started[1]).toBe(0);
    expect(ended).toBe(0);
    p.stop();
  });

  it('plays at its volume: one gain between every sound and the speakers, set before and while it plays', async () => {
    const { view } = fakeView();
    const p = new Player(view, 1);
    p.volume = 0.25; // before any sound: kept
    p.load(animation(4), {} as AudioBuffer);
    void p.play();
    const ctx = FakeContext.last;
    expect(ctx.gains).toHaveLength(1);
    expect(ctx.gains[0].gain.value).toBe(0.25);
    expect(ctx.gains[0].to).toEqual([ctx.destination]);
    expect(ctx.sources[0].to, 'the sound goes to the gain only').toEqual([ctx.gains[0]]);
    p.volume = 0; // while it plays: at once
    expect(ctx.gains[0].gain.value).toBe(0);
    void p.play(0);
    expect(ctx.gains, 'one gain for every sound').toHaveLength(1);
    expect(ctx.sources[1].to).toEqual([ctx.gains[0]]);
    expect(p.volume).toBe(0);
    p.dispose();
  });

  it('refuses an animation without unposed frames', () => {
    const a = animation(2);
    delete a.unposed;
    expect(() => new Player(fakeView().view, 1).load(a, {} as AudioBuffer)).toThrow(/unposed/);
  });
});
