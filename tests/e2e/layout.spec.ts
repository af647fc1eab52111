import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { SPEECH, speechSamples, wav } from './helpers/audio';

/**
 * A steady layout (issue 18): whatever the page is doing and whatever its status line says, the face's canvas
 * keeps its size and the controls keep their places. Measured at idle, while animating, playing, recording, and
 * after an error; any shift of more than half a pixel fails.
 */
test.use({ launchOptions: fakeMicrophone(SPEECH) });

const WATCHED = ['#face-canvas', '#timeline', '#file-input + span', '#record-button', '#microphone-select', '#sample-select', '#backend-select',
  '#play-button', '#scrub', '#time-label', '#paint-select', '#export-video', '#export-glb', '#export-raw', '#status', '#details'];

type Boxes = Record<string, { x: number; y: number; width: number; height: number }>;

async function boxes(page: import('@playwright/test').Page): Promise<Boxes> {
  return page.evaluate((ids) => Object.fromEntries(ids.map((id) => {
    const r = document.querySelector(id)!.getBoundingClientRect();
    return [id, { x: r.x, y: r.y, width: r.width, height: r.height }];
  })), WATCHED);
}

function shifts(base: Boxes, now: Boxes): string[] {
  const out: string[] = [];
  for (const id of WATCHED) {
    for (const k of ['x', 'y', 'width', 'height'] as const) {
      if (Math.abs(base[id][k] - now[id][k]) > 0.5) out.push(`${id} ${k} ${base[id][k].toFixed(1)} -> ${now[id][k].toFixed(1)}`);
    }
  }
  return out;
}

test('the canvas and the controls stay put at idle, animating, playing, recording and after an error', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(page.locator('#sample-select option')).toHaveCount(4);
  const idle = await boxes(page);
  const states: Record<string, Boxes> = {};

  // Animating: a clip long enough to be caught in progress (the status then says which frame).
  const { samples, rate } = speechSamples();
  const long = new Float32Array(rate * 40);
  for (let o = 0; o < long.length; o += samples.length) long.set(samples.subarray(0, Math.min(samples.length, long.length - o)), o);
  await page.locator('#file-input').setInputFiles({ name: 'a-rather-long-file-name-for-a-forty-second-recording-of-speech.wav', mimeType: 'audio/wav', buffer: wav([long], rate) });
  await expect(page.locator('#status')).toContainText(/frame \d+ of/, { timeout: 30_000 });
  states.animating = await boxes(page);
  await expect(page.locator('#cancel-button')).toBeHidden({ timeout: 120_000 });

  // Playing: the take plays as soon as it is animated.
  await expect(page.locator('#play-button')).toHaveText('Pause');
  states.playing = await boxes(page);
  await page.locator('#play-button').click();
  await expect(page.locator('#play-button')).toHaveText('Play');
  states.paused = await boxes(page);

  // Recording, with the live figures changing in the details.
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  await expect(page.locator('#record-button')).toHaveText('Stop recording');
  states.recording = await boxes(page);
  await page.locator('#record-button').click();
  await expect(page.locator('#clip-info')).toContainText('Recording', { timeout: 60_000 });

  // An error: a file that is not audio.
  await page.locator('#file-input').setInputFiles({ name: 'broken.wav', mimeType: 'audio/wav', buffer: Buffer.from('RIFF....WAVEnot really audio') });
  await expect(page.locator('body')).toHaveAttribute('data-take', 'error', { timeout: 30_000 });
  await expect(page.locator('#status')).toHaveClass(/error/);
  states.error = await boxes(page);

  for (const [state, b] of Object.entries(states)) expect(shifts(idle, b), `shifts while ${state}`).toEqual([]);
  await test.info().attach('error-state.png', { body: await page.screenshot(), contentType: 'image/png' });
});

test('the details, opened, lie over the face and cover no control, at any width; Escape on them closes them', async ({ page }) => {
  const controls = 'section.controls button, section.controls select, section.controls input, section.controls .file-button span, #status, #details summary';
  for (const viewport of [{ width: 1100, height: 760 }, { width: 1920, height: 1080 }, { width: 390, height: 800 }]) {
    await page.setViewportSize(viewport);
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
    await page.locator('#details summary').click();
    await expect(page.locator('#details .details-body')).toBeVisible();
    const covered = await page.evaluate((selector) => {
      const panel = document.querySelector('#details .details-body')!.getBoundingClientRect();
      const stage = document.getElementById('stage')!.getBoundingClientRect();
      const hit = [...document.querySelectorAll(selector)].filter((el) => {
        const r = el.getBoundingClientRect();
        return r.width > 0 && r.left < panel.right && panel.left < r.right && r.top < panel.bottom && panel.top < r.bottom;
      }).map((el) => el.id || el.textContent!.trim());
      const inside = panel.left >= stage.left - 0.5 && panel.right <= stage.right + 0.5 && panel.bottom <= stage.bottom + 0.5;
      return { hit, inside };
    }, controls);
    expect(covered.hit, `controls under the details at ${viewport.width} px`).toEqual([]);
    expect(covered.inside, `the details within the face's view at ${viewport.width} px`).toBe(true);
    await page.keyboard.press('Escape'); // the focus is on the summary just clicked
    await expect(page.locator('#details .details-body')).toBeHidden();
    await expect(page.locator('#details summary')).toBeFocused();
  }
});

test('on a phone the status line stays on screen, scrolled or not, and covers no control once scrolled to the end', async ({ page }) => {
  await page.setViewportSize({ width: 360, height: 640 });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  for (const y of [0, 10_000]) {
    await page.evaluate((top) => scrollTo(0, top), y);
    const r = await page.evaluate(() => {
      const s = document.getElementById('status')!.getBoundingClientRect();
      const bar = document.querySelector('.status-bar')!.getBoundingClientRect();
      const under = [...document.querySelectorAll('section.controls button, section.controls select, section.controls input:not([type=file]), .file-button span')]
        .filter((el) => { const b = el.getBoundingClientRect(); return b.bottom > bar.top && b.top < bar.bottom; }).map((el) => el.id || el.textContent);
      return { top: s.top, bottom: s.bottom, height: innerHeight, under, page: document.documentElement.scrollHeight };
    });
    expect(r.page, 'the page scrolls at this size').toBeGreaterThan(r.height);
    expect(r.top, `status top, scrolled to ${y}`).toBeGreaterThanOrEqual(0);
    expect(r.bottom, `status bottom, scrolled to ${y}`).toBeLessThanOrEqual(r.height);
    if (y > 0) expect(r.under, 'controls under the status bar at the end of the page').toEqual([]);
  }
});

test.describe('under a finger (a coarse pointer)', () => {
  test.use({ hasTouch: true, viewport: { width: 375, height: 667 } });

  test('every control is at least 24 px tall and no select zooms the page when tapped', async ({ page }) => {
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
    expect(await page.evaluate(() => matchMedia('(pointer: coarse)').matches), 'the pointer is coarse').toBe(true);
    const controls = await page.evaluate(() => [...document.querySelectorAll(
      'section.controls button:not([hidden]), section.controls select, section.controls input:not([type=file]), .file-button span, #details summary')]
      // A checkbox is hit through its label, which toggles it.
      .map((el) => ({ id: el.id || el.textContent!.trim(), tag: el.tagName, font: parseFloat(getComputedStyle(el).fontSize),
        height: ((el as HTMLInputElement).type === 'checkbox' ? el.closest('label')! : el).getBoundingClientRect().height })));
    expect(controls.length).toBeGreaterThan(10);
    expect(controls.filter((c) => c.height < 24).map((c) => `${c.id} ${c.height.toFixed(1)} px`), 'controls under 24 px').toEqual([]);
    // Safari on iOS zooms the page into a select or text field whose text is under 16 px when it is tapped.
    expect(controls.filter((c) => c.tag === 'SELECT' && c.font < 16).map((c) => `${c.id} ${c.font} px`), 'selects under 16 px').toEqual([]);
  });
});

test('on a phone, when a take has played, the controls its message names are on screen, not under the status line', async ({ page }) => {
  test.setTimeout(120_000);
  await page.setViewportSize({ width: 375, height: 667 });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#sample-select').selectOption((await page.locator('#sample-select option').nth(1).getAttribute('value'))!);
  await expect(page.locator('#status')).toContainText('press Play', { timeout: 60_000 });
  await expect(page.locator('#status')).toContainText('open another file');
  const r = await page.evaluate(() => ({
    scrolled: scrollY,
    bar: document.querySelector('.status-bar')!.getBoundingClientRect().top,
    play: document.getElementById('play-button')!.getBoundingClientRect().bottom,
    open: document.querySelector('#file-input + span')!.getBoundingClientRect().bottom,
  }));
  expect(r.scrolled, 'the page was not scrolled').toBe(0);
  expect(r.play, 'Play above the status line').toBeLessThanOrEqual(r.bar);
  expect(r.open, '"Open an audio file…" above the status line').toBeLessThanOrEqual(r.bar);
});
