import { test, expect } from './fixtures';
import { SPEECH, speechSamples, wav } from './helpers/audio';

/**
 * What keyboard and screen-reader users and visitors who ask for reduced motion meet (WCAG 2.2 AA), in the demo
 * and in <talking-face>: only the announcer is a live region, and it never hears of progress or the clock; focus
 * is not lost when Cancel hides; the paint notices are announced; a vertex is chosen by keyboard; the element's
 * face turns and zooms by keyboard; reduced motion holds the face at rest still.
 */
type Page = import('@playwright/test').Page;

/** Record every change of text inside any live region of the document (any element a screen reader would speak from). */
const WATCH_LIVE = () => {
  const g = globalThis as unknown as { liveChanges: Record<string, number> };
  g.liveChanges = {};
  const live = 'output, [role=status], [role=log], [role=alert], [role=timer], [role=marquee], [aria-live]:not([aria-live=off])';
  new MutationObserver((records) => {
    for (const r of records) {
      const node = r.target instanceof Element ? r.target : r.target.parentElement;
      const region = node?.closest(live);
      if (region) g.liveChanges[region.id || region.tagName] = (g.liveChanges[region.id || region.tagName] ?? 0) + 1;
    }
  }).observe(document.body, { childList: true, characterData: true, subtree: true });
};

const liveChanges = (page: Page) => page.evaluate(() => (globalThis as unknown as { liveChanges: Record<string, number> }).liveChanges);

test('the demo: one live region, quiet while playing; Cancel hands its focus on; notices spoken; a vertex chosen by keyboard', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.evaluate(WATCH_LIVE);

  // Play a file to its end: the clock beside the scrubber changes every frame and is no live region.
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#status')).toContainText('Finished playing', { timeout: 30_000 });
  const changes = await liveChanges(page);
  console.log('live-region changes while a take played:', JSON.stringify(changes));
  expect(Object.keys(changes), 'live regions that spoke').toEqual(['announce']);
  expect(changes.announce).toBeLessThan(8);
  // The scrubber says where it is in seconds, not as a bare frame number.
  await page.locator('#scrub').focus();
  await page.keyboard.press('Home');
  await page.keyboard.press('ArrowRight');
  await expect(page.locator('#scrub')).toHaveAttribute('aria-valuetext', /^0\.03 s of \d+\.\d\d s$/);

  // The same news again later (the frames exported twice) is heard again: the region is emptied and filled anew.
  const heard: number[] = [];
  for (const round of [0, 1]) {
    if (round) await page.waitForTimeout(1200); // (the same news within a second is one change told twice)
    const before = (await liveChanges(page)).announce;
    const saved = page.waitForEvent('download');
    await page.locator('#export-raw').click();
    await saved;
    await expect(page.locator('#announce')).toHaveText(/^Saved .*: the raw frames\.$/);
    heard.push((await liveChanges(page)).announce - before);
  }
  expect(heard[1], 'the second export is announced too').toBeGreaterThan(0);

  // A file take has no truth: choosing the error map says so to a screen reader too.
  await page.locator('#paint-select').selectOption('error');
  await expect(page.locator('#announce')).toHaveText(/The error map needs a sample clip/);

  // A vertex's attention: ] and [ on the face go round the lips; the legend names the vertex chosen.
  await page.locator('#paint-select').selectOption('vertex-attention');
  await expect(page.locator('body')).toHaveAttribute('data-painted', 'vertex-attention', { timeout: 30_000 });
  const vertexOf = async () => Number((await page.locator('#legend').textContent())!.match(/Vertex (\d+)'s/)![1]);
  const first = await vertexOf();
  await page.locator('#face-canvas').focus();
  await page.keyboard.press(']');
  await expect.poll(vertexOf, { timeout: 20_000 }).not.toBe(first);
  const second = await vertexOf();
  await page.keyboard.press('[');
  await expect.poll(vertexOf, { timeout: 20_000 }).toBe(first);
  expect(second).not.toBe(first);
  await page.locator('#paint-select').selectOption('none');

  // Cancel is focused while a long clip is animated; when it hides, the focus goes on to Play, not to the page.
  const { samples, rate } = speechSamples();
  const long = new Float32Array(rate * 30);
  for (let o = 0; o < long.length; o += samples.length) long.set(samples.subarray(0, Math.min(samples.length, long.length - o)), o);
  await page.locator('#file-input').setInputFiles({ name: 'long.wav', mimeType: 'audio/wav', buffer: wav([long], rate) });
  await expect(page.locator('#cancel-button')).toBeVisible();
  await page.locator('#cancel-button').focus();
  await page.keyboard.press('Enter');
  await expect(page.locator('#cancel-button')).toBeHidden({ timeout: 30_000 });
  await expect(page.locator('#play-button')).toBeFocused();
});

test('reduced motion holds the demo face at rest still; on a phone the status line says all it has', async ({ page }) => {
  test.setTimeout(120_000);
  await page.emulateMedia({ reducedMotion: 'reduce' });
  await page.setViewportSize({ width: 320, height: 640 });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const idle = () => page.evaluate(() => (globalThis as unknown as { talkingFace: { view: { idleState: unknown } } }).talkingFace.view.idleState);
  await page.waitForTimeout(1500);
  expect(await idle(), 'no breathing, blinks or eye movements').toBeNull();
  // Held still for a while, speech still blends in over 0.12 s: no faster than 1 per 0.12 s, not one jump after the
  // stillness (the view and this sampler run in either order within a frame: the bound runs from the frame before).
  const sampled = page.evaluate(() => new Promise<[number, number][]>((resolve) => {
    const view = (globalThis as unknown as { talkingFace: { view: { speechWeight: number } } }).talkingFace.view;
    const out: [number, number][] = [];
    const sample = () => {
      out.push([performance.now(), view.speechWeight]);
      if (out.at(-1)![1] >= 1 || out.length > 3000) resolve(out);
      else requestAnimationFrame(sample);
    };
    sample();
  }));
  await page.locator('#file-input').setInputFiles(SPEECH);
  const w = await sampled;
  expect(w.at(-1)![1], 'speaking').toBe(1);
  for (let i = 1; i < w.length; i++) expect(w[i][1] - w[i - 1][1], `rise at ${w[i][0].toFixed(0)} ms`).toBeLessThanOrEqual((w[i][0] - w[Math.max(0, i - 2)][0] + 5) / 120);
  await page.emulateMedia({ reducedMotion: 'no-preference' });
  await expect.poll(idle, { timeout: 10_000 }).not.toBeNull();

  const status = await page.locator('#status').evaluate((s) => ({ shown: s.clientHeight, needed: s.scrollHeight }));
  expect(status.needed, 'the status line is not cut short').toBeLessThanOrEqual(status.shown + 1);
});

test('<talking-face>: the face turns and zooms by keyboard; screen readers hear states, not progress, with hide-status too', async ({ page }) => {
  test.setTimeout(120_000);
  await page.emulateMedia({ reducedMotion: 'reduce' });
  await page.goto('/examples/embed.html');
  await page.evaluate(WATCH_LIVE);
  await page.evaluate(() => document.getElementById('left')!.setAttribute('hide-status', ''));
  await page.evaluate(() => (document.getElementById('left') as unknown as { ready: Promise<unknown> }).ready);
  const camera = () => page.evaluate(() => {
    const v = (document.getElementById('left') as unknown as { stage: { view: { camera: { position: { x: number; y: number; z: number } } } } }).stage.view;
    const p = v.camera.position;
    return [p.x, p.y, p.z];
  });
  await expect.poll(async () => (await camera()).length, { timeout: 30_000 }).toBe(3);
  const before = await camera();
  await page.locator('#left canvas').focus();
  await page.keyboard.press('ArrowLeft');
  await page.keyboard.press('+');
  const after = await camera();
  expect(Math.hypot(after[0] - before[0], after[1] - before[1], after[2] - before[2]), 'the camera moved').toBeGreaterThan(0.05);
  expect(await page.locator('#left canvas').getAttribute('aria-label')).toContain('Arrow keys orbit');

  // Speak a clip long enough to be animated in several chunks: the status line shows progress, the announcer does not.
  const { samples, rate } = speechSamples();
  const long = new Float32Array(rate * 12);
  for (let o = 0; o < long.length; o += samples.length) long.set(samples.subarray(0, Math.min(samples.length, long.length - o)), o);
  const bytes = [...wav([long], rate)];
  await page.evaluate((b) => {
    const w = globalThis as unknown as { announced: string[]; progress: string[] };
    [w.announced, w.progress] = [[], []];
    const root = document.getElementById('left')!.shadowRoot!;
    new MutationObserver(() => w.announced.push(root.querySelector('.announce')!.textContent!)).observe(root.querySelector('.announce')!, { childList: true, characterData: true, subtree: true });
    new MutationObserver(() => w.progress.push(root.querySelector('.status')!.textContent!)).observe(root.querySelector('.status')!, { childList: true, characterData: true, subtree: true });
    void (document.getElementById('left') as unknown as { speak(a: Blob): Promise<void> }).speak(new Blob([new Uint8Array(b)], { type: 'audio/wav' }));
  }, bytes);
  await expect.poll(() => page.evaluate(() => (globalThis as unknown as { announced: string[] }).announced.some((a) => a.startsWith('Playing'))), { timeout: 60_000 }).toBe(true);
  const { announced, progress } = await page.evaluate(() => {
    const w = globalThis as unknown as { announced: string[]; progress: string[] };
    return { announced: w.announced, progress: w.progress };
  });
  console.log(`announced: ${announced.join(' | ')}`);
  expect(progress.some((p) => /frame \d+ of/.test(p)), 'the status line showed progress').toBe(true);
  expect(announced.some((a) => /frame \d+ of/.test(a)), 'no progress announced').toBe(false);
  const ax = await page.locator('#left').ariaSnapshot();
  expect(ax, 'the announcer stays in the accessibility tree under hide-status').toContain('status');
  const spoke = Object.keys(await liveChanges(page));
  // The page's own live regions (the element's are in its shadow root, watched above): the frame counters are not.
  expect(spoke.filter((k) => k !== 'log'), 'no live region of the page but its event log').toEqual([]);
});

test('<talking-face>: focus stays on the face when it is shown after loading; the page names each face', async ({ page }) => {
  test.setTimeout(90_000);
  await page.goto('/examples/embed.html', { waitUntil: 'domcontentloaded' });
  await page.evaluate(() => customElements.whenDefined('talking-face'));
  const status = () => page.evaluate(() => document.getElementById('left')!.shadowRoot!.querySelector('.status')!.textContent);
  expect(await status()).toContain('Loading');
  await page.locator('#left canvas').focus();
  await expect.poll(status, { timeout: 60_000 }).toContain('Ready');
  const focused = () => page.evaluate(() => {
    const host = document.activeElement as HTMLElement | null;
    return `${host?.id}/${host?.shadowRoot?.activeElement?.tagName ?? ''}`;
  });
  expect(await focused(), 'the new canvas took the focus of the one it replaced').toBe('left/CANVAS');
  const before = await page.locator('#left canvas').getAttribute('aria-label');
  expect(before).toMatch(/^Left face\. .*Arrow keys orbit/);
  expect(await page.locator('#right canvas').getAttribute('aria-label')).toMatch(/^Right face\. /);
  // The element is a group (its ElementInternals' default role), named by the page: as Chromium's tree has it
  // (Playwright's own snapshot computes roles from the DOM alone and does not see an element's internals).
  const cdp = await page.context().newCDPSession(page);
  const { nodes } = (await cdp.send('Accessibility.getFullAXTree')) as { nodes: { role?: { value: string }; name?: { value: string } }[] };
  expect(nodes.filter((n) => n.name?.value === 'Left face').map((n) => n.role?.value)).toEqual(['group']);
});
