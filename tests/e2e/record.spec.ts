import { test, expect, imageStats } from './fixtures';
import { CHROMIUM_ARGS } from '../../playwright.config';
import { SPEECH, lipGaps } from './helpers/audio';

/** The demo's Record button with Chromium's fake microphone playing tests/fixtures/speech-kal.wav. */
test.use({
  launchOptions: {
    executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium',
    args: [...CHROMIUM_ARGS, '--use-fake-ui-for-media-stream', '--use-fake-device-for-media-stream', `--use-file-for-fake-audio-capture=${SPEECH}`],
  },
});

test('record: the face follows the microphone live, then the take replays in sync', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  await expect(page.locator('#record-button')).toHaveAttribute('aria-pressed', 'true');
  await expect(page.locator('#status')).toContainText(/latency \d+ ms/, { timeout: 20_000 });
  const live = await page.locator('#face-canvas').screenshot();
  expect((await imageStats(page, live)).foregroundFraction).toBeGreaterThan(0.15);
  await page.waitForTimeout(2500);
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#clip-info')).toContainText('Recording');
  const gaps = await lipGaps(page);
  expect(gaps.length).toBeGreaterThan(60);
  expect(Math.max(...gaps) - Math.min(...gaps), 'the mouth opens and closes (mm)').toBeGreaterThan(2);
  await page.locator('#play-button').click();
  await expect(page.locator('#play-button')).toHaveText('Pause');
  await expect.poll(() => page.locator('#scrub').inputValue(), { timeout: 10_000 }).not.toBe('0');
  await page.locator('#play-button').click();
  await expect(page.locator('#play-button')).toHaveText('Play');
  // Scrubbing shows the chosen frame.
  await page.locator('#scrub').fill('30');
  await expect(page.locator('#time-label')).toHaveText('1.00 s');
});
