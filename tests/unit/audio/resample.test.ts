/** The streaming resampler (src/audio/resample.ts): behind live capture when the AudioContext cannot run at the model's rate, behind speakStream(), and (resampleAll) behind decodeAudio(). */
import { describe, expect, it } from 'vitest';
import { StreamResampler, resampleAll } from '../../../src/audio/resample';

const tone = (hz: number, rate: number, n: number) => Float32Array.from({ length: n }, (_, i) => Math.sin((2 * Math.PI * hz * i) / rate));

function pushAll(r: StreamResampler, x: Float32Array, pieces: number[]): Float32Array {
  const out: number[] = [];
  for (let i = 0, k = 0; i < x.length; k++) {
    const size = pieces[k % pieces.length];
    out.push(...r.push(x.subarray(i, i + size)));
    i += size;
  }
  return Float32Array.from(out);
}

describe('StreamResampler', () => {
  for (const from of [48000, 44100, 8000]) {
    it(`${from} Hz -> 16 kHz keeps a 440 Hz tone in place and in level`, () => {
      const x = tone(440, from, from); // one second
      const y = pushAll(new StreamResampler(from, 16000), x, [128]);
      expect(y.length).toBeGreaterThan(15000);
      let err = 0;
      for (let n = 200; n < y.length - 200; n++) err = Math.max(err, Math.abs(y[n] - Math.sin((2 * Math.PI * 440 * n) / 16000)));
      expect(err).toBeLessThan(0.01);
    });
  }

  it('removes what the lower rate cannot carry (12 kHz at 48 kHz -> 16 kHz)', () => {
    const y = pushAll(new StreamResampler(48000, 16000), tone(12000, 48000, 48000), [128]);
    const rms = Math.sqrt(y.slice(200, -200).reduce((s, v) => s + v * v, 0) / (y.length - 400));
    expect(rms).toBeLessThan(0.01); // an alias at 4 kHz would be 0.7
  });

  it('gives the same samples whatever the piece sizes', () => {
    const x = tone(300, 44100, 30000).map((v, i) => v + 0.3 * Math.sin(i * 0.37));
    const a = pushAll(new StreamResampler(44100, 16000), x, [30000]);
    const b = pushAll(new StreamResampler(44100, 16000), x, [128, 7, 1000, 333]);
    expect(b.length).toBe(a.length);
    let d = 0;
    for (let i = 0; i < a.length; i++) d = Math.max(d, Math.abs(a[i] - b[i]));
    expect(d).toBeLessThan(1e-6);
  });

  it('gives the same samples from its table of weights as with weights computed for each output (and an odd rate the latter way)', () => {
    const x = tone(300, 44100, 30000).map((v, i) => v + 0.3 * Math.sin(i * 0.37));
    const a = pushAll(new StreamResampler(44100, 16000), x, [1000]);
    const b = pushAll(new StreamResampler(44100, 16000, 16, 0), x, [1000]);
    expect(b.length).toBe(a.length);
    let d = 0;
    for (let i = 0; i < a.length; i++) d = Math.max(d, Math.abs(a[i] - b[i]));
    expect(d).toBeLessThan(1e-6);
    const odd = pushAll(new StreamResampler(22051, 16000), tone(440, 22051, 22051), [500]); // 16,000 fractions: none kept
    let err = 0;
    for (let n = 200; n < odd.length - 200; n++) err = Math.max(err, Math.abs(odd[n] - Math.sin((2 * Math.PI * 440 * n) / 16000)));
    expect(err).toBeLessThan(0.01);
  });

  it('passes the stream through at equal rates', () => {
    const x = tone(300, 16000, 1000);
    expect(Array.from(new StreamResampler(16000, 16000).push(x))).toEqual(Array.from(x));
  });
});

describe('resampleAll', () => {
  it('is the stream resampler\'s output, its tail included, length * to / from samples in step with the input', async () => {
    const x = tone(300, 44100, 3 * 44100 + 77).map((v, i) => v + 0.3 * Math.sin(i * 0.37));
    const all = await resampleAll(x, 44100, 16000);
    expect(all.length).toBe(Math.round((x.length * 16000) / 44100));
    const r = new StreamResampler(44100, 16000);
    const streamed = Float32Array.from([...pushAll(r, x, [1000]), ...r.push(new Float32Array(200))]).subarray(0, all.length);
    expect(Math.max(...all.map((v, i) => Math.abs(v - streamed[i])))).toBeLessThan(1e-6);
    // The last samples are the input's, brought out by the tail (not zeros): a 440 Hz tone is in place to the end.
    const t = await resampleAll(tone(440, 48000, 48000), 48000, 16000);
    expect(t.length).toBe(16000);
    for (const n of [0, 15990, 15995]) expect(t[n]).toBeCloseTo(Math.sin((2 * Math.PI * 440 * n) / 16000), 1);
    expect(Math.abs(t[15999])).toBeGreaterThan(0); // (not cut short)
  });

  it('stops at its signal between slices of a long clip', async () => {
    const stop = new AbortController();
    const long = tone(440, 48000, 48000 * 120); // two minutes: several slices
    const made = resampleAll(long, 48000, 16000, stop.signal);
    stop.abort(new Error('cancelled'));
    await expect(made).rejects.toThrow('cancelled');
  });
});
