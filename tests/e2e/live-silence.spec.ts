import { writeFileSync, mkdirSync } from 'node:fs';
import { resolve } from 'node:path';
import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { SAMPLE_RATE, wav, lipGaps } from './helpers/audio';

/** A silent microphone (Chromium's fake device playing a silent WAV): the mouth stays closed. */
const DIR = resolve(import.meta.dirname, '../../test-results');
mkdirSync(DIR, { recursive: true });
const SILENT = resolve(DIR, 'silence-16k.wav');
writeFileSync(SILENT, wav([new Float32Array(SAMPLE_RATE * 4)], SAMPLE_RATE));

test.use({ launchOptions: fakeMicrophone(SILENT) });

test('live from a silent microphone: the mouth stays closed', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  await page.waitForTimeout(2500);
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#status')).toContainText('silent');
  const gaps = await lipGaps(page);
  expect(gaps.length).toBeGreaterThan(60);
  console.log(`silent microphone: ${gaps.length} frames, inner-lip gap mean ${(gaps.reduce((a, b) => a + b, 0) / gaps.length).toFixed(2)} mm, largest ${Math.max(...gaps).toFixed(2)} mm`);
  // Closed: the inner lips within 1.5 mm of touching on every frame (the training rest faces close them to
  // 0.03-0.07 mm; the template's neutral mouth is 5.5 mm open).
  expect(Math.max(...gaps), 'largest inner-lip gap in silence (mm)').toBeLessThan(1.5);
});
