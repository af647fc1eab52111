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

  /** A WAV header (fmt with `tag`, `channels`, `rate`, `bits`; a LIST chunk before it) and then `samples` 16-bit samples. */
  const wavStream = (samples: number[], { tag = 1, channels = 1, rate = 24000, bits = 16 } = {}) => {
    const head = new DataView(new ArrayBuffer(12 + 8 + 6 + 8 + 16 + 8));
    const put = (at: number, text: string) => [...text].forEach((c, i) => head.setUint8(at + i, c.charCodeAt(0)));
    put(0, 'RIFF'); head.setUint32(4, 0xffffffff, true); put(8, 'WAVE'); // (a stream's size: not known)
    put(12, 'LIST'); head.setUint32(16, 5, true); // odd: padded to 6
    put(26, 'fmt '); head.setUint32(30, 16, true);
    head.setUint16(34, tag, true); head.setUint16(36, channels, true); head.setUint32(38, rate, true); head.setUint16(48, bits, true);
    put(50, 'data'); head.setUint32(54, 0xffffffff, true);
    const out = new Uint8Array(head.byteLength + 2 * samples.length);
    out.set(new Uint8Array(head.buffer));
    samples.forEach((v, i) => new DataView(out.buffer).setInt16(head.byteLength + 2 * i, v, true));
    return out;
  };

  it('skips a WAV header at the stream\'s start (as some services send their PCM), in one piece or split, not playing it', () => {
    const bytes = wavStream([16384, -16384, 8192]);
    expect(Array.from(new PcmReader('write', 24000).read(bytes))).toEqual([0.5, -0.5, 0.25]);
    for (const cut of [3, 11, 30, 55, 59]) { // within "RIFF", before "WAVE", inside fmt, inside the data chunk's header, inside the first sample
      const r = new PcmReader('write', 24000);
      const got = [...r.read(bytes.subarray(0, cut)), ...r.read(bytes.subarray(cut))];
      expect(got, `split at ${cut}`).toEqual([0.5, -0.5, 0.25]);
    }
    const raw = Uint8Array.of(0x00, 0x40, 0x52, 0x49); // raw PCM (even one whose later bytes spell "RI")
    expect(Array.from(new PcmReader('write').read(raw))).toEqual([0.5, 0x4952 / 32768]);
    const r = new PcmReader('write');
    r.read(Uint8Array.of(0x00, 0x40));
    expect(Array.from(r.read(wavStream([16384]).subarray(0, 12))).length, 'only the start of a stream is a header').toBe(6);
  });

  it('refuses a WAV header that is not mono 16-bit PCM at the stream\'s rate, saying what it is', () => {
    expect(() => new PcmReader('write', 16000).read(wavStream([1]))).toThrow(/write: the stream is a WAV file \(mono, 16-bit PCM, 24000 Hz\); it takes mono 16-bit PCM at the stream's sampleRate \(16000 Hz\)/);
    expect(() => new PcmReader('write', 24000).read(wavStream([1], { channels: 2 }))).toThrow(/\(2 channels, 16-bit PCM, 24000 Hz\)/);
    expect(() => new PcmReader('write', 24000).read(wavStream([1], { tag: 3, bits: 32 }))).toThrow(/\(mono, 32-bit float, 24000 Hz\)/);
    const r = new PcmReader('write', 16000);
    expect(() => r.read(wavStream([1]))).toThrow(RangeError);
    expect(() => r.read(new Uint8Array(8)), 'the pieces after it are refused too, not played as PCM').toThrow(/the stream is a WAV file/);
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
