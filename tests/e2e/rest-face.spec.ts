import { test, expect } from './fixtures';

/** Before any audio the face shows the model's rest face, mouth closed, not the template opened for the lips to part. */
test('the idle face has its mouth closed', async ({ page }) => {
  test.setTimeout(90_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-rest', 'shown', { timeout: 60_000 });
  const gaps = await page.evaluate(() => {
    const tf = (globalThis as unknown as { talkingFace: { view: { shownVertices: Float32Array }; template: { positions: Float32Array; regions: Record<string, Uint32Array> }; engine: { unitsPerMm: number } } }).talkingFace;
    const { regions } = tf.template;
    const up = Array.from(regions.lips_inner_upper).filter((v) => !regions.lips_inner_lower.includes(v));
    const lo = Array.from(regions.lips_inner_lower).filter((v) => !regions.lips_inner_upper.includes(v));
    const gap = (p: Float32Array) => (up.reduce((s, v) => s + p[v * 3 + 1], 0) / up.length - lo.reduce((s, v) => s + p[v * 3 + 1], 0) / lo.length) / tf.engine.unitsPerMm;
    return { shown: gap(tf.view.shownVertices), template: gap(tf.template.positions) };
  });
  console.log(`idle inner-lip gap ${gaps.shown.toFixed(2)} mm (the opened template: ${gaps.template.toFixed(2)} mm)`);
  expect(gaps.template).toBeGreaterThan(3);
  expect(gaps.shown, 'inner-lip gap of the idle face (mm)').toBeLessThan(1);
});
