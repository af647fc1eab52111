/**
 * speakStream()'s stream (src/component/speech-stream.ts) on a stand-in engine, player and audio clock: its options
 * checked before anything stops, `done` rejected on a failure, a bad piece refused before it is played or animated,
 * the delay read from the first piece, stop() cancelling the engine's work, and the take handed over once played.
 */
import { beforeEach, describe, expect, it } from 'vitest';
import { checkedStreamOptions, SpeechStream, STREAM_MARGIN_SECONDS, FIRST_PIECE_SECONDS } from '../../../src/component/speech-stream';
import type { WorkHost } from '../../../src/component/work-host';
import type { TalkingFaceEngine } from '../../../src/engine/engine';
import type { Animation, Frames } from '../../../src/engine/frames';
import type { Pipeline } from '../../../src/engine/pipeline';
import { StreamSession } from '../../../src/engine/stream';
import { Player } from '../../../src/player/player';
import { drawAt, FakeContext, installAudioClock } from '../helpers/audio-clock';

const RATE = 16000;
const FPS = 25;
const LOOK_AHEAD = 1600; // samples: 0.1 s

beforeEach(installAudioClock);

/** A stand-in engine whose frames carry their index; `pushed` counts the samples its streams received. */
function standIn(pushed: { samples: number; produced: number }, fail = false): TalkingFaceEngine {
  const pipeline = {
    manifest: { audio: { sample_rate: RATE } }, fps: FPS, newState: () => ({}), samplesBehind: () => 0,
    frameCount: (n: number) => Math.max(1, Math.round((n / RATE) * FPS)),
    samplesNeeded: (f: number) => (f * RATE) / FPS + LOOK_AHEAD,
    produce: async (_s: unknown, f0: number, f1: number): Promise<Frames> => {
      if (fail) throw new Error('boom');
      pushed.produced += f1 - f0;
      const count = f1 - f0;
      return { count, vertices: new Float32Array(count * 3), unposed: Float32Array.from({ length: count * 3 }, (_, i) => f0 + Math.floor(i / 3)),
        pose: new Float32Array(count * 6), tongue: new Float32Array(count), speech: new Float32Array(count).fill(1), phones: new Uint8Array(count) };
    },
  } as unknown as Pipeline;
  return {
    manifest: pipeline.manifest, fps: FPS, backend: 'cpu',
    createStream: (onFrames: (first: number, frames: Frames) => void) => {
      const s = new StreamSession(pipeline, onFrames);
      const push = s.push.bind(s);
      s.push = (x: Float32Array) => ((pushed.samples += x.length), push(x));
      return s;
    },
  } as unknown as TalkingFaceEngine;
}

function host(engine: Promise<TalkingFaceEngine | null>) {
  const controller = new AbortController();
  const events: string[] = [];
  const player = new Player({ setVertices() {}, setPose() {} }, 1);
  const h: WorkHost = {
    signal: controller.signal, element: { hasAttribute: () => false, getAttribute: () => null } as unknown as Element, engine,
    player: () => player, settled: async () => player, current: () => !controller.signal.aborted,
    status: (t) => events.push(`status:${t}`), playing: (t) => events.push(`playing:${t}`),
    fail: (stage, m) => (events.push(`error:${stage}`), new Error(m)), dispatch: (e) => events.push(e.type),
    halt: () => { // as the element's: `ended` if it was playing
      const playing = player.isPlaying;
      player.stop();
      if (playing) events.push('ended');
    },
  };
  return { h, controller, events };
}
const settled = (p: Promise<unknown>) => Promise.race([p.then(() => 'resolved', (e: Error) => `rejected: ${e.message}`),
  new Promise((r) => setTimeout(() => r('pending'), 200))]);
const tick = () => new Promise((r) => setTimeout(r, 5));

describe('checkedStreamOptions', () => {
  it('says what is wrong with the options, before anything is stopped', () => {
    expect(checkedStreamOptions({ sampleRate: 24000 })).toEqual({ sampleRate: 24000, media: null, delayMs: undefined });
    expect(() => checkedStreamOptions({} as never)).toThrow(/sampleRate must be the stream's rate in Hz/);
    expect(() => checkedStreamOptions(undefined as never)).toThrow(/sampleRate must be/);
    expect(() => checkedStreamOptions({ sampleRate: 24000, delayMs: -1 })).toThrow(/delayMs must be from 0 to 10000 ms; it was -1/);
    expect(() => checkedStreamOptions({ media: {} as MediaStream })).toThrow(/media must be a MediaStream/);
  });
});

describe('SpeechStream', () => {
  it('rejects done, and reports, when the engine fails; and when the model cannot be loaded', async () => {
    const failing = host(Promise.resolve(standIn({ samples: 0, produced: 0 }, true)));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), failing.h, () => undefined);
    s.write(new Float32Array(RATE));
    expect(await settled(s.done)).toBe('rejected: the streamed speech could not be animated: boom');
    expect(failing.events.filter((e) => !e.startsWith('playing:'))).toEqual(['error:inference', 'ended']); // the sound had begun: it ends
    expect(s.write(new Float32Array(10))).toBe(false);
    const noModel = host(Promise.reject(new Error('no model')));
    const t = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), noModel.h, () => undefined);
    expect(await settled(t.done)).toBe('rejected: no model');
  });

  it('refuses a bad piece before it is played or animated, and goes on', async () => {
    const pushed = { samples: 0, produced: 0 };
    const { h } = host(Promise.resolve(standIn(pushed)));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), h, () => undefined);
    await tick();
    expect(() => s.write(Float32Array.of(0, 1e13))).toThrow(/sample 1 of the piece is 9999999827968; samples must be finite numbers/);
    expect(() => s.write('text' as never)).toThrow(TypeError);
    expect([s.seconds, pushed.samples, FakeContext.last?.sources.length ?? 0]).toEqual([0, 0, 0]);
    expect(s.write(new Float32Array(1600))).toBe(true);
    expect(pushed.samples).toBe(1600);
  });

  it("waits the look-ahead, the first piece (at most FIRST_PIECE_SECONDS) and the margin, the piece coming after the model", async () => {
    for (const [seconds, counted] of [[0.04, 0.04], [0.2, 0.2], [1, FIRST_PIECE_SECONDS]]) {
      const { h } = host(Promise.resolve(standIn({ samples: 0, produced: 0 })));
      const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), h, () => undefined);
      await tick(); // the model is there before the first piece
      s.write(new Float32Array(seconds * RATE));
      expect(s.delayMs, `${seconds} s`).toBeCloseTo(1000 * (LOOK_AHEAD / RATE + counted + STREAM_MARGIN_SECONDS), 6);
    }
    const { h } = host(Promise.resolve(standIn({ samples: 0, produced: 0 })));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE, delayMs: 800 }), h, () => undefined);
    s.write(new Float32Array(RATE));
    await tick();
    expect(s.delayMs).toBe(800);
  });

  it('once stopped, the engine stops too: the frames under way are not computed further', async () => {
    const pushed = { samples: 0, produced: 0 };
    const { h, controller, events } = host(Promise.resolve(standIn(pushed)));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), h, () => undefined);
    await tick();
    s.write(new Float32Array(20 * RATE)); // 500 frames, computed in chunks
    controller.abort(); // the element's stop()
    expect(await settled(s.done)).toBe('resolved');
    await tick();
    expect(pushed.produced).toBeLessThan(100);
    expect(events.filter((e) => e === 'ended')).toEqual([]); // the element sends `ended` for a stop
  });

  it('hands over the take once it has played: its frames, its sound at its own rate; ended once', async () => {
    const { h, events } = host(Promise.resolve(standIn({ samples: 0, produced: 0 })));
    let take: { animation: Animation; buffer: AudioBuffer } | null = null;
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: 24000 }), h, (animation, buffer) => (take = { animation, buffer }));
    await tick();
    for (let i = 0; i < 10; i++) s.write(new Int16Array(2400).fill(1000)); // 1 s in 0.1 s pieces
    s.end();
    for (let t = 0; t < 3 && !take; t += 0.05) {
      await tick();
      drawAt(t);
    }
    expect(await settled(s.done)).toBe('resolved');
    expect(take!.animation.frames).toBe(FPS);
    expect(Array.from(take!.animation.unposed!.filter((_, i) => i % 3 === 0))).toEqual(Array.from({ length: FPS }, (_, f) => f));
    expect([take!.buffer.length, take!.buffer.duration]).toEqual([24000, 1]);
    expect(events.filter((e) => e === 'ended')).toEqual(['ended']);
    expect(events.at(-2)).toBe('status:Played streamed speech (1.0 s).');
  });
});
