import { test, expect } from './fixtures';

/**
 * decodeAudio() brings a file at the browser's rate down to the model's through a low-pass (as training's sox does):
 * what lies above the model's Nyquist frequency (a fricative's hiss at 44.1 kHz) is removed, not folded into the band
 * the model hears; what lies in that band keeps its level.
 */
test('decoding at 44.1 or 48 kHz to 16 kHz: a tone above 8 kHz is removed, one below keeps its level', async ({ page }) => {
  await page.goto('/examples/embed.html', { waitUntil: 'domcontentloaded' });
  const read = await page.evaluate(async () => {
    const { decodeAudio } = await import('/lib/talking-face.js' as string) as { decodeAudio(b: AudioBuffer, rate: number): Promise<{ samples: Float32Array }> };
    const rms = (x: Float32Array) => Math.sqrt(x.reduce((s, v) => s + v * v, 0) / x.length);
    const out: Record<string, number> = {};
    for (const rate of [44100, 48000]) {
      for (const hz of [1000, 11000]) {
        const buffer = new AudioBuffer({ length: rate, numberOfChannels: 1, sampleRate: rate });
        buffer.copyToChannel(Float32Array.from({ length: rate }, (_, i) => 0.5 * Math.sin((2 * Math.PI * hz * i) / rate)), 0);
        const { samples } = await decodeAudio(buffer, 16000);
        out[`${rate}:${hz}:length`] = samples.length;
        out[`${rate}:${hz}`] = rms(samples.subarray(1600, samples.length - 1600)) / (0.5 * Math.SQRT1_2); // (away from the ends)
      }
    }
    return out;
  });
  console.log(`level after decoding to 16 kHz, as a share of the tone's: ${JSON.stringify(read)}`);
  for (const rate of [44100, 48000]) {
    expect(read[`${rate}:1000:length`]).toBe(16000);
    expect(read[`${rate}:1000`], `1 kHz from ${rate} Hz`).toBeCloseTo(1, 1);
    expect(read[`${rate}:11000`], `11 kHz from ${rate} Hz (folded to 5 kHz unless filtered)`).toBeLessThan(0.01);
  }
});
