import { test, expect } from './fixtures';
import { FPS, SAMPLE_RATE, SPEECH, framesOf, lipGaps, wav } from './helpers/audio';

/** A 16-bit PCM WAV of `seconds` of silence. */
const silentWav = (seconds: number) => wav([new Float32Array(Math.round(seconds * SAMPLE_RATE))], SAMPLE_RATE);

test.describe('animating an audio file', () => {
  test.beforeEach(async ({ page }) => {
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  });

  test('speech opens and closes the mouth, and the take plays as soon as it is animated', async ({ page }) => {
    await page.locator('#file-input').setInputFiles(SPEECH);
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#details')).toContainText('x real time');
    await expect(page.locator('#status')).not.toContainText('no speech');
    const gaps = await lipGaps(page);
    expect(gaps.length).toBe(framesOf(SPEECH));
    expect(Math.max(...gaps) - Math.min(...gaps)).toBeGreaterThan(2); // it moves by millimetres, not noise
    await expect(page.locator('#play-button')).toBeEnabled();
    await expect(page.locator('#play-button')).toHaveText('Pause'); // playing without a press
    await expect.poll(() => page.locator('#scrub').inputValue(), { timeout: 10_000 }).not.toBe('0');
    await page.locator('#play-button').click();
    await expect(page.locator('#play-button')).toHaveText('Play');
    await page.locator('#play-button').click();
    await expect(page.locator('#play-button')).toHaveText('Pause');
  });

  test('a silent recording is animated and reported as silent', async ({ page }) => {
    // (That the mouth stays closed through a silent microphone is checked in live-silence.spec.ts.)
    await page.locator('#file-input').setInputFiles({ name: 'silence.wav', mimeType: 'audio/wav', buffer: silentWav(2) });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#status')).toContainText('silent');
    expect((await lipGaps(page)).length).toBe(2 * FPS);
  });

  test('a file that is not audio, or a damaged one, is named for what it is, and the page keeps working', async ({ page }) => {
    await page.locator('#file-input').setInputFiles({ name: 'photo.png', mimeType: 'image/png', buffer: Buffer.from('\x89PNG\r\n\x1a\n and an image', 'latin1') });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'error', { timeout: 30_000 });
    await expect(page.locator('#status')).toContainText('it is a PNG image, not audio');
    await page.locator('#file-input').setInputFiles({ name: 'broken.wav', mimeType: 'audio/wav', buffer: Buffer.from('RIFF....WAVEnot really audio') });
    await expect(page.locator('#status')).toContainText('it is a damaged WAV file');
    await page.locator('#file-input').setInputFiles(SPEECH);
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  });

  test('a WAV cut short plays what it holds and says how much is missing', async ({ page }) => {
    const whole = wav([Float32Array.from({ length: 2 * SAMPLE_RATE }, (_, i) => 0.3 * Math.sin(i / 5))], SAMPLE_RATE);
    await page.locator('#file-input').setInputFiles({ name: 'cut.wav', mimeType: 'audio/wav', buffer: whole.subarray(0, 44 + SAMPLE_RATE) });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#status')).toContainText('the file ends early: it holds 0.5 s of the 2.0 s its header states');
  });
});
