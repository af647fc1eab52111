/**
 * decodeAudio's signal (src/audio/decode.ts): a long file's decode (35 s for 45 minutes of 48 kHz stereo in headless
 * Chromium here) does not hold Cancel up. decodeAudioData cannot be stopped, so the abort rejects at once.
 */
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { decodeAudio, mixToMono } from '../../../src/audio/decode';

beforeEach(() => vi.stubGlobal('AudioBuffer', class {})); // Web Audio's, which Node lacks
afterEach(() => vi.unstubAllGlobals());

describe('decodeAudio with a signal', () => {
  it('rejects as soon as the signal aborts, while the browser is still decoding', async () => {
    let started = false;
    vi.stubGlobal('OfflineAudioContext', class {
      decodeAudioData(): Promise<never> {
        started = true;
        return new Promise(() => undefined); // a decode that takes its time
      }
    });
    const abort = new AbortController();
    const decoding = decodeAudio(new ArrayBuffer(64), 16000, abort.signal);
    await new Promise((r) => setTimeout(r, 10));
    expect(started).toBe(true);
    abort.abort(new DOMException('Cancelled', 'AbortError'));
    await expect(decoding).rejects.toThrow('Cancelled');
    await expect(decodeAudio(new ArrayBuffer(64), 16000, abort.signal)).rejects.toThrow('Cancelled'); // aborted before it starts
  });

  it('gives a decode failure as before', async () => {
    vi.stubGlobal('OfflineAudioContext', class {
      decodeAudioData(): Promise<never> {
        return Promise.reject(new Error('bad data'));
      }
    });
    await expect(decodeAudio(new ArrayBuffer(64), 16000, new AbortController().signal)).rejects.toThrow(/cannot decode the file \(bad data\): if it plays elsewhere, convert it/);
  });
});

describe('mixToMono', () => {
  it('takes the mean of the channels, so speech on all of them keeps its level', () => {
    const ch = (...x: number[]) => Float32Array.from(x);
    expect(Array.from(mixToMono([ch(0.5, -1)]))).toEqual([0.5, -1]);
    expect(Array.from(mixToMono([ch(1, 0.5), ch(0, 0.5)]))).toEqual([0.5, 0.5]);
    // three channels, speech on the third only (Web Audio's own down-mix keeps the first: silence)
    expect(Array.from(mixToMono([ch(0), ch(0), ch(0.9)]))[0]).toBeCloseTo(0.3, 6);
  });

  it('mixes 5.1 with the speakers\' weights, to unit gain: the same speech on every channel stays as loud, not 3.4 times', () => {
    const same = Array.from({ length: 6 }, () => Float32Array.from([0.8]));
    expect(mixToMono(same)[0]).toBeCloseTo(0.8, 6);
    const centreOnly = Array.from({ length: 6 }, (_, c) => Float32Array.from([c === 2 ? 1 : 0]));
    const lfeOnly = Array.from({ length: 6 }, (_, c) => Float32Array.from([c === 3 ? 1 : 0]));
    expect(mixToMono(centreOnly)[0]).toBeCloseTo(1 / (2 * Math.SQRT1_2 + 2), 6); // dialogue, the loudest weight
    expect(mixToMono(lfeOnly)[0]).toBe(0);
  });
});
