import { test, expect } from './fixtures';

/**
 * A face not on screen draws nothing (src/render/canvas-size.ts, OnScreen): an idle <talking-face> (it breathes and
 * blinks, a draw every animation frame) hidden with display: none or scrolled out of view stops drawing, and draws
 * again when it is shown. Draw calls are counted per canvas by wrapping WebGL2's drawElements and drawArrays.
 */
test('a <talking-face> hidden or scrolled away stops drawing, and draws again when shown', async ({ page }) => {
  test.setTimeout(90_000);
  await page.addInitScript(() => {
    const counts = new Map<HTMLCanvasElement | OffscreenCanvas, number>();
    (globalThis as unknown as { drawCounts: typeof counts }).drawCounts = counts;
    const proto = WebGL2RenderingContext.prototype as unknown as Record<string, (...a: unknown[]) => unknown>;
    for (const name of ['drawElements', 'drawArrays']) {
      const original = proto[name];
      proto[name] = function (this: WebGL2RenderingContext, ...args: unknown[]) {
        counts.set(this.canvas, (counts.get(this.canvas) ?? 0) + 1);
        return original.apply(this, args);
      };
    }
  });
  await page.goto('/examples/embed.html');
  await page.evaluate(() => (document.getElementById('left') as HTMLElement & { ready: Promise<unknown> }).ready);
  await page.waitForFunction(() => document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent!.includes('Ready'), null, { timeout: 30_000 });
  const drawsIn = (ms: number) => page.evaluate(async (wait) => {
    const canvas = document.getElementById('left')!.shadowRoot!.querySelector('canvas')!;
    const counts = (globalThis as unknown as { drawCounts: Map<HTMLCanvasElement, number> }).drawCounts;
    const before = counts.get(canvas) ?? 0;
    await new Promise((r) => setTimeout(r, wait));
    return (counts.get(canvas) ?? 0) - before;
  }, ms);
  expect(await drawsIn(1500), 'shown and idle, it draws').toBeGreaterThan(0);

  await page.evaluate(() => (document.getElementById('left')!.style.display = 'none'));
  await drawsIn(300); // (the report that it is hidden comes with the next frame)
  expect(await drawsIn(1500), 'display: none').toBe(0);
  await page.evaluate(() => (document.getElementById('left')!.style.display = ''));
  await expect.poll(() => drawsIn(500), { timeout: 10_000 }).toBeGreaterThan(0);

  await page.evaluate(() => {
    document.body.style.paddingBottom = '300vh';
    window.scrollTo(0, document.body.scrollHeight);
  });
  await drawsIn(300);
  expect(await drawsIn(1500), 'scrolled out of view').toBe(0);
  await page.evaluate(() => window.scrollTo(0, 0));
  await expect.poll(() => drawsIn(500), { timeout: 10_000 }).toBeGreaterThan(0);
});
