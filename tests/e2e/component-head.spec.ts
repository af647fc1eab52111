import { test, expect } from './fixtures';

/**
 * <talking-face head-motion="..."> (docs/embedding.md): how far the head's own motion turns the head, per element
 * (two elements share one engine, so it is carried by each animation, not set on the engine): 0 keeps the mean
 * pose, 2 turns it twice as far as 1; a value outside 0-3 warns and the element animates with the model's own motion.
 */
type FaceEl = HTMLElement & { speak(a: string): Promise<void>; currentAnimation: { frames: number; pose: Float32Array } | null };

/** Speak the sample with `head-motion` set to `value` (null: removed); the head rotation's spread (degrees). */
async function spreadWith(page: import('@playwright/test').Page, value: string | null): Promise<number> {
  return page.locator('#left').evaluate(async (el, v) => {
    const face = el as FaceEl;
    if (v === null) face.removeAttribute('head-motion');
    else face.setAttribute('head-motion', v);
    await face.speak('/examples/sample.wav');
    const a = face.currentAnimation!;
    const sd = [0, 1, 2].map((k) => {
      const x = Array.from({ length: a.frames }, (_, f) => (a.pose[6 * f + k] * 180) / Math.PI);
      const m = x.reduce((s, y) => s + y, 0) / x.length;
      return Math.sqrt(x.reduce((s, y) => s + (y - m) ** 2, 0) / x.length);
    });
    return Math.hypot(...sd);
  }, value);
}

test('the head-motion attribute makes an element\'s head calmer or livelier', async ({ page }) => {
  test.setTimeout(120_000);
  const warnings: string[] = [];
  page.on('console', (m) => m.type() === 'warning' && warnings.push(m.text()));
  await page.goto('/examples/embed.html');
  await page.locator('#left').evaluate((el) => (el as unknown as { ready: Promise<unknown> }).ready);
  const asLearnt = await spreadWith(page, null);
  const still = await spreadWith(page, '0');
  const lively = await spreadWith(page, '2');
  const bad = await spreadWith(page, 'lively');
  console.log(`head spread (deg): head-motion 0 ${still.toFixed(2)}, none ${asLearnt.toFixed(2)}, 2 ${lively.toFixed(2)}, "lively" ${bad.toFixed(2)}`);
  expect(still).toBeLessThan(0.3 * asLearnt);
  expect(lively / asLearnt).toBeGreaterThan(1.6);
  expect(lively / asLearnt).toBeLessThan(2.4);
  expect(Math.abs(bad - asLearnt)).toBeLessThan(1e-6);
  expect(warnings.some((w) => w.includes('head-motion="lively"') && w.includes('0 to 3'))).toBe(true);
});
