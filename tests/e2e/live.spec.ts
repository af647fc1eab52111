import { resolve } from 'node:path';
import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';

/**
 * Live capture through the engine: Chromium's fake microphone plays tests/fixtures/speech-kal.wav into
 * getUserMedia -> AudioWorklet -> StreamSession (dev/live.html). The streamed frames must equal the
 * offline animation of the captured take, and the lips must move with the speech.
 */
const WAV = resolve(import.meta.dirname, '../fixtures/speech-kal.wav');
test.use({ launchOptions: fakeMicrophone(WAV) });

test('microphone -> worklet -> streaming engine: frames equal the offline animation of the take', async ({ page }) => {
  await page.goto('/dev/live.html?seconds=3');
  const handle = await page.waitForFunction(() => (globalThis as unknown as { liveResult?: unknown }).liveResult, null, { timeout: 50_000 });
  const r = (await handle.jsonValue()) as {
    error?: string; capturedSeconds: number; peak: number; frames: number; offlineFrames: number; streamVsOffline: number;
    latency: { frames: number; p50Ms: number }; lookAheadMs: number; tracksEnded: boolean; mmPerUnit: number; gaps: number[];
  };
  expect(r.error, r.error).toBeUndefined();
  expect(r.capturedSeconds).toBeGreaterThan(2);
  expect(r.peak, 'speech reached the worklet').toBeGreaterThan(0.05);
  expect(r.frames).toBe(r.offlineFrames);
  expect(r.streamVsOffline).toBeLessThan(1e-5);
  expect(r.latency.frames).toBeGreaterThan(10);
  expect(Number.isFinite(r.latency.p50Ms)).toBe(true);
  console.log(`live capture (fake microphone -> AudioWorklet -> engine): latency p50 ${r.latency.p50Ms.toFixed(0)} ms over ${r.latency.frames} frames (look-ahead ${r.lookAheadMs.toFixed(0)} ms)`);
  expect(r.lookAheadMs).toBeLessThanOrEqual(150);
  expect(r.tracksEnded, 'stop() released the microphone').toBe(true);
  const range = (Math.max(...r.gaps) - Math.min(...r.gaps)) * r.mmPerUnit;
  expect(range, 'inner-lip gap range in mm').toBeGreaterThan(2);
});
