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

test('an element removed while its clip waits for a gesture leaves no listener on the document', async ({ page, guard }) => {
  test.setTimeout(120_000);
  guard.allowConsoleError(/AudioContext was not allowed to start/);
  await page.addInitScript(() => {
    const g = globalThis as unknown as { listening: number };
    g.listening = 0;
    const add = document.addEventListener.bind(document), remove = document.removeEventListener.bind(document);
    document.addEventListener = (type: string, ...rest: [EventListenerOrEventListenerObject, (boolean | AddEventListenerOptions)?]) => {
      if (type === 'pointerdown') g.listening++;
      return add(type, ...rest);
    };
    document.removeEventListener = (type: string, ...rest: [EventListenerOrEventListenerObject, (boolean | EventListenerOptions)?]) => {
      if (type === 'pointerdown') g.listening--;
      return remove(type, ...rest);
    };
    document.addEventListener('DOMContentLoaded', () => {
      const el = document.createElement('talking-face');
      el.id = 'held';
      el.setAttribute('src', '/examples/sample.wav');
      el.setAttribute('autoplay', '');
      document.body.prepend(el);
      // Watched from here, not by evaluate() (a gesture, which would let the sound start).
      void customElements.whenDefined('talking-face').then(() => {
        const status = el.shadowRoot!.querySelector('p.status')!;
        new MutationObserver(() => console.log(`held status: ${status.textContent}`)).observe(status, { childList: true, characterData: true, subtree: true });
      });
    });
  });
  const log: string[] = [];
  page.on('console', (m) => m.text().startsWith('held') && log.push(m.text()));
  await page.goto('/examples/embed.html');
  const listening = () => page.evaluate(() => (globalThis as unknown as { listening: number }).listening);
  await expect.poll(() => log.some((l) => l.includes('Click or press a key')), { timeout: 60_000 }).toBe(true);
  const waiting = await listening();
  await page.evaluate(() => document.getElementById('held')!.remove());
  expect(await listening(), 'pointerdown listeners once the waiting element left').toBe(waiting - 1);
});

test("speakStream(engine) on the library's own context, begun before any gesture: onBlocked, then it plays on a click and done settles", async ({ page, guard }) => {
  test.setTimeout(120_000);
  guard.allowConsoleError(/AudioContext was not allowed to start/);
  const log: string[] = [];
  page.on('console', (m) => m.text().startsWith('stream') && log.push(m.text()));
  // All from an init script: an evaluate() would count as a gesture and let the sound start.
  await page.addInitScript(() => window.addEventListener('load', async () => {
    const { speakStream } = await import('/lib/npm/engine.js' as string);
    const g = globalThis as unknown as { ownSceneExample?: { state: { engine?: unknown } } };
    while (!g.ownSceneExample?.state.engine) await new Promise((r) => setTimeout(r, 100));
    let [shown, speaking] = [0, 0];
    const speech = speakStream(g.ownSceneExample.state.engine, { sampleRate: 16000, onBlocked: () => console.log(`stream blocked after ${shown} frames`),
      show: (_frames: unknown, _f: number, on: boolean) => (shown++, on && speaking++) });
    const wav = await (await fetch('/examples/sample.wav')).arrayBuffer();
    speech.write(new Uint8Array(wav, 44, (wav.byteLength - 44) & ~1)); // 16-bit PCM at 16 kHz after its header
    speech.end();
    const expected = Math.round((((wav.byteLength - 44) >> 1) / 16000) * (g.ownSceneExample.state.engine as { fps: number }).fps);
    speech.done.then(() => console.log(`stream done: ${shown} frames shown, ${speaking} speaking, take ${speech.take?.animation.frames} of ${expected}`),
      (e: Error) => console.log(`stream failed: ${e.message}`));
  }));
  await page.goto('/examples/own-scene.html');
  await expect.poll(() => log.find((l) => l.startsWith('stream blocked')), { timeout: 60_000 }).toBe('stream blocked after 0 frames');
  await page.waitForTimeout(1000);
  expect(log.filter((l) => !l.startsWith('stream blocked')), 'nothing shown, nothing settled while held back').toEqual([]);
  await page.mouse.click(2, 2); // a gesture anywhere on the page
  await expect.poll(() => log.find((l) => l.startsWith('stream done') || l.startsWith('stream failed')), { timeout: 60_000 }).toMatch(/^stream done/);
  const [, shown, speaking, take, expected] = /(\d+) frames shown, (\d+) speaking, take (\d+) of (\d+)/.exec(log.find((l) => l.startsWith('stream done'))!)!.map(Number);
  expect(take, 'the whole sample played').toBe(expected);
  expect(shown).toBeGreaterThan(10);
  expect(speaking).toBeGreaterThan(5);
});
