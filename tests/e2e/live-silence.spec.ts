import { writeFileSync, mkdirSync } from 'node:fs';
import { resolve } from 'node:path';
import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { wav, lipGaps } from './helpers/audio';

/** A silent microphone (Chromium's fake device playing a silent WAV): the mouth stays closed. */
const DIR = resolve(import.meta.dirname, '../../test-results');
mkdirSync(DIR, { recursive: true });
const SILENT = resolve(DIR, 'silence-16k.wav');
writeFileSync(SILENT, wav([new Float32Array(16000 * 4)], 16000));

test.use({ launchOptions: fakeMicrophone(SILENT) });

test('live from a silent microphone: the mouth stays closed', async ({ page }) => {
  test.setTimeout(120_000);
  // Known failure, kept visible: the shipped model leaves the inner lips 1.6 mm apart on average in silence
  // (up to 2.4 mm; docs/results/default.md, "Silence"). Playwright reports it if this starts passing, so
  // this line goes when the model is fixed.
  test.fail(true, 'the shipped model does not close the lips fully in silence (docs/results/default.md)');
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
  // Closed: the inner lips within 1.5 mm of touching on every frame (the rig's closed mouth is ~0.4 mm;
  // the template's neutral mouth is 5.5 mm open).
  expect(Math.max(...gaps), 'largest inner-lip gap in silence (mm)').toBeLessThan(1.5);
});
