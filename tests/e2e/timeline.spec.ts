import { test, expect } from './fixtures';

/**
 * The timeline under the face (issue 14): for a sample clip it draws the predicted inner-lip gap (blue), the
 * truth's (grey) and the heard phones, and its playhead (a white column) follows the scrubber.
 */
async function columns(page: import('@playwright/test').Page): Promise<{ blue: number; grey: number; whiteColumn: number }> {
  return page.evaluate(() => {
    const c = document.getElementById('timeline') as HTMLCanvasElement;
    const d = c.getContext('2d')!.getImageData(0, 0, c.width, c.height).data;
    let blue = 0, grey = 0;
    const white = new Array(c.width).fill(0);
    for (let i = 0; i < d.length; i += 4) {
      const [r, g, b] = [d[i], d[i + 1], d[i + 2]];
      if (b > 200 && r < 180 && g > 150) blue++;
      if (Math.abs(r - 0x9a) < 12 && Math.abs(g - 0xa3) < 12 && Math.abs(b - 0xb5) < 12) grey++;
      if (r > 250 && g > 250 && b > 250) white[(i / 4) % c.width]++;
    }
    return { blue, grey, whiteColumn: white.indexOf(Math.max(...white)) };
  });
}

test('the timeline shows the lip gap, the truth and the heard phones, and its playhead follows the scrubber', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const box = await page.locator('#timeline').boundingBox();
  const first = await page.locator('#sample-select option').nth(1).getAttribute('value');
  await page.locator('#sample-select').selectOption(first!);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  const after = await page.locator('#timeline').boundingBox();
  expect([after!.width, after!.height], 'the strip kept its size').toEqual([box!.width, box!.height]);
  const start = await columns(page);
  expect(start.blue, 'predicted gap curve').toBeGreaterThan(50);
  expect(start.grey, 'truth gap curve').toBeGreaterThan(50);
  await page.locator('#scrub').fill('60');
  const later = await columns(page);
  expect(later.whiteColumn, 'the playhead moved right').toBeGreaterThan(start.whiteColumn + 20);
  // The window resized (paused at frame 60): the playhead stays at the frame, at its place on the new width.
  const atFrame60 = later.whiteColumn / (await page.evaluate(() => (document.getElementById('timeline') as HTMLCanvasElement).width));
  const wide = await page.evaluate(() => (document.getElementById('timeline') as HTMLCanvasElement).width);
  await page.setViewportSize({ width: 700, height: 760 });
  await expect.poll(async () => (await page.evaluate(() => (document.getElementById('timeline') as HTMLCanvasElement).width))).toBeLessThan(wide);
  const resized = await columns(page);
  const width = await page.evaluate(() => (document.getElementById('timeline') as HTMLCanvasElement).width);
  expect(resized.whiteColumn / width, 'the playhead after a resize').toBeCloseTo(atFrame60, 2);
  await test.info().attach('timeline.png', { body: await page.locator('#timeline').screenshot(), contentType: 'image/png' });
});
