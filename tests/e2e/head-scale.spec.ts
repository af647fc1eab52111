import { test, expect } from './fixtures';

/**
 * The demo's "Head motion" slider (engine.headMotionScale): speakers move their heads by very different amounts
 * and their voices do not say how much (docs/results/README.md, Head motion), so a visitor can make the head calmer
 * or livelier. On a sample clip, moved by keyboard: at 0 the head keeps the pose head's mean pose (it barely moves);
 * at 2 the head's own motion is twice as far; the lips and eyes are the same at every setting.
 */
type Take = { animation: { frames: number; pose: Float32Array; unposed: Float32Array } };
type TF = { take: Take | null };

/** The take's head rotation: each axis's standard deviation over the clip (degrees), the three axes' norm. */
async function spread(page: import('@playwright/test').Page): Promise<number> {
  return page.evaluate(() => {
    const a = (globalThis as unknown as { talkingFace: TF }).talkingFace.take!.animation;
    const sd = [0, 1, 2].map((k) => {
      const v = Array.from({ length: a.frames }, (_, f) => (a.pose[6 * f + k] * 180) / Math.PI);
      const m = v.reduce((s, x) => s + x, 0) / v.length;
      return Math.sqrt(v.reduce((s, x) => s + (x - m) ** 2, 0) / v.length);
    });
    return Math.hypot(...sd);
  });
}

/** Press `key` on the slider and wait for the take drawn again with the new scale. */
async function slide(page: import('@playwright/test').Page, key: string): Promise<void> {
  await page.evaluate(() => Object.assign(globalThis, { previousTake: (globalThis as unknown as { talkingFace: TF }).talkingFace.take }));
  await page.locator('#head-scale').press(key);
  await page.waitForFunction(() => {
    const g = globalThis as unknown as { talkingFace: TF; previousTake: Take };
    return g.talkingFace.take !== g.previousTake && document.body.dataset.take === 'ready';
  }, null, { timeout: 60_000 });
}

test('the head-motion slider makes the head calmer or livelier and leaves the lips as they are', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(page.locator('#sample-select option')).toHaveCount(4);
  const first = await page.locator('#sample-select option').nth(1).getAttribute('value');
  await page.locator('#sample-select').selectOption(first!);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#head-scale')).toBeEnabled();
  await expect(page.locator('#head-scale')).toHaveValue('1');
  const asLearnt = await spread(page);
  const unposed = await page.evaluate(() => Array.from((globalThis as unknown as { talkingFace: TF }).talkingFace.take!.animation.unposed));

  await slide(page, 'Home');
  await expect(page.locator('#head-scale')).toHaveValue('0');
  const still = await spread(page);
  await slide(page, 'End');
  await expect(page.locator('#head-scale')).toHaveValue('2');
  await expect(page.locator('#head-scale')).toHaveAttribute('aria-valuetext', /livelier/);
  const lively = await spread(page);
  console.log(`head spread (deg): scale 0 ${still.toFixed(2)}, 1 ${asLearnt.toFixed(2)}, 2 ${lively.toFixed(2)}`);
  expect(still).toBeLessThan(0.3 * asLearnt);
  expect(lively / asLearnt).toBeGreaterThan(1.6);
  expect(lively / asLearnt).toBeLessThan(2.4);
  const same = await page.evaluate((before) => {
    const now = (globalThis as unknown as { talkingFace: TF }).talkingFace.take!.animation.unposed;
    return now.length === before.length && now.every((x, i) => x === before[i]);
  }, unposed);
  expect(same, 'the unposed face (lips, eyes) does not change with the head').toBe(true);
});

test('New head motion draws the next seed; one stopped before it is drawn leaves the seed of the head shown', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(page.locator('#sample-select option')).toHaveCount(4);
  await page.locator('#sample-select').selectOption((await page.locator('#sample-select option').nth(1).getAttribute('value'))!);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  const seed = () => page.evaluate(() => (globalThis as unknown as { talkingFace: { engine: { headMotionSeed: number } } }).talkingFace.engine.headMotionSeed);
  expect(await seed()).toBe(0);
  const pose = () => page.evaluate(() => Array.from((globalThis as unknown as { talkingFace: TF }).talkingFace.take!.animation.pose));
  const first = await pose();

  // Stopped at once (Escape, in the same task as the click): the take keeps its head, and so does the seed.
  await page.evaluate(() => {
    document.getElementById('head-reroll')!.click();
    document.dispatchEvent(new KeyboardEvent('keydown', { key: 'Escape', bubbles: true, cancelable: true }));
  });
  await expect(page.locator('#status')).toHaveText('Stopped drawing the head again: the take is as it was.');
  expect(await seed(), 'the seed of the head still shown').toBe(0);
  await expect(page.locator('body')).toHaveAttribute('data-head-seed', '0');
  expect(await pose()).toEqual(first);

  await page.evaluate(() => Object.assign(globalThis, { previousTake: (globalThis as unknown as { talkingFace: TF }).talkingFace.take }));
  await page.locator('#head-reroll').click();
  await page.waitForFunction(() => {
    const g = globalThis as unknown as { talkingFace: TF; previousTake: Take };
    return g.talkingFace.take !== g.previousTake && document.body.dataset.take === 'ready';
  }, null, { timeout: 60_000 });
  expect(await seed(), 'the next seed, none skipped').toBe(1);
  expect(await pose()).not.toEqual(first);
  await expect(page.locator('#details'), 'the sample\'s E_vl is kept with its new head').toContainText(/E_vl on this clip: \d+\.\d\d mm/);
});
