import { test, expect } from './fixtures';
import { CHROMIUM_ARGS } from '../../playwright.config';
import { SPEECH } from './helpers/audio';

/**
 * A browser that gives no WebGL (hardware acceleration turned off, a graphics driver it blocks with no software
 * fallback, a policy): what a visitor and an embedding page get. The demo says so plainly; <talking-face> says so
 * once (an error event, stage 'render'), is ready with `drawn: false`, and still speaks: the sound plays and its
 * frame events come, ARKit weights included, for a page that shows them its own way; the page's own-scene example
 * says why it shows nothing.
 */
test.use({ launchOptions: { executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium', args: [...CHROMIUM_ARGS, '--disable-3d-apis'] } });

const PLAIN = /cannot draw 3D here \(WebGL is turned off or unavailable\)[:.] turn on hardware acceleration in its settings, or try another browser/i;

test('the demo says plainly that this browser cannot draw the face, and what to do', async ({ page, guard }) => {
  guard.allowConsoleError(/^Error: this browser cannot draw 3D here/); // the start's failure, for a developer's console
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-ready', 'error', { timeout: 60_000 });
  await expect(page.locator('#status')).toHaveText(PLAIN);
  await expect(page.locator('#status')).not.toContainText('THREE');
  // A file opened then waits for nothing: the message stays, not "still loading" for ever.
  await page.locator('#file-input').setInputFiles(SPEECH);
  await page.waitForTimeout(500);
  await expect(page.locator('#status')).toHaveText(PLAIN);
  await page.locator('#record-button').click();
  await expect(page.locator('#status')).toHaveText(PLAIN);
});

test('a file opened while the demo starts, which then cannot draw the face: the message that says why stays', async ({ page, guard }) => {
  guard.allowConsoleError(/^Error: this browser cannot draw 3D here/);
  await page.route('**/models/template/template.json', async (route) => { // the face is built (and fails) 2 s in
    await new Promise((resolve) => setTimeout(resolve, 2000));
    await route.continue();
  });
  await page.goto('/', { waitUntil: 'domcontentloaded' });
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('#status')).toContainText('is animated once it is in'); // waiting, as the start then fails
  await expect(page.locator('body')).toHaveAttribute('data-ready', 'error', { timeout: 60_000 });
  await page.waitForTimeout(1000);
  await expect(page.locator('#status')).toHaveText(PLAIN);
});

test('<talking-face> without WebGL: one render error, ready (drawn: false), and speech still plays with its frame events', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(() => {
    const g = globalThis as unknown as { seen: string[]; frames: { jawOpen: number; time: number }[] };
    [g.seen, g.frames] = [[], []];
    document.addEventListener('DOMContentLoaded', () => {
      const left = document.getElementById('left')!;
      left.setAttribute('blendshapes', '');
      left.addEventListener('error', (e) => g.seen.push(`error:${(e as unknown as CustomEvent).detail.stage}:${(e as unknown as CustomEvent).detail.message}`));
      left.addEventListener('ready', (e) => g.seen.push(`ready:drawn=${(e as CustomEvent).detail.drawn}`));
      left.addEventListener('ended', () => g.seen.push('ended'));
      left.addEventListener('frame', (e) => g.frames.push({ jawOpen: (e as CustomEvent).detail.arkit?.jawOpen, time: (e as CustomEvent).detail.time }));
    });
  });
  await page.goto('/examples/embed.html');
  const seen = () => page.evaluate(() => (globalThis as unknown as { seen: string[] }).seen);
  await expect.poll(seen, { timeout: 60_000 }).toContainEqual('ready:drawn=false');
  const [error, ready] = await seen();
  expect(error).toMatch(/^error:render:the face is not shown: this browser cannot draw 3D here/);
  expect(error).toMatch(PLAIN);
  expect(ready).toBe('ready:drawn=false');
  const status = () => page.evaluate(() => document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent!);
  expect(await status()).toMatch(PLAIN);

  // It speaks: the sound plays (the speak() promise resolves once it has), frames come with their weights, then ended.
  await page.evaluate(() => (document.getElementById('left') as unknown as { speak(src: string): Promise<void> }).speak('/examples/sample.wav'));
  await expect.poll(seen, { timeout: 30_000 }).toContainEqual('ended');
  const frames = await page.evaluate(() => (globalThis as unknown as { frames: { jawOpen: number; time: number }[] }).frames);
  console.log(`without WebGL: ${frames.length} frame events, last at ${frames.at(-1)?.time.toFixed(2)} s`);
  expect(frames.length, 'frame events while the speech played').toBeGreaterThan(20);
  const jaw = frames.map((f) => f.jawOpen);
  expect(jaw.every((j) => Number.isFinite(j)), 'each carries its ARKit weights').toBe(true);
  expect(Math.max(...jaw) - Math.min(...jaw), 'the jaw moves with the speech').toBeGreaterThan(0.05);
  expect((await seen()).filter((s) => s.startsWith('error')), 'said once').toHaveLength(1);

  // No video can be made of what is not drawn: said plainly.
  const video = await page.evaluate(() => (document.getElementById('left') as unknown as { recordVideo(): Promise<Blob> }).recordVideo().then(() => 'made', (e: Error) => e.message));
  expect(video).toMatch(/the video could not be made: the face is not shown: this browser cannot draw 3D here/);
});

test('the own-scene example says why it shows nothing', async ({ page, guard }) => {
  guard.allowConsoleError(/uncaught: no WebGL here/); // the example stops there
  await page.goto('/examples/own-scene.html');
  await expect(page.locator('#log')).toHaveText(/This page cannot show its scene: the browser cannot draw 3D here/, { timeout: 30_000 });
});
