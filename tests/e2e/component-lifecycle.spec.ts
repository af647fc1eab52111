import { resolve } from 'node:path';
import { test, expect, imageStats } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';

/**
 * <talking-face> told to stop, removed, moved or switched while it works (examples/embed.html): it never opens the
 * microphone or plays after a stop or once removed, stop() cancels an animation under way, one element's backend
 * leaves the others' alone, a moved element goes on as it was, and removed elements give back their WebGL context and
 * (after a while) their engine.
 */
test.use({ launchOptions: fakeMicrophone(resolve(import.meta.dirname, '../fixtures/speech-kal.wav')) });

type FaceEl = HTMLElement & { speak(a: unknown): Promise<void>; startMicrophone(): Promise<void>; stop(): void; currentAnimation: { frames: number } | null; backend: string | null };

/** Every element event by id, and every microphone request, from before the elements upgrade. */
const WATCH = () => {
  const seen: Record<string, string[]> = {};
  const g = globalThis as unknown as { faceEvents: typeof seen; microphoneRequests: number };
  g.faceEvents = seen;
  g.microphoneRequests = 0;
  const getUserMedia = navigator.mediaDevices.getUserMedia.bind(navigator.mediaDevices);
  navigator.mediaDevices.getUserMedia = (c) => {
    g.microphoneRequests++;
    return getUserMedia(c);
  };
  for (const type of ['ready', 'frame', 'ended', 'error']) {
    document.addEventListener(type, (e) => {
      const id = (e.target as HTMLElement).id;
      if (id) (seen[id] ??= []).push(type === 'frame' ? `frame:${(e as CustomEvent).detail.mode}` : type === 'ready' ? `ready:${(e as CustomEvent).detail.backend}` : type);
    }, true);
  }
};

const statusOf = (id: string) => `document.getElementById('${id}').shadowRoot.querySelector('p.status').textContent`;

test('stopped or removed before the model is ready: no microphone, no playback', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(WATCH);
  await page.goto('/examples/embed.html', { waitUntil: 'domcontentloaded' });
  await page.evaluate(() => customElements.whenDefined('talking-face'));
  // While the model loads: ask for the microphone and the sample, then stop both; and add a live element, then remove it.
  expect(await page.evaluate(statusOf('left'))).toContain('Loading');
  await page.evaluate(() => {
    const gone = document.createElement('talking-face');
    gone.id = 'gone';
    gone.setAttribute('live', '');
    document.body.append(gone);
    setTimeout(() => gone.remove(), 200);
  });
  await page.locator('#mic').click();
  await page.locator('#speak').click();
  await page.locator('#stop').click();
  expect(await page.evaluate(statusOf('left')), 'stopped while the model loaded').not.toContain('Ready');
  const events = () => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents);
  await expect.poll(async () => (await events()).left?.some((e) => e.startsWith('ready')) && (await events()).right?.some((e) => e.startsWith('ready')), { timeout: 60_000 }).toBe(true);
  await page.waitForTimeout(3000); // what a lost stop() would have started by now: the capture, the animation, playback
  const seen = await events();
  expect(seen.gone ?? [], 'a removed element sends nothing').toEqual([]);
  expect(seen.left).not.toContain('frame:playback');
  expect(seen.right).not.toContain('frame:live');
  expect(await page.evaluate(() => (globalThis as unknown as { microphoneRequests: number }).microphoneRequests), 'microphone requests').toBe(0);
  expect(await page.evaluate(statusOf('right'))).not.toContain('Listening');
  // Asked again once ready, both work.
  await page.locator('#mic').click();
  await expect.poll(async () => (await events()).right?.filter((e) => e === 'frame:live').length ?? 0, { timeout: 60_000 }).toBeGreaterThan(5);
  await page.locator('#stop').click();
});

test('stop() cancels an animation under way: speak() resolves, the status says so, nothing plays', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(WATCH);
  await page.goto('/examples/embed.html');
  await expect.poll(() => page.evaluate(statusOf('left')), { timeout: 60_000 }).toContain('Ready');
  // Two minutes of a voiced sound (a harmonic series whose loudness comes and goes): seconds of work on two cores.
  const timing = await page.evaluate(async () => {
    const rate = 16000, seconds = 120;
    const buffer = new AudioBuffer({ length: rate * seconds, sampleRate: rate, numberOfChannels: 1 });
    const x = buffer.getChannelData(0);
    for (let i = 0; i < x.length; i++) {
      const t = i / rate;
      x[i] = 0.2 * (0.5 + 0.5 * Math.sin(2 * Math.PI * 3 * t)) * (Math.sin(2 * Math.PI * 140 * t) + 0.5 * Math.sin(2 * Math.PI * 280 * t) + 0.3 * Math.sin(2 * Math.PI * 700 * t));
    }
    const left = document.getElementById('left') as unknown as { speak(a: AudioBuffer): Promise<void>; stop(): void };
    const status = () => document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent!;
    const spoken = left.speak(buffer);
    while (!status().startsWith('Animating')) await new Promise((r) => setTimeout(r, 50));
    const stoppedAt = performance.now();
    left.stop();
    await spoken;
    return { resolvedAfterMs: performance.now() - stoppedAt, status: status() };
  });
  expect(timing.resolvedAfterMs, 'speak() resolves soon after stop()').toBeLessThan(3000);
  expect(timing.status).toBe('Stopped.');
  await page.waitForTimeout(1000);
  expect(await page.locator('#left').evaluate((el) => (el as FaceEl).currentAnimation)).toBeNull();
  expect((await page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents)).left).not.toContain('frame:playback');
});

test('a call that fails beside a speak() under way leaves stop() able to cancel it; removing `live` stops the microphone, not a speak() begun since', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(WATCH);
  await page.goto('/examples/embed.html');
  await expect.poll(() => page.evaluate(statusOf('left')), { timeout: 60_000 }).toContain('Ready');
  const timing = await page.evaluate(async () => {
    const rate = 16000, seconds = 120; // seconds of work on two cores (as above)
    const buffer = new AudioBuffer({ length: rate * seconds, sampleRate: rate, numberOfChannels: 1 });
    const x = buffer.getChannelData(0);
    for (let i = 0; i < x.length; i++) x[i] = 0.2 * Math.sin(2 * Math.PI * 3 * i / rate) * Math.sin(2 * Math.PI * 140 * i / rate);
    const left = document.getElementById('left') as unknown as { speak(a: AudioBuffer): Promise<void>; stop(): void; recordVideo(): Promise<Blob> };
    const status = () => document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent!;
    const spoken = left.speak(buffer);
    while (!status().startsWith('Animating')) await new Promise((r) => setTimeout(r, 50));
    const refused = await left.recordVideo().then(() => 'made', (e: Error) => e.message); // no take yet: it fails, and says so
    const stoppedAt = performance.now();
    left.stop();
    await spoken;
    return { refused, resolvedAfterMs: performance.now() - stoppedAt, status: status() };
  });
  expect(timing.refused).toContain('there is no take to record');
  expect(timing.resolvedAfterMs, 'speak() resolves soon after stop()').toBeLessThan(3000);
  expect(timing.status).toBe('Stopped.');

  // Listening; then, as a framework does for a button that says "speak this instead": speak(), then `live` removed.
  await page.locator('#right').evaluate((el) => el.setAttribute('live', ''));
  await expect.poll(() => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents.right?.filter((e) => e === 'frame:live').length ?? 0), { timeout: 30_000 }).toBeGreaterThan(3);
  const spoke = await page.locator('#right').evaluate(async (el) => {
    const face = el as unknown as { speak(a: string): Promise<void> };
    const spoken = face.speak('/examples/sample.wav');
    el.removeAttribute('live');
    let frames = 0;
    el.addEventListener('frame', (e) => { if ((e as CustomEvent).detail.mode === 'playback') frames++; });
    await spoken;
    return frames;
  });
  expect(spoke, 'the speak() played').toBeGreaterThan(10);
  expect(await page.evaluate(statusOf('right'))).toMatch(/^Played/);
});

test('stop() during speak(url)\'s download ends it: speak() resolves at once, not when the download would', async ({ page }) => {
  test.setTimeout(60_000);
  await page.route('**/examples/slow-speech.wav', () => undefined); // never answered (a slow host)
  await page.goto('/examples/embed.html');
  await expect.poll(() => page.evaluate(statusOf('left')), { timeout: 60_000 }).toContain('Ready');
  const stopped = await page.evaluate(async () => {
    const left = document.getElementById('left') as unknown as { speak(a: string): Promise<void>; stop(): void };
    const spoken = left.speak('/examples/slow-speech.wav');
    await new Promise((r) => setTimeout(r, 500));
    const t0 = performance.now();
    left.stop();
    await spoken;
    return { ms: performance.now() - t0, status: document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent };
  });
  expect(stopped.ms).toBeLessThan(1000);
  expect(stopped.status).toBe('Stopped.');
});

test('one element\'s backend attribute leaves the others\' engines alone; a bad value warns and means auto', async ({ page }) => {
  test.setTimeout(180_000);
  await page.addInitScript(WATCH);
  const warnings: string[] = [];
  page.on('console', (m) => m.type() === 'warning' && warnings.push(m.text()));
  await page.goto('/examples/embed.html');
  const events = () => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents);
  await expect.poll(async () => (await events()).right?.includes('ready:cpu'), { timeout: 60_000 }).toBe(true);
  await page.locator('#left').evaluate((el) => el.setAttribute('backend', 'webgpu'));
  await expect.poll(async () => (await events()).left?.includes('ready:webgpu'), { timeout: 60_000 }).toBe(true);
  expect(await page.locator('#left').evaluate((el) => (el as FaceEl).backend)).toBe('webgpu');
  expect(await page.locator('#right').evaluate((el) => (el as FaceEl).backend), 'the other element').toBe('cpu');
  // Unknown: a warning, and auto (the CPU decoder, the WebGPU adapter here being software).
  await page.locator('#left').evaluate((el) => el.setAttribute('backend', 'gpu'));
  await expect.poll(() => warnings.some((w) => w.includes('backend="gpu"')), { timeout: 10_000 }).toBe(true);
  await expect.poll(() => page.locator('#left').evaluate((el) => (el as FaceEl).backend), { timeout: 60_000 }).toBe('cpu');
  // Still speaks.
  await page.locator('#speak').click();
  await expect.poll(async () => (await events()).left?.filter((e) => e === 'frame:playback').length ?? 0, { timeout: 60_000 }).toBeGreaterThan(5);
});

test('an element moved in the page (removed and put back at once) goes on: no new load, playback not cut, no WebGL errors', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(WATCH);
  const gl: string[] = [];
  page.on('console', (m) => /WebGL|GL_INVALID/.test(m.text()) && !/GPU stall due to ReadPixels/.test(m.text()) && gl.push(m.text()));
  await page.goto('/examples/embed.html');
  const events = () => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents);
  await expect.poll(async () => (await events()).left?.filter((e) => e.startsWith('ready')).length, { timeout: 60_000 }).toBe(1);
  await page.evaluate(() => document.body.append(document.getElementById('left')!));
  await page.locator('#speak').click();
  await expect.poll(async () => (await events()).left?.filter((e) => e === 'frame:playback').length ?? 0, { timeout: 60_000 }).toBeGreaterThan(0);
  // Moved while it plays: it plays on to its end (frames come at the page's frame rate: a few a second on a loaded machine with software WebGL).
  await page.evaluate(() => document.querySelector('.pair')!.prepend(document.getElementById('left')!));
  await expect.poll(async () => (await events()).left?.filter((e) => e === 'ended').length ?? 0, { timeout: 60_000 }).toBe(1);
  expect((await events()).left?.filter((e) => e === 'frame:playback').length).toBeGreaterThan(2);
  expect((await events()).left?.filter((e) => e.startsWith('ready')), 'moved twice, loaded once').toHaveLength(1);
  expect(await page.evaluate(statusOf('left'))).toMatch(/^Played \(\d+ frames, /);
  const stats = await imageStats(page, await page.locator('#left').screenshot());
  expect(stats.foregroundFraction, 'the moved face is drawn').toBeGreaterThan(0.1);
  expect(gl, 'WebGL messages').toEqual([]);
  // Attributes that mean what is loaded load nothing again (an empty model is the default one, as absent).
  await page.evaluate(() => document.getElementById('left')!.setAttribute('model', ''));
  await page.waitForTimeout(1_000);
  expect((await events()).left?.filter((e) => e.startsWith('ready'))).toHaveLength(1);
  // Changed while out of the page, in the same task as the move (a framework re-parenting it): loaded as changed.
  await page.evaluate(() => {
    const left = document.getElementById('left')!;
    left.remove();
    left.setAttribute('avatar', '/examples/avatars/arkit-face.glb');
    document.querySelector('.pair')!.prepend(left);
  });
  await expect.poll(async () => (await events()).left?.filter((e) => e.startsWith('ready')).length, { timeout: 60_000 }).toBe(2);
  expect(await page.locator('#left').evaluate((el) => (el as unknown as { avatar: { summary: { scheme: string } } | null }).avatar?.summary.scheme)).toBe('arkit');
});

test('removed from the page, the elements free their engine (onnxruntime\'s worker, the decoder workers); put back, they load again', async ({ page }) => {
  test.setTimeout(150_000);
  await page.addInitScript(WATCH);
  await page.goto('/examples/embed.html');
  const events = () => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents);
  const readies = async (id: string) => (await events())[id]?.filter((e) => e.startsWith('ready')).length ?? 0;
  await expect.poll(async () => (await readies('left')) + (await readies('right')), { timeout: 60_000 }).toBe(2);
  const names = () => page.workers().map((w) => w.url().replace(/^.*\/assets\//, ''));
  const working = names().length;
  expect(working, `the engine's workers: ${names().join(', ')}`).toBeGreaterThanOrEqual(2);
  // Moved (removed and put back at once): the same engine, nothing loaded again.
  await page.evaluate(() => document.body.append(document.getElementById('right')!));
  await page.waitForTimeout(1_000);
  expect(await readies('right')).toBe(1);
  expect(names().length).toBe(working);
  // Both removed: after the engine's linger (ENGINE_LINGER_MS, 10 s) every worker it started has ended.
  await page.evaluate(() => {
    const g = globalThis as unknown as { parked: HTMLElement[] };
    g.parked = ['left', 'right'].map((id) => document.getElementById(id)!);
    for (const el of g.parked) el.remove();
  });
  // A removed element's late calls (a route gone, its speech service answering after): refused at once, saying why;
  // they neither open the microphone nor keep the engine.
  await page.waitForTimeout(2_000);
  const late = await page.evaluate(async () => {
    const [left, right] = (globalThis as unknown as { parked: (HTMLElement & { speak(a: string): Promise<void>; startMicrophone(): Promise<void> })[] }).parked;
    const t0 = performance.now();
    const spoke = await left.speak('/examples/sample.wav').then(() => 'spoke', (e: Error) => e.message);
    const listened = await right.startMicrophone().then(() => 'listening', (e: Error) => e.message);
    return { spoke, listened, ms: performance.now() - t0, asked: (globalThis as unknown as { microphoneRequests: number }).microphoneRequests };
  });
  expect(late.spoke).toBe('there is no face to show it on (is the element in the page?)');
  expect(late.listened).toBe('there is no face to show it on (is the element in the page?)');
  expect(late.asked, 'no microphone opened for a removed element').toBe(0);
  expect(late.ms, 'refused before any animating').toBeLessThan(2_000);
  await page.waitForTimeout(3_000);
  expect(names().length, 'kept a while (an element put back soon takes it back)').toBe(working);
  await expect.poll(() => names().length, { timeout: 30_000, message: `workers left: ${names().join(', ')}` }).toBe(0);
  // Put back: loads again, and speaks.
  await page.evaluate(() => document.querySelector('.pair')!.append(...(globalThis as unknown as { parked: HTMLElement[] }).parked));
  await expect.poll(async () => (await readies('left')) + (await readies('right')), { timeout: 60_000 }).toBe(4);
  await page.locator('#speak').click();
  await expect.poll(async () => (await events()).left?.filter((e) => e === 'ended').length ?? 0, { timeout: 60_000 }).toBe(1);
  expect((await events()).left).not.toContain('error'); // (the late call's was sent while out of the page: not seen here)
});

test('removed elements give their WebGL context back at once: 18 shown and removed, held by the page, none evicted', async ({ page }) => {
  test.setTimeout(180_000);
  await page.addInitScript(WATCH);
  const warnings: string[] = [];
  page.on('console', (m) => /Too many active WebGL contexts/.test(m.text()) && warnings.push(m.text()));
  await page.goto('/examples/embed.html');
  const events = () => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents);
  await expect.poll(async () => (await events()).left?.filter((e) => e.startsWith('ready')).length, { timeout: 60_000 }).toBe(1);
  for (let i = 0; i < 18; i++) {
    // Kept by the page (a route cache, a framework's reference) after it is removed: only dispose frees its context.
    await page.evaluate((id) => {
      const g = globalThis as unknown as { kept?: HTMLElement[] };
      const el = document.createElement('talking-face');
      el.id = id;
      el.setAttribute('backend', 'cpu');
      (g.kept ??= []).push(el);
      document.body.append(el);
    }, `kept${i}`);
    await expect.poll(async () => (await events())[`kept${i}`]?.filter((e) => e.startsWith('ready')).length ?? 0, { timeout: 30_000 }).toBe(1);
    await page.evaluate((id) => document.getElementById(id)!.remove(), `kept${i}`);
  }
  await page.waitForTimeout(1_000);
  expect(warnings, 'contexts evicted').toEqual([]);
  const seen = await events();
  expect(Object.entries(seen).filter(([, e]) => e.some((x) => x === 'error')), 'error events').toEqual([]);
  // The elements on the page still draw.
  expect((await imageStats(page, await page.locator('#left').screenshot())).foregroundFraction).toBeGreaterThan(0.1);
});

test('src set while the model loads is spoken once it is in; a clip played to its end says so', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(WATCH);
  await page.goto('/examples/embed.html', { waitUntil: 'domcontentloaded' });
  await page.evaluate(() => customElements.whenDefined('talking-face'));
  expect(await page.evaluate(statusOf('left'))).toContain('Loading');
  await page.evaluate(() => document.getElementById('left')!.setAttribute('src', '/examples/sample.wav'));
  const events = () => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents);
  await expect.poll(async () => (await events()).left?.filter((e) => e === 'ended').length ?? 0, { timeout: 90_000 }).toBe(1);
  const seen = (await events()).left!;
  expect(seen.filter((e) => e.startsWith('ready'))).toHaveLength(1);
  expect(seen).toContain('frame:playback');
  expect(seen).not.toContain('error');
  expect(await page.evaluate(statusOf('left'))).toMatch(/^Played \(\d+ frames, /);
});
