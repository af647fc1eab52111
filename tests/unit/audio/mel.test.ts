/** Log-Mel (src/audio/mel.ts): meyda's features against Python's on the exporter's fixture clip, and the fast path against Meyda.extract. */
import { describe, expect, it } from 'vitest';
import type { Manifest } from '../../../src/model/manifest';
import { f32 } from '../../../src/model/safetensors';
import { logMel, logMelFrames, logMelFramesMeyda, melFrameCount } from '../../../src/audio/mel';
import { loadFixtures, loadManifest, maxAbsDiff } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);

describe('log-Mel vs the PyTorch fixture', () => {
  it('log-Mel with meyda matches Python', () => {
    const mel = logMel(f32(fx, 'audio'), manifest.audio);
    expect(maxAbsDiff(mel, f32(fx, 'mel'))).toBeLessThan(1e-4);
  });

  it('the fast log-Mel equals Meyda.extract, on speech, loud noise, silence and a streaming offset', () => {
    const a = manifest.audio;
    const speech = f32(fx, 'audio');
    let seed = 1;
    const noise = Float32Array.from({ length: 8000 }, () => ((seed = (seed * 16807) % 2147483647) / 2147483647 - 0.5) * 2);
    for (const x of [speech, noise, new Float32Array(3000)]) {
      const K = melFrameCount(x.length, a);
      const fast = logMelFrames(x, a, 0, K);
      const meyda = logMelFramesMeyda(x, a, 0, K);
      let rel = 0;
      for (let i = 0; i < fast.length; i++) rel = Math.max(rel, Math.abs(fast[i] - meyda[i]) / Math.max(1, Math.abs(meyda[i])));
      expect(rel).toBeLessThan(1e-6);
    }
    // A window of the signal with its offset gives the same frames as the whole signal.
    const part = logMelFrames(speech.subarray(3000, 6000), a, 25, 5, undefined, 3000, speech.length);
    expect(maxAbsDiff(part, logMelFrames(speech, a, 25, 5))).toBe(0);
  });
});
