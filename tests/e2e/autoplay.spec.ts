import { test, expect } from './fixtures';
import { CHROMIUM_ARGS } from '../../playwright.config';

/**
 * The browser's own autoplay rules (every other test turns them off): sound may start only after a person's
 * gesture on the page. <talking-face src autoplay> then says to click, and plays on the first click.
 *
 * Every Playwright evaluate() counts as a gesture (it runs with userGesture), so until the click this test only
 * listens: the element is made by an init script, which also logs its status and events to the console.
 */
test.use({
  launchOptions: {
    executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium',
    args: [...CHROMIUM_ARGS.filter((a) => !a.startsWith('--autoplay-policy')), '--autoplay-policy=document-user-activation-required'],
  },
});

test('autoplay held back until a gesture: the element says so, then plays on a click', async ({ page, guard }) => {
  test.setTimeout(120_000);
  guard.allowConsoleError(/AudioContext was not allowed to start/);
  const log: string[] = [];
  page.on('console', (m) => m.text().startsWith('auto') && log.push(m.text()));
  await page.addInitScript(() => document.addEventListener('DOMContentLoaded', () => {
    const el = document.createElement('talking-face');
    el.setAttribute('src', '/examples/sample.wav');
    el.setAttribute('autoplay', '');
    let frames = 0;
    el.addEventListener('frame', () => frames++ === 0 && console.log('auto: first frame'));
    el.addEventListener('ended', () => console.log(`auto: ended after ${frames} frames`));
    document.body.prepend(el);
    void customElements.whenDefined('talking-face').then(() => {
      const status = el.shadowRoot!.querySelector('p.status')!;
      new MutationObserver(() => console.log(`auto status: ${status.textContent}`)).observe(status, { childList: true, characterData: true, subtree: true });
    });
  }));
  await page.goto('/examples/embed.html');
  await expect.poll(() => log.some((l) => l.includes('Click or press a key to hear it')), { timeout: 60_000 }).toBe(true);
  await page.waitForTimeout(1500);
  expect(log, 'no frames while the sound is held back').not.toContain('auto: first frame');
  await page.mouse.click(5, 5); // a gesture anywhere on the page
  await expect.poll(() => log.some((l) => l.startsWith('auto: ended')), { timeout: 60_000 }).toBe(true);
  expect(log.some((l) => l.startsWith('auto status: Playing')), 'back to the playing status').toBe(true);
  // Frames are shown as the page draws (a few a second under a software GPU), and each one sends a frame event.
  expect(Number(/after (\d+) frames/.exec(log.find((l) => l.startsWith('auto: ended'))!)![1])).toBeGreaterThan(5);
});
