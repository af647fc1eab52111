import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { SPEECH } from './helpers/audio';

/**
 * The whole demo by keyboard alone (issue 18): open a file, play, pause, scrub, orbit and zoom the face, step
 * frames, record, stop, export. Focus moves with Tab only; nothing is clicked. The live region announces changes
 * of state, not every frame.
 */
test.use({ launchOptions: fakeMicrophone(SPEECH) });

type Page = import('@playwright/test').Page;

/** Press Tab until `selector` has the focus (as a person would), at most 40 times. */
async function tabTo(page: Page, selector: string): Promise<void> {
  for (let i = 0; i < 40; i++) {
    if (await page.locator(selector).evaluate((el) => el === document.activeElement)) return;
    await page.keyboard.press('Tab');
  }
  throw new Error(`Tab never reached ${selector}`);
}

const camera = (page: Page) => page.evaluate(() => {
  const v = (globalThis as unknown as { talkingFace: { view: { camera: { position: { x: number; y: number; z: number } }; controls: { target: { x: number; y: number; z: number } } } } }).talkingFace.view;
  const p = v.camera.position, t = v.controls.target;
  return { x: p.x, y: p.y, z: p.z, distance: Math.hypot(p.x - t.x, p.y - t.y, p.z - t.z) };
});

test('open, play, pause, scrub, orbit, zoom, step, record, stop and export by keyboard alone', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  // Count what the live region announces from here on.
  await page.evaluate(() => {
    const w = globalThis as unknown as { announced: string[] };
    w.announced = [];
    new MutationObserver(() => w.announced.push(document.getElementById('announce')!.textContent ?? '')).observe(document.getElementById('announce')!, { childList: true, characterData: true, subtree: true });
  });

  // Open a file: Enter on "Open an audio file…" opens the chooser; the take then plays by itself.
  // (Waiting for the chooser from before the first Tab: Playwright then intercepts it well before Enter.)
  const chooser = page.waitForEvent('filechooser');
  await tabTo(page, '#file-input');
  await page.keyboard.press('Enter');
  await (await chooser).setFiles(SPEECH);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#play-button')).toHaveText('Pause');

  // Pause and play with Space and Enter on the Play button; Escape stops playback.
  await tabTo(page, '#play-button');
  await page.keyboard.press('Space');
  await expect(page.locator('#play-button')).toHaveText('Play');
  await page.keyboard.press('Enter');
  await expect(page.locator('#play-button')).toHaveText('Pause');
  await expect(page.locator('#play-button')).toBeFocused();
  await page.keyboard.press('Escape');
  await expect(page.locator('#play-button')).toHaveText('Play');

  // Loop is a checkbox: Enter toggles it as Space does.
  await tabTo(page, '#loop-check');
  await page.keyboard.press('Enter');
  await expect(page.locator('#loop-check')).toBeChecked();
  await page.keyboard.press('Space');
  await expect(page.locator('#loop-check')).not.toBeChecked();

  // Scrub: Home, End and the arrows move the frame.
  await tabTo(page, '#scrub');
  await page.keyboard.press('Home');
  await expect(page.locator('#time-label')).toHaveText('0.00 s');
  await page.keyboard.press('ArrowRight');
  await expect(page.locator('#scrub')).toHaveValue('1');
  await expect(page.locator('#time-label')).toHaveText('0.03 s');

  // The face: arrows orbit, + and - zoom, comma and full stop step a frame, Space plays.
  await tabTo(page, '#face-canvas');
  const before = await camera(page);
  await page.keyboard.press('ArrowLeft');
  await page.keyboard.press('ArrowUp');
  const turned = await camera(page);
  expect(Math.hypot(turned.x - before.x, turned.y - before.y, turned.z - before.z), 'the camera moved').toBeGreaterThan(0.01 * before.distance);
  expect(turned.distance).toBeCloseTo(before.distance, 3);
  await page.keyboard.press('+');
  expect((await camera(page)).distance).toBeLessThan(0.9 * before.distance);
  await page.keyboard.press('-');
  expect((await camera(page)).distance).toBeCloseTo(before.distance, 3);
  await page.keyboard.press('.');
  await page.keyboard.press('.');
  await expect(page.locator('#scrub')).toHaveValue('3');
  await page.keyboard.press(',');
  await expect(page.locator('#scrub')).toHaveValue('2');
  // Space held down plays once: its repeats do not toggle playback on and off.
  await page.keyboard.down(' ');
  for (let i = 0; i < 3; i++) await page.keyboard.down(' '); // (each a repeat)
  await page.keyboard.up(' ');
  await expect(page.locator('#play-button')).toHaveText('Pause');
  await page.keyboard.press('Escape');
  await expect(page.locator('#play-button')).toHaveText('Play');

  // Record: Enter starts, the focus stays on the button, Space stops; Escape stops a second take.
  await tabTo(page, '#record-button');
  await page.keyboard.press('Enter');
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  await expect(page.locator('#record-button')).toHaveClass(/recording/);
  await expect(page.locator('#record-button')).toBeFocused();
  await page.waitForTimeout(1500);
  await page.keyboard.press('Space');
  await expect(page.locator('#clip-info')).toContainText('Recording', { timeout: 60_000 });
  await expect(page.locator('#record-button')).not.toHaveClass(/recording/);
  await expect(page.locator('#record-button')).toBeFocused();
  await page.keyboard.press('Enter');
  await expect(page.locator('#record-button')).toHaveClass(/recording/, { timeout: 20_000 });
  await page.waitForTimeout(1000);
  await page.keyboard.press('Escape');
  await expect(page.locator('#record-button')).not.toHaveClass(/recording/);
  await expect(page.locator('#status')).toContainText('Recording is ready', { timeout: 60_000 });

  // Export: Enter on "Export .glb" downloads the take.
  await tabTo(page, '#export-glb');
  const [download] = await Promise.all([page.waitForEvent('download'), page.keyboard.press('Enter')]);
  expect(download.suggestedFilename()).toBe('Recording.glb');
  await expect(page.locator('#export-glb')).toBeFocused();

  // The live region spoke of each change of state once, not of every frame or progress step.
  const announced = await page.evaluate(() => (globalThis as unknown as { announced: string[] }).announced);
  console.log(`announced ${announced.length} times:\n  ${announced.join('\n  ')}`);
  expect(announced.length).toBeLessThan(30);
  expect(announced.some((a) => /frame \d+ of/.test(a)), 'no progress in the live region').toBe(false);
  for (let i = 1; i < announced.length; i++) expect(announced[i], 'no announcement repeated back to back').not.toBe(announced[i - 1]);
});
