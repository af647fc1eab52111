/**
 * decodeAudio's signal (src/audio/decode.ts): a long file's decode (35 s for 45 minutes of 48 kHz stereo in headless
 * Chromium here) does not hold Cancel up. decodeAudioData cannot be stopped, so the abort rejects at once.
 */
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { decodeAudio } from '../../../src/audio/decode';

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
    await expect(decodeAudio(new ArrayBuffer(64), 16000, new AbortController().signal)).rejects.toThrow(/cannot decode the file.*bad data/);
  });
});
