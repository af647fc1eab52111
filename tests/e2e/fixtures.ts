/**
 * Shared end-to-end fixtures. Every test page is watched for the whole test:
 * any request that leaves the page's own origin, any console error and any
 * uncaught exception fails the test afterwards.
 */
import { test as base, expect, type Page } from '@playwright/test';

export interface PageGuard {
  /** Console errors that a test provoked on purpose and checks itself. */
  allowConsoleError(pattern: RegExp): void;
  requests: string[];
}

export const test = base.extend<{ guard: PageGuard }>({
  guard: [
    async ({ page, baseURL }, use) => {
      const origin = new URL(baseURL!).origin;
      const foreign: string[] = [];
      const errors: string[] = [];
      const allowed: RegExp[] = [];
      const requests: string[] = [];
      page.on('request', (req) => {
        const url = req.url();
        requests.push(url);
        if (url.startsWith('data:') || url.startsWith('blob:')) return;
        if (new URL(url).origin !== origin) foreign.push(url);
      });
      page.on('console', (msg) => {
        if (msg.type() === 'error') errors.push(msg.text());
      });
      page.on('pageerror', (err) => errors.push(`uncaught: ${err.message}`));
      await use({ allowConsoleError: (p) => allowed.push(p), requests });
      expect(foreign, 'requests beyond the page origin').toEqual([]);
      expect(errors.filter((e) => !allowed.some((p) => p.test(e))), 'console errors').toEqual([]);
    },
    { auto: true },
  ],
});
export { expect };

export interface ImageStats {
  width: number;
  height: number;
  /** Fraction of pixels whose colour differs from the corner (background) colour. */
  foregroundFraction: number;
  /** Bounding box of foreground pixels, as fractions of the image size. */
  box: { x0: number; y0: number; x1: number; y1: number };
  distinctColours: number;
}

/** Decode a PNG screenshot inside the page (no PNG library needed) and measure what is drawn. */
export async function imageStats(page: Page, png: Buffer): Promise<ImageStats> {
  return page.evaluate(async (b64) => {
    const blob = await (await fetch(`data:image/png;base64,${b64}`)).blob();
    const bmp = await createImageBitmap(blob);
    const c = new OffscreenCanvas(bmp.width, bmp.height);
    const ctx = c.getContext('2d')!;
    ctx.drawImage(bmp, 0, 0);
    const { data, width, height } = ctx.getImageData(0, 0, bmp.width, bmp.height);
    const bg = [data[0], data[1], data[2]];
    let fg = 0;
    let x0 = width, y0 = height, x1 = -1, y1 = -1;
    const colours = new Set<number>();
    for (let y = 0; y < height; y++) {
      for (let x = 0; x < width; x++) {
        const i = 4 * (y * width + x);
        colours.add((data[i] >> 3) | ((data[i + 1] >> 3) << 5) | ((data[i + 2] >> 3) << 10));
        if (Math.abs(data[i] - bg[0]) + Math.abs(data[i + 1] - bg[1]) + Math.abs(data[i + 2] - bg[2]) > 24) {
          fg++;
          x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y);
        }
      }
    }
    return {
      width, height,
      foregroundFraction: fg / (width * height),
      box: { x0: x0 / width, y0: y0 / height, x1: (x1 + 1) / width, y1: (y1 + 1) / height },
      distinctColours: colours.size,
    };
  }, png.toString('base64'));
}

/** The fraction of pixels whose colour differs (by more than 24 in R + G + B) between two screenshots of one size. */
export async function differingFraction(page: Page, a: Buffer, b: Buffer): Promise<number> {
  return page.evaluate(async ([x, y]) => {
    const pixels = async (b64: string) => {
      const bmp = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
      const c = new OffscreenCanvas(bmp.width, bmp.height).getContext('2d')!;
      c.drawImage(bmp, 0, 0);
      return c.getImageData(0, 0, bmp.width, bmp.height).data;
    };
    const [p, q] = [await pixels(x), await pixels(y)];
    let n = 0;
    for (let i = 0; i < p.length; i += 4) if (Math.abs(p[i] - q[i]) + Math.abs(p[i + 1] - q[i + 1]) + Math.abs(p[i + 2] - q[i + 2]) > 24) n++;
    return n / (p.length / 4);
  }, [a.toString('base64'), b.toString('base64')] as const);
}
