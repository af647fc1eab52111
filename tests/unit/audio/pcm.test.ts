/** Streamed speech's pieces as samples (src/audio/pcm.ts): floats, 16-bit integers, and bytes split anywhere. */
import { describe, expect, it } from 'vitest';
import { checkedStreamRate, PcmReader } from '../../../src/audio/pcm';

describe('PcmReader', () => {
  it('copies float samples, and scales 16-bit integers to -1..1', () => {
    const r = new PcmReader('write');
    const given = Float32Array.of(0.5, -0.25);
    const read = r.read(given);
    expect(Array.from(read)).toEqual([0.5, -0.25]);
    given[0] = 0;
    expect(read[0]).toBe(0.5); // a copy: the page may reuse its buffer
    expect(Array.from(r.read(Int16Array.of(16384, -32768, 32767)))).toEqual([0.5, -1, 32767 / 32768]);
  });

  it('reads bytes from a SharedArrayBuffer too (a cross-origin isolated page\'s worker may hand one over)', () => {
    const shared = new SharedArrayBuffer(4);
    new Int16Array(shared).set([16384, -16384]);
    expect(Array.from(new PcmReader('write').read(shared))).toEqual([0.5, -0.5]);
  });

  it('reads 16-bit little-endian bytes, a sample split between two pieces included, from any view', () => {
    const samples = Int16Array.of(1000, -2, 32767, -32768, 0, 12345);
    const bytes = new Uint8Array(samples.buffer);
    const whole = Array.from(new PcmReader('write').read(bytes.slice().buffer));
    expect(whole).toEqual(Array.from(samples, (v) => v / 32768));
    for (const cuts of [[1], [3, 4], [1, 2, 3, 5, 7, 11], [0, 12]]) {
      const r = new PcmReader('write');
      const got: number[] = [];
      let from = 0;
      for (const to of [...cuts, bytes.length]) {
        got.push(...r.read(new DataView(bytes.buffer, from, to - from)));
        from = to;
      }
      expect(got, `cut at ${cuts}`).toEqual(whole);
      expect(r.pending).toBe(false);
    }
    const r = new PcmReader('write');
    r.read(bytes.subarray(0, 3));
    expect(r.pending).toBe(true); // a stream that ended here is one byte short
  });

  it('says what it takes when given something else, and refuses samples that are not finite', () => {
    const r = new PcmReader('SpeechStream.write');
    expect(() => r.read('UklGRg==')).toThrow(/SpeechStream\.write takes a Float32Array .* given a string \(base64 text\? decode it to bytes first\)/);
    expect(() => r.read(new Blob([new Uint8Array(4)]))).toThrow(/given a Blob \(a WebSocket's message: set socket\.binaryType = 'arraybuffer' first\)$/);
    expect(() => r.read([0.1, 0.2])).toThrow(/given an Array$/);
    expect(() => r.read(Int32Array.of(1))).toThrow(/given an Int32Array$/);
    expect(() => r.read(Float64Array.of(0.1))).toThrow(/given a Float64Array/);
    expect(() => r.read(undefined)).toThrow(/given undefined/);
    expect(() => r.read(Float32Array.of(0, NaN))).toThrow(/sample 1 of the piece is NaN/);
  });
});

describe('checkedStreamRate', () => {
  it('takes whole rates an AudioBuffer holds and says what a rate must be otherwise', () => {
    for (const rate of [8000, 16000, 22050, 24000, 44100, 48000, 96000]) expect(checkedStreamRate(rate, 'speakStream')).toBe(rate);
    expect(() => checkedStreamRate('24000', 'speakStream')).toThrow(/it was a string \("24000": give a number\)$/);
    for (const rate of [undefined, '24000', 0, 7999, 24000.5, 192000, NaN]) {
      expect(() => checkedStreamRate(rate, 'speakStream'), String(rate)).toThrow(/speakStream: sampleRate must be the stream's rate in Hz, a whole number from 8000 to 96000/);
    }
  });
});
