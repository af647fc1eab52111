import { test, expect } from './fixtures';
import { SPEECH } from './helpers/audio';

/**
 * The encoders' sessions are created and run in onnxruntime's own worker (src/encoders/onnx-worker.ts), off the
 * page's main thread; where no worker can run, or it fails to start, they run in the page and give the same take.
 */
async function animate(page: import('@playwright/test').Page): Promise<string> {
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  return (await page.locator('#take-info').textContent()) ?? '';
}

test('the encoders run in onnxruntime worker', async ({ page }) => {
  await page.goto('/');
  await animate(page);
  expect(page.workers().map((w) => w.url()).some((u) => /onnx-worker/.test(u))).toBe(true);
});

test('without Web Workers the encoders run in the page', async ({ page }) => {
  await page.addInitScript(() => Object.defineProperty(globalThis, 'Worker', { value: undefined }));
  await page.goto('/');
  await animate(page);
  expect(page.workers()).toEqual([]);
});

test('where onnxruntime worker cannot load, the encoders fall back to the page', async ({ page, guard }) => {
  await page.route(/onnx-worker[^/]*\.js$/, (route) => route.fulfill({ status: 404, body: 'not found' }));
  guard.allowConsoleError(/onnx-worker|404|Not Found/i);
  const warnings: string[] = [];
  page.on('console', (m) => { if (m.type() === 'warning' && /onnxruntime's worker/.test(m.text())) warnings.push(m.text()); });
  await page.goto('/');
  await animate(page);
  expect(warnings, 'said once, not once per session').toHaveLength(1);
});
