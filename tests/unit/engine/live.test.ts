/**
 * LiveSession (src/engine/live.ts) and engine.listen() where they fail: the take's sound outlives its last frames
 * failing, and a bad option is a rejected promise (the caller's catch lets the microphone go), not a throw.
 */
import { describe, expect, it } from 'vitest';
import { LiveSession } from '../../../src/engine/live';
import { TalkingFaceEngine } from '../../../src/engine/engine';
import type { StreamSession } from '../../../src/engine/stream';

describe('LiveSession.stop', () => {
  it('returns the take\'s sound even where its last frames fail, and says why through onError', async () => {
    const stream = { sampleRate: 16000, push: () => Promise.resolve(), end: () => Promise.reject(new Error('the last batch failed')) } as unknown as StreamSession;
    const errors: string[] = [];
    const session = new (LiveSession as unknown as new (s: StreamSession, c: null, keep: boolean) => LiveSession)(stream, null, true);
    (session as unknown as { onError: (e: Error) => void }).onError = (e) => errors.push(e.message);
    const receive = (session as unknown as { receive(p: Float32Array, onError: (e: Error) => void): void }).receive.bind(session);
    receive(new Float32Array(5120).fill(0.25), (e) => errors.push(e.message));
    const take = await session.stop();
    expect(take.length).toBe(5120);
    expect(take[5119]).toBe(0.25);
    expect(errors).toEqual(['the last batch failed']);
  });
});

describe('engine.listen', () => {
  it('a head-motion scale it cannot take rejects, as a disposed engine does, instead of throwing', async () => {
    const engine = Object.create(TalkingFaceEngine.prototype) as TalkingFaceEngine;
    Object.assign(engine, { pipeline: { disposed: false } });
    const listening = engine.listen({} as MediaStream, () => undefined, { headMotionScale: -2 });
    await expect(listening).rejects.toThrow(RangeError);
  });
});
