/**
 * speakStream()'s stream (src/player/speech-stream.ts) on a stand-in engine, player and audio clock: its options
 * checked before anything stops, `done` rejected on a failure, a bad piece refused before it is played or animated,
 * the delay read from the first piece, stop() cancelling the engine's work, and the take handed over once played.
 */
import { beforeEach, describe, expect, it } from 'vitest';
import { SpeechStream, STREAM_MARGIN_SECONDS, FIRST_PIECE_SECONDS } from '../../../src/player/speech-stream';
import { checkedStreamOptions, type StreamHost, type StreamTake } from '../../../src/player/stream-options';
import type { TalkingFaceEngine } from '../../../src/engine/engine';
import { Player } from '../../../src/player/player';
import { drawAt, FakeContext, installAudioClock } from '../helpers/audio-clock';
import { FPS, LOOK_AHEAD, RATE, standIn } from '../helpers/stream-engine';

beforeEach(installAudioClock);

function host(engine: Promise<TalkingFaceEngine | null>) {
  const controller = new AbortController();
  const events: string[] = [];
  const taken: StreamTake[] = [];
  const player = new Player({ setVertices() {}, setPose() {} }, 1);
  const h: StreamHost = {
    signal: controller.signal, engine, output: async () => player, streamOptions: () => ({}), current: () => !controller.signal.aborted,
    status: (t) => events.push(`status:${t}`), playing: (d) => events.push(`playing:${d}`),
    fail: (stage, m) => (events.push(`error:${stage}`), new Error(m)), frame: () => events.push('frame'),
    played: (take) => {
      if (take) taken.push(take);
      events.push('ended'); // as the element's
    },
    halt: () => { // as the element's: `ended` if it was playing
      const playing = player.isPlaying;
      player.stop();
      if (playing) events.push('ended');
    },
  };
  return { h, controller, events, taken };
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
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), failing.h);
    s.write(new Float32Array(RATE));
    expect(await settled(s.done)).toBe('rejected: the streamed speech could not be animated: boom');
    expect(failing.events.filter((e) => !e.startsWith('playing:'))).toEqual(['error:inference', 'ended']); // the sound had begun: it ends
    expect(s.write(new Float32Array(10))).toBe(false);
    const noModel = host(Promise.reject(new Error('no model')));
    const t = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), noModel.h);
    expect(await settled(t.done)).toBe('rejected: no model');
  });

  it('rejects done where the engine refuses to stream at all (a throw as it starts), the pieces written before it waiting', async () => {
    const engine = standIn({ samples: 0, produced: 0 });
    engine.createStream = () => {
      throw new Error('the engine was disposed');
    };
    const refused = host(Promise.resolve(engine));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), refused.h);
    s.write(new Float32Array(RATE)); // before the engine is there: it waits
    expect(await settled(s.done)).toBe('rejected: the streamed speech could not be animated: the engine was disposed');
    expect(refused.events).toEqual(['error:inference']);
    expect([s.open, s.write(new Float32Array(10))]).toEqual([false, false]);
  });

  it('refuses a bad piece before it is played or animated, and goes on', async () => {
    const pushed = { samples: 0, produced: 0 };
    const { h } = host(Promise.resolve(standIn(pushed)));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), h);
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
      const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), h);
      await tick(); // the model is there before the first piece
      s.write(new Float32Array(seconds * RATE));
      expect(s.delayMs, `${seconds} s`).toBeCloseTo(1000 * (LOOK_AHEAD / RATE + counted + STREAM_MARGIN_SECONDS), 6);
    }
    const { h } = host(Promise.resolve(standIn({ samples: 0, produced: 0 })));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE, delayMs: 800 }), h);
    s.write(new Float32Array(RATE));
    await tick();
    expect(s.delayMs).toBe(800);
  });

  it('once stopped, the engine stops too: the frames under way are not computed further', async () => {
    const pushed = { samples: 0, produced: 0 };
    const { h, controller, events } = host(Promise.resolve(standIn(pushed)));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: RATE }), h);
    await tick();
    s.write(new Float32Array(20 * RATE)); // 500 frames, computed in chunks
    controller.abort(); // the element's stop()
    expect(await settled(s.done)).toBe('resolved');
    await tick();
    expect(pushed.produced).toBeLessThan(100);
    expect(events.filter((e) => e === 'ended')).toEqual([]); // the element sends `ended` for a stop
  });

  it('hands over the take once it has played: its frames, its sound at its own rate; ended once', async () => {
    const { h, events, taken } = host(Promise.resolve(standIn({ samples: 0, produced: 0 })));
    const s = new SpeechStream(checkedStreamOptions({ sampleRate: 24000 }), h);
    await tick();
    for (let i = 0; i < 10; i++) s.write(new Int16Array(2400).fill(1000)); // 1 s in 0.1 s pieces
    s.end();
    for (let t = 0; t < 3 && taken.length === 0; t += 0.05) {
      await tick();
      drawAt(t);
    }
    expect(await settled(s.done)).toBe('resolved');
    const take = taken[0];
    expect(taken).toEqual([s.take]);
    expect(take.animation.frames).toBe(FPS);
    expect(Array.from(take.animation.unposed!.filter((_, i) => i % 3 === 0))).toEqual(Array.from({ length: FPS }, (_, f) => f));
    expect([take.buffer.length, take.buffer.duration]).toEqual([24000, 1]);
    expect(events.filter((e) => e === 'ended')).toEqual(['ended']);
    expect(events.at(-2)).toBe('status:Played streamed speech (1.0 s).');
  });
});
