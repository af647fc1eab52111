/** The voice-activity check (src/encoders/voice-activity.ts): per-frame speech probability and the per-clip decision. */
import { describe, expect, it } from 'vitest';
import { levelAt, melFlatness, speechFound, speechProbabilities, NOISE_FLATNESS, SPEECH_LEVEL } from '../../../src/encoders/voice-activity';

describe('voice activity', () => {
  it('measures the level around a sample, within the samples held', () => {
    const x = new Float32Array(1000).fill(0.5);
    expect(levelAt(x, 0, 500, 100)).toBeCloseTo(0.5, 6);
    expect(levelAt(x, 2000, 500, 100)).toBe(0); // outside what is held
  });

  it('takes 1 - P(silence), and nothing where the signal is too quiet or as flat as noise', () => {
    const post = Float32Array.from([0.1, 0.9, 0.8, 0.2]); // two content frames, classes [phone, SIL]
    const p = speechProbabilities(post, 2, 1, [0, 1, 1, 1], [0.1, 0.1, SPEECH_LEVEL / 2, 0.1], [0, 0, 0, 2 * NOISE_FLATNESS]);
    expect(Array.from(p, (v) => Number(v.toFixed(2)))).toEqual([0.1, 0.8, 0, 0]);
  });

  it('measures spectral flatness per FFT bin: 1 for energy spread evenly, near 0 for one band', () => {
    const widths = Float64Array.from([0, 2, 4, 8]); // an empty first filter is skipped
    const even = Float32Array.from([5, Math.log1p(2), Math.log1p(4), Math.log1p(8)]);
    expect(melFlatness(even, widths)).toBeCloseTo(1, 6);
    const peaked = Float32Array.from([0, Math.log1p(1e4), 0, 0]);
    expect(melFlatness(peaked, widths)).toBeLessThan(0.01);
  });

  it('finds speech in varied phones, not in silence or one steady sound', () => {
    const fps = 30;
    const varied = Uint8Array.from({ length: 60 }, (_, f) => Math.floor(f / 4) % 8);
    const steady = new Uint8Array(60).fill(3);
    const speaking = new Float32Array(60).fill(0.9);
    expect(speechFound(speaking, varied, fps)).toBe(true);
    expect(speechFound(speaking, steady, fps)).toBe(false); // a tone: one "phone" throughout
    expect(speechFound(new Float32Array(60).fill(0.1), varied, fps)).toBe(false); // silence or noise
    expect(speechFound(speaking.map((v, f) => (f < 3 ? v : 0)), varied, fps)).toBe(false); // 0.1 s of it
  });
});
