import { test, expect } from './fixtures';
import { FPS, SPEECH, speechSamples, wav, resample, lipGaps } from './helpers/audio';

/** Inputs a visitor may bring: other rates, stereo, clipping, very long files, a broken or missing model. */
test.describe('the demo with unusual audio', () => {
  test.beforeEach(async ({ page }) => {
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  });

  const { samples, rate } = speechSamples();
  const seconds = samples.length / rate;
  const cases: [string, () => Buffer, string][] = [
    ['8 kHz telephone audio', () => wav([resample(samples, rate, 8000)], 8000), 'mono'],
    ['48 kHz audio', () => wav([resample(samples, rate, 48000)], 48000), 'mono'],
    ['stereo', () => wav([samples, samples.map((v) => 0.5 * v)], rate), '2 channels mixed to mono'],
  ];
  for (const [name, make, info] of cases) {
    test(`${name} is resampled / mixed and animated`, async ({ page }) => {
      await page.locator('#file-input').setInputFiles({ name: 'clip.wav', mimeType: 'audio/wav', buffer: make() });
      await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
      await expect(page.locator('#clip-info')).toContainText(info);
      const gaps = await lipGaps(page);
      expect(Math.abs(gaps.length - Math.round(seconds * FPS))).toBeLessThanOrEqual(1);
      expect(Math.max(...gaps) - Math.min(...gaps)).toBeGreaterThan(2);
    });
  }

  test('clipped audio is animated with a note', async ({ page }) => {
    const loud = samples.map((v) => Math.max(-1, Math.min(1, v * 12)));
    await page.locator('#file-input').setInputFiles({ name: 'loud.wav', mimeType: 'audio/wav', buffer: wav([loud], rate) });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#status')).toContainText('clipped');
  });

  test('a very long file shows progress and can be cancelled; the page keeps working', async ({ page }) => {
    const tenMinutes = new Float32Array(600 * 8000).map((_, i) => 0.1 * Math.sin(i * 0.05) * Math.sin(i * 0.0003));
    await page.locator('#file-input').setInputFiles({ name: 'long.wav', mimeType: 'audio/wav', buffer: wav([tenMinutes], 8000) });
    await expect(page.locator('#status')).toContainText('long clip', { timeout: 60_000 });
    await expect(page.locator('#status')).toContainText(/frame \d+ of 18000/);
    await page.locator('#cancel-button').click();
    await expect(page.locator('#status')).toContainText('Stopped animating long.wav');
    await expect(page.locator('#cancel-button')).toBeHidden();
    await page.locator('#file-input').setInputFiles(SPEECH);
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  });
});

test('a file opened while the model loads is animated once it is in; Record then says to wait; the decoder waits too', async ({ page }) => {
  test.setTimeout(90_000);
  await page.route('**/models/gava.safetensors', async (route) => {
    await new Promise((resolve) => setTimeout(resolve, 5000)); // a slow connection
    await route.continue();
  });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-ready', 'true', { timeout: 30_000 });
  expect(await page.locator('body').getAttribute('data-engine')).toBeNull();
  await expect(page.locator('#backend-select'), 'no choice that could not be applied yet').toBeDisabled();
  await page.locator('#record-button').click();
  await expect(page.locator('#status')).toHaveText('The model is still loading: press Record again once it is ready.');
  await expect(page.locator('#status')).not.toHaveClass(/error/);
  await page.locator('#file-input').setInputFiles(SPEECH);
  const waiting = 'The model is still loading: speech-kal.wav is animated once it is in (Escape cancels)…';
  await expect(page.locator('#status')).toHaveText(waiting);
  await page.keyboard.press('Escape'); // it waits cancellably
  await expect(page.locator('#status')).toHaveText('Stopped animating speech-kal.wav. Open another file or record.');
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('#status')).toHaveText(waiting);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#play-button')).toHaveText('Pause'); // and played, as a file opened once it was in
  await expect(page.locator('#backend-select')).toBeEnabled();
});

test.describe('the demo with a broken model', () => {
  test('a corrupt model file is reported and the face can still be viewed', async ({ page }) => {
    await page.route('**/models/gava.safetensors', (route) => route.fulfill({ status: 200, contentType: 'application/octet-stream', body: Buffer.from('not the weights') }));
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'error', { timeout: 60_000 });
    await expect(page.locator('#details')).toContainText('corrupt');
    await expect(page.locator('#status')).toContainText('The face can still be viewed');
    await page.locator('#file-input').setInputFiles(SPEECH);
    await expect(page.locator('#status')).toContainText('The model is not loaded');
  });

  test('a missing model is reported', async ({ page, guard }) => {
    guard.allowConsoleError(/404|Failed to load resource/);
    await page.route('**/models/manifest.json', (route) => route.fulfill({ status: 404, body: 'not found' }));
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'error', { timeout: 60_000 });
    await expect(page.locator('#details')).toContainText('HTTP 404');
    await expect(page.locator('body')).toHaveAttribute('data-ready', 'true');
  });

  test('no microphone gives a clear message', async ({ page }) => {
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
    await page.locator('#record-button').click();
    await expect(page.locator('body')).toHaveAttribute('data-recording', 'error', { timeout: 20_000 });
    await expect(page.locator('#status')).toContainText(/no microphone was found|microphone access was denied/);
    await expect(page.locator('#record-button')).toBeEnabled();
  });
});
