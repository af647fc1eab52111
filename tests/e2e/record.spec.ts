import { test, expect, imageStats } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { FPS, SAMPLE_RATE, SPEECH, lipGaps } from './helpers/audio';

/** The demo's Record button with Chromium's fake microphone playing tests/fixtures/speech-kal.wav. */
test.use({ launchOptions: fakeMicrophone(SPEECH) });

test('record: the face follows the microphone live, then the take replays in sync', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  // Count the live frames the face shows (a device slower than the stream gets them in batches: each is played out).
  await page.evaluate(() => {
    const g = globalThis as unknown as { talkingFace: { view: { setVertices(v: Float32Array): void } }; shownLive: number };
    const view = g.talkingFace.view, set = view.setVertices.bind(view);
    g.shownLive = 0;
    view.setVertices = (v) => (g.shownLive++, set(v));
  });
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  await expect(page.locator('#record-button')).toHaveClass(/recording/);
  await expect(page.locator('#details')).toContainText(/latency \d+ ms/, { timeout: 20_000 });
  const live = await page.locator('#face-canvas').screenshot();
  expect((await imageStats(page, live)).foregroundFraction).toBeGreaterThan(0.15);
  // A sample chosen while recording: the status says to stop first, the menu goes back, the recording goes on.
  await expect(page.locator('#sample-select option')).not.toHaveCount(1, { timeout: 20_000 });
  await page.locator('#sample-select').selectOption((await page.locator('#sample-select option').nth(1).getAttribute('value'))!);
  await expect(page.locator('#status')).toContainText('stop it first');
  await expect(page.locator('#sample-select')).toHaveValue('');
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true');
  await page.waitForTimeout(2000);
  const shown = await page.evaluate(() => (globalThis as unknown as { shownLive: number }).shownLive);
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#clip-info')).toContainText('Recording');
  const frames = await page.evaluate(() => (globalThis as unknown as { talkingFace: { take: { animation: { frames: number } } } }).talkingFace.take.animation.frames);
  console.log(`live: the face showed ${shown} frames while ${frames} were made (a software-drawn face here draws ~15 a second)`);
  // Before, one frame per batch: 15 of 192 here; played out, 71 (the bound leaves room for a machine twice as busy).
  expect(shown, 'live frames are played out, not only the last of each batch').toBeGreaterThan(frames / 6);
  const gaps = await lipGaps(page);
  expect(gaps.length).toBeGreaterThan(60);
  expect(Math.max(...gaps) - Math.min(...gaps), 'the mouth opens and closes (mm)').toBeGreaterThan(2);
  // ... in time with the speech: the lip gap follows the loudness of the take (best over a lag of +-100 ms).
  const envelope = await page.evaluate((per) => {
    const take = (globalThis as unknown as { talkingFace: { take: { samples: Float32Array; animation: { frames: number } } } }).talkingFace.take;
    return Array.from({ length: take.animation.frames }, (_, f) => {
      let e = 0;
      const a = Math.max(0, Math.round((f - 0.5) * per)), b = Math.min(take.samples.length, Math.round((f + 0.5) * per));
      for (let i = a; i < b; i++) e += take.samples[i] ** 2;
      return Math.sqrt(e / Math.max(1, b - a));
    });
  }, SAMPLE_RATE / FPS);
  const corr = (x: number[], y: number[]) => {
    const mx = x.reduce((s, v) => s + v, 0) / x.length, my = y.reduce((s, v) => s + v, 0) / y.length;
    let sxy = 0, sxx = 0, syy = 0;
    for (let i = 0; i < x.length; i++) { sxy += (x[i] - mx) * (y[i] - my); sxx += (x[i] - mx) ** 2; syy += (y[i] - my) ** 2; }
    return sxy / Math.sqrt(sxx * syy);
  };
  const lagged = [-3, -2, -1, 0, 1, 2, 3].map((lag) => corr(gaps.slice(Math.max(0, lag), gaps.length + Math.min(0, lag)), envelope.slice(Math.max(0, -lag), envelope.length - Math.max(0, lag))));
  console.log(`lip gap vs loudness: correlation ${lagged.map((c) => c.toFixed(2)).join(' ')} at lags -3..3 frames`);
  expect(Math.max(...lagged), 'lip gap follows the speech').toBeGreaterThan(0.3);
  await page.locator('#play-button').click();
  await expect(page.locator('#play-button')).toHaveText('Pause');
  await expect.poll(() => page.locator('#scrub').inputValue(), { timeout: 10_000 }).not.toBe('0');
  await page.locator('#play-button').click();
  await expect(page.locator('#play-button')).toHaveText('Play');
  // Scrubbing shows the chosen frame.
  await page.locator('#scrub').fill(String(FPS));
  await expect(page.locator('#time-label')).toHaveText('1.00 s');
});

test("while recording, the last take's playback rests; a file opened while the recording is finished waits for it", async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(page.locator('#sample-select option')).not.toHaveCount(1, { timeout: 20_000 });
  await page.locator('#sample-select').selectOption((await page.locator('#sample-select option').nth(1).getAttribute('value'))!);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  for (const id of ['#play-button', '#scrub', '#export-video', '#export-glb', '#export-raw', '#head-reroll']) await expect(page.locator(id), id).toBeDisabled();
  await page.locator('#face-canvas').focus();
  await page.keyboard.press('Space'); // play, by keyboard: not while the microphone drives the face
  await page.waitForTimeout(500);
  await expect(page.locator('#play-button')).toHaveText('Play');
  await expect(page.locator('#status')).toContainText('Recording');
  await page.waitForTimeout(1500);
  // Stop, and at once open a file (same task): it waits, the recording's take is what is shown.
  await page.evaluate(() => {
    document.getElementById('record-button')!.click();
    const input = document.getElementById('file-input') as HTMLInputElement;
    const data = new DataTransfer();
    data.items.add(new File([new Uint8Array(64)], 'too-soon.wav', { type: 'audio/wav' }));
    input.files = data.files;
    input.dispatchEvent(new Event('change', { bubbles: true }));
  });
  await expect(page.locator('#status')).toContainText('Finishing the recording');
  await expect(page.locator('#clip-info')).toContainText('Recording', { timeout: 60_000 });
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready');
  await expect(page.locator('#play-button')).toBeEnabled();
  await expect(page.locator('#play-button')).toHaveText('Play');
  await page.locator('#play-button').click();
  await expect(page.locator('#play-button')).toHaveText('Pause');
});

test('a take whose live frames were skipped is animated again with progress; Escape stops that and keeps the live frames', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const record = page.locator('#record-button');
  await record.focus();
  await page.keyboard.press('Enter');
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  await page.waitForTimeout(1500);
  // A slow device: the page's thread held for 1.5 s, more than the live lag limit (15 frames), so frames are skipped.
  await page.evaluate(() => { const t = performance.now(); while (performance.now() - t < 1500); });
  await expect(page.locator('#take-info')).toContainText('frames skipped to keep up', { timeout: 20_000 });
  // The visitor is told, on the status line, not only in the details.
  await expect(page.locator('#status')).toContainText('this device is slower than real time, so the face skips frames');
  await page.waitForTimeout(1000);
  // Watch the status: at its first progress line, press Escape (before the next chunk of the animation runs).
  await page.evaluate(() => {
    const g = globalThis as unknown as { statuses: string[] };
    g.statuses = [];
    const status = document.getElementById('status')!;
    new MutationObserver(() => {
      g.statuses.push(status.textContent ?? '');
      if (/frame \d+ of \d+/.test(status.textContent ?? '') && !g.statuses.some((s) => s.startsWith('Stopped'))) {
        document.activeElement!.dispatchEvent(new KeyboardEvent('keydown', { key: 'Escape', bubbles: true }));
      }
    }).observe(status, { childList: true, characterData: true, subtree: true });
  });
  await page.keyboard.press('Enter'); // Stop recording
  await expect(page.locator('#status')).toHaveText(/^Stopped animating the whole take: it keeps the live frames \(the \d+ skipped to keep up hold the frame before them\)\. Press Play\.$/, { timeout: 30_000 });
  const statuses = await page.evaluate(() => (globalThis as unknown as { statuses: string[] }).statuses);
  expect(statuses.some((s) => /^Animating the whole take .*: frame 0 of \d+…$/.test(s)), statuses.join(' | ')).toBe(true);
  // The take is kept (before, it was discarded): every frame of the recording, playable.
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready');
  const { frames, seconds } = await page.evaluate(() => {
    const take = (globalThis as unknown as { talkingFace: { take: { animation: { frames: number; fps: number }; seconds: number } } }).talkingFace.take;
    return { frames: take.animation.frames, seconds: take.seconds * take.animation.fps };
  });
  expect(Math.abs(frames - seconds)).toBeLessThanOrEqual(1);
  // Not all of its frames were computed: no speed figure (it was the live stream's time over every frame).
  await expect(page.locator('#take-info')).toContainText(/Decoder \w+: no speed figure: the live frames were kept, \d+ of them held where the device fell behind\./);
  await expect(page.locator('#play-button')).toBeEnabled();
  await expect(page.locator('#cancel-button')).toBeHidden();
  await expect(record, 'the focus stays on Record, enabled again').toBeFocused();
  await expect(record).toBeEnabled();
});
