import { test, expect } from './fixtures';

/**
 * The studio environment (src/render/environment.ts) is prefiltered on the CPU and handed to three.js as a ready
 * PMREM cube texture: a mirror ball lit by it alone must show the studio the way the code defines it, not mirrored
 * or with faces swapped (dev/environment.html compares every pixel with the radiance it should reflect).
 */
test('a mirror ball reflects the studio environment as defined, not mirrored', async ({ page }) => {
  await page.goto('/dev/environment.html');
  const handle = await page.waitForFunction(() => (globalThis as unknown as { environmentResult?: unknown }).environmentResult, null, { timeout: 30_000 });
  const r = (await handle.jsonValue()) as { error?: string; pixels: number; correlation: number; mirroredCorrelation: number };
  expect(r.error, String(r.error)).toBeUndefined();
  expect(r.pixels).toBeGreaterThan(8000);
  expect(r.correlation).toBeGreaterThan(0.9);
  expect(r.mirroredCorrelation).toBeLessThan(r.correlation - 0.1);
});
