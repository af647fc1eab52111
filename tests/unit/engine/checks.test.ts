import { describe, expect, it } from 'vitest';
import { checkedBackend, checkedChunk, checkedFrame, checkedLayer, checkedSamples, checkedSeed, checkedWorkers } from '../../../src/engine/checks';

describe('the engine\'s argument checks', () => {
  it('samples: a Float32Array of finite audio, else an error that names what is wrong', () => {
    const ok = new Float32Array([0, 0.5, -1, 32767]);
    expect(checkedSamples(ok, 'animate')).toBe(ok);
    expect(() => checkedSamples([0, 1], 'animate')).toThrow(TypeError);
    expect(() => checkedSamples(null, 'animate')).toThrow(/not null/);
    expect(() => checkedSamples(new Float64Array(4), 'animate')).toThrow(/not Float64Array/);
    class AudioBuffer {}
    expect(() => checkedSamples(new AudioBuffer(), 'animate')).toThrow(/not AudioBuffer \(decodeAudio\(\) gives both/);
    expect(() => checkedSamples(new Float32Array([0, NaN]), 'animate')).toThrow(/sample 1 is NaN/);
    expect(() => checkedSamples(new Float32Array([Infinity]), 'StreamSession.push')).toThrow(/StreamSession.push: sample 0 is Infinity/);
    expect(() => checkedSamples(new Float32Array([0, 0, 1e20]), 'animate')).toThrow(RangeError);
  });

  it('chunk sizes are whole numbers (below 1 means 1); frames finite; backends by name', () => {
    expect(checkedChunk(96)).toBe(96);
    expect(checkedChunk(0)).toBe(1);
    expect(checkedChunk(-5)).toBe(1);
    for (const bad of [2.5, NaN, 96.2]) expect(() => checkedChunk(bad)).toThrow(/whole number/);
    expect(checkedFrame(3.7, 10)).toBe(3);
    expect(checkedFrame(99, 10)).toBe(9);
    expect(() => checkedFrame(NaN, 10)).toThrow(/frame number from 0 to 9/);
    expect(checkedBackend('auto')).toBe('auto');
    expect(checkedBackend('webgpu')).toBe('webgpu');
    expect(() => checkedBackend('gpu')).toThrow(/'auto', 'cpu' or 'webgpu', not "gpu"/);
    expect(() => checkedBackend(undefined)).toThrow(RangeError);
  });

  it('decoder workers: 0 to 64 whole (NaN would decode nothing, Infinity start workers forever); layers counted from 0', () => {
    for (const ok of [0, 1, 4, 64]) expect(checkedWorkers(ok)).toBe(ok);
    for (const bad of [NaN, Infinity, -1, 2.5, 65, '4']) expect(() => checkedWorkers(bad)).toThrow(/cpuWorkers must be a whole number from 0 to 64/);
    expect(checkedLayer(0, 3)).toBe(0);
    expect(checkedLayer(2, 3)).toBe(2);
    for (const bad of [3, -1, 1.5, NaN, '2']) expect(() => checkedLayer(bad, 3)).toThrow(/layer must be a whole number from 0 to 2 \(the decoder's layers count from 0\)/);
  });
});

describe('the head motion\'s seed', () => {
  it('is an integer JavaScript holds exactly (beyond 2^53 the browser and Python would draw different motion), or null', () => {
    for (const ok of [0, -7, 2 ** 32 + 5, Number.MAX_SAFE_INTEGER, null]) expect(checkedSeed(ok)).toBe(ok);
    for (const bad of [2 ** 60, -(2 ** 53), 1.5, NaN, '3', undefined]) expect(() => checkedSeed(bad)).toThrow(/headMotionSeed must be an integer from/);
  });
});

describe('TalkingFaceEngine.load\'s failure', () => {
  it('a load refused at once (a stallSeconds that is no positive number) still settles sessionsRequested: nothing more is asked', async () => {
    const { TalkingFaceEngine } = await import('../../../src/engine/engine');
    await expect(TalkingFaceEngine.load({ stallSeconds: -1 })).rejects.toThrow(/stallSeconds must be a positive number/);
    const waited = await Promise.race([TalkingFaceEngine.sessionsRequested.then(() => 'settled'), new Promise((r) => setTimeout(() => r('waiting for ever'), 50))]);
    expect(waited).toBe('settled');
  });
});
