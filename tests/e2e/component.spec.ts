import { resolve } from 'node:path';
import { test, expect, imageStats } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { framesOf } from './helpers/audio';

/**
 * <talking-face> from the library build in a plain HTML page (examples/embed.html): two instances at
 * once, one speaking a file while the other animates the (fake) microphone; events; a bad model URL.
 */
const WAV = resolve(import.meta.dirname, '../fixtures/speech-kal.wav');
test.use({ launchOptions: fakeMicrophone(WAV) });

type FaceEl = HTMLElement & { speak(a: string): Promise<void>; startMicrophone(): Promise<void>; stop(): void; currentAnimation: { frames: number } | null; backend: string | null };

test('two instances in a plain page: one speaks a file, the other follows the microphone', async ({ page }) => {
  test.setTimeout(180_000);
  // Record every event before the elements upgrade.
  await page.addInitScript(() => {
    const seen: Record<string, string[]> = {};
    (globalThis as unknown as { faceEvents: typeof seen }).faceEvents = seen;
    for (const type of ['ready', 'frame', 'ended', 'error']) {
      document.addEventListener(type, (e) => {
        const id = (e.target as HTMLElement).id;
        if (!id) return;
        (seen[id] ??= []).push(type === 'frame' ? `frame:${(e as CustomEvent).detail.mode}` : type);
      }, true);
    }
  });
  await page.goto('/examples/embed.html');
  const events = () => page.evaluate(() => (globalThis as unknown as { faceEvents: Record<string, string[]> }).faceEvents);
  await expect.poll(async () => (await events()).left?.includes('ready') && (await events()).right?.includes('ready'), { timeout: 60_000 }).toBe(true);
  expect(await page.locator('#left').evaluate((el) => (el as FaceEl).backend)).toBe('cpu');

  // Both faces are drawn (the canvas lives in each element's shadow root).
  for (const id of ['#left', '#right']) {
    const stats = await imageStats(page, await page.locator(id).screenshot());
    expect(stats.foregroundFraction, `${id} not blank`).toBeGreaterThan(0.1);
  }

  await page.locator('#speak').click();
  await page.locator('#mic').click();
  await expect.poll(async () => (await events()).left?.filter((e) => e === 'frame:playback').length ?? 0, { timeout: 60_000 }).toBeGreaterThan(10);
  await expect.poll(async () => (await events()).right?.filter((e) => e === 'frame:live').length ?? 0, { timeout: 60_000 }).toBeGreaterThan(10);
  const left = await page.locator('#left').evaluate((el) => (el as FaceEl).currentAnimation?.frames ?? 0);
  expect(left).toBe(framesOf(resolve(import.meta.dirname, '../../examples/sample.wav')));
  // Independent: the live instance has no offline animation, and the speaking one got no live frames.
  expect(await page.locator('#right').evaluate((el) => (el as FaceEl).currentAnimation)).toBeNull();
  expect((await events()).left).not.toContain('frame:live');
  await expect.poll(async () => (await events()).left?.includes('ended'), { timeout: 30_000 }).toBe(true);
  await page.locator('#stop').click();
  expect((await events()).left).not.toContain('error');
  expect((await events()).right).not.toContain('error');
});

test('a missing model gives an error event and message, and the page keeps working', async ({ page, guard }) => {
  test.setTimeout(120_000);
  guard.allowConsoleError(/404|Failed to load resource/);
  await page.goto('/examples/embed.html');
  const message = await page.evaluate(() => new Promise<string>((resolve) => {
    const el = document.createElement('talking-face');
    el.setAttribute('model', '/models/no-such-manifest.json');
    el.addEventListener('error', (e) => resolve((e as unknown as CustomEvent).detail.message));
    document.body.append(el);
  }));
  expect(message).toMatch(/model could not be loaded.*no-such-manifest\.json.*404/);
  // The status line inside the element says so too.
  await expect(page.locator('talking-face').last().locator('p.status')).toContainText('could not be loaded');
  // The other instances are unaffected.
  await page.locator('#speak').click();
  await expect.poll(() => page.locator('#left').evaluate((el) => (el as FaceEl).currentAnimation?.frames ?? 0), { timeout: 60_000 }).toBeGreaterThan(0);
});

test('speak() of a file the browser cannot decode rejects with a TalkingFaceError naming what it is; silence is the face at rest', async ({ page }) => {
  test.setTimeout(60_000);
  await page.goto('/examples/embed.html');
  const outcome = await page.evaluate(async () => {
    const el = document.getElementById('left') as HTMLElement & { speak(a: Blob): Promise<void>; stop(): void; currentAnimation: { frames: number } | null;
      ready: Promise<{ times: Record<string, number>; restFace(): Promise<unknown> }> };
    const header = new DataView(new ArrayBuffer(44 + 256));
    [...'RIFF\0\0\0\0WAVEfmt '].forEach((c, i) => header.setUint8(i, c.charCodeAt(0)));
    header.setUint32(16, 16, true);
    header.setUint16(20, 0x11, true); // IMA ADPCM
    header.setUint16(22, 1, true);
    header.setUint32(24, 8000, true);
    header.setUint16(34, 4, true);
    [...'data'].forEach((c, i) => header.setUint8(36 + i, c.charCodeAt(0)));
    header.setUint32(40, 256, true);
    const failed = await el.speak(new Blob([header.buffer])).then(() => null, (e: Error & { stage?: string }) => ({ name: e.name, stage: e.stage, message: e.message }));
    const engine = await el.ready;
    await engine.restFace(); // the face at rest, which the model makes once from a second of silence
    const modelMs = () => engine.times.content + engine.times.decoder;
    const before = modelMs();
    const played = el.speak(new AudioBuffer({ length: 16000 * 20, numberOfChannels: 1, sampleRate: 16000 }) as unknown as Blob);
    await new Promise((r) => el.addEventListener('frame', r, { once: true }));
    el.stop();
    await played;
    return { failed, modelMs: modelMs() - before, frames: el.currentAnimation?.frames, status: el.shadowRoot!.querySelector('p.status')!.textContent };
  });
  expect(outcome.failed).toEqual({ name: 'TalkingFaceError', stage: 'audio', message: expect.stringMatching(/WAV file in IMA ADPCM, which this browser cannot decode: convert it/) });
  expect(outcome.frames).toBe(20 * 30);
  expect(outcome.modelMs, 'the content encoder and the decoder did not run on 20 s of silence').toBe(0);
});

test('in a right-to-left page with its own text styles, the status stays English and readable; hidden hides it', async ({ page }) => {
  test.setTimeout(60_000);
  await page.goto('/examples/embed.html');
  await page.evaluate(() => {
    document.documentElement.lang = 'ar';
    document.documentElement.dir = 'rtl';
    document.body.style.cssText += ';text-transform: uppercase; letter-spacing: .25em; white-space: nowrap; text-indent: 3em';
  });
  await expect(page.locator('#left p.status')).toContainText('Ready', { timeout: 60_000 });
  const status = await page.locator('#left p.status').evaluate((p) => {
    const s = getComputedStyle(p);
    return { lang: (p as HTMLElement).lang, direction: s.direction, textTransform: s.textTransform, letterSpacing: s.letterSpacing, whiteSpace: s.whiteSpace, textIndent: s.textIndent };
  });
  expect(status).toEqual({ lang: 'en', direction: 'ltr', textTransform: 'none', letterSpacing: 'normal', whiteSpace: 'normal', textIndent: '0px' });
  await page.locator('#left').evaluate((el) => ((el as HTMLElement).hidden = true));
  await expect(page.locator('#left')).toBeHidden();
  expect(await page.locator('#left').evaluate((el) => el.getBoundingClientRect().height)).toBe(0);
});

/** The policy docs/embedding.md gives, as a page would send it, on a page whose only script is its own file. */
const CSP = "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'";

test('under the Content-Security-Policy docs/embedding.md gives, the element loads, speaks and follows the microphone', async ({ page, context }) => {
  test.setTimeout(120_000);
  await context.route('**/csp/page.html', (r) => r.fulfill({ contentType: 'text/html', headers: { 'Content-Security-Policy': CSP },
    body: '<!doctype html><html lang="en"><title>CSP</title><body><talking-face id="face"></talking-face><script type="module" src="/csp/page.js"></script>' }));
  await context.route('**/csp/page.js', (r) => r.fulfill({ contentType: 'text/javascript', headers: { 'Content-Security-Policy': CSP },
    body: "globalThis.violations = [];\ndocument.addEventListener('securitypolicyviolation', (e) => globalThis.violations.push(`${e.violatedDirective} ${e.blockedURI}`));\nawait import('/lib/talking-face.js');" }));
  await page.goto('/csp/page.html');
  const face = page.locator('#face');
  await expect(face.locator('p.status')).toContainText('Ready', { timeout: 60_000 });
  expect(await face.evaluate((el) => el.getBoundingClientRect().height), 'its style applies (a <style> element would be refused)').toBeGreaterThan(200);
  expect(await face.evaluate((el) => (el as FaceEl).speak('/examples/sample.wav').then(() => 'spoken', (e: Error) => e.message))).toBe('spoken');
  await face.evaluate((el) => {
    (globalThis as unknown as { live: number }).live = 0;
    el.addEventListener('frame', (e) => ((e as CustomEvent).detail.mode === 'live' && (globalThis as unknown as { live: number }).live++));
    return (el as FaceEl).startMicrophone();
  });
  await expect(face.locator('p.status')).toContainText('Listening', { timeout: 20_000 });
  await expect.poll(() => page.evaluate(() => (globalThis as unknown as { live: number }).live), { timeout: 20_000 }).toBeGreaterThan(3);
  await face.evaluate((el) => (el as FaceEl).stop());
  expect(await page.evaluate(() => (globalThis as unknown as { violations: string[] }).violations)).toEqual([]);
});

test('in a frame not allowed the microphone, startMicrophone() says what the embedding page must add', async ({ page, context }) => {
  test.setTimeout(60_000);
  await context.route('**/frame/outer.html', (r) => r.fulfill({ contentType: 'text/html',
    body: '<!doctype html><html lang="en"><title>outer</title><iframe src="/examples/embed.html" allow="microphone \'none\'" width="800" height="600"></iframe>' }));
  await page.goto('/frame/outer.html');
  const frame = page.frameLocator('iframe');
  await expect(frame.locator('#left p.status')).toContainText('Ready', { timeout: 60_000 });
  const message = await frame.locator('#left').evaluate((el) => (el as FaceEl).startMicrophone().then(() => 'started', (e: Error) => e.message));
  expect(message).toMatch(/in a frame that is not allowed the microphone: the page that embeds it must give its <iframe> allow="microphone"/);
});

test('a policy without \'wasm-unsafe-eval\' on every response: the error says to add it', async ({ page, context, guard }) => {
  test.setTimeout(90_000);
  guard.allowConsoleError(/unsafe-eval|WebAssembly|wasm|Content Security Policy|Aborted|no available backend|could not be loaded/);
  const strict = "default-src 'self'; script-src 'self'";
  await context.route('**/csp/page.html', (r) => r.fulfill({ contentType: 'text/html', headers: { 'Content-Security-Policy': strict },
    body: '<!doctype html><html lang="en"><title>CSP</title><body><talking-face id="face"></talking-face><script type="module" src="/csp/page.js"></script>' }));
  await context.route('**/csp/page.js', (r) => r.fulfill({ contentType: 'text/javascript', headers: { 'Content-Security-Policy': strict },
    body: "globalThis.errors = [];\ndocument.addEventListener('error', (e) => e.detail && globalThis.errors.push(e.detail.message), true);\nawait import('/lib/talking-face.js');" }));
  // The workers' scripts carry the policy too, as from a server that sends it with every response.
  await context.route('**/lib/assets/*.js', async (r) => {
    const res = await r.fetch();
    await r.fulfill({ response: res, headers: { ...res.headers(), 'content-security-policy': strict } });
  });
  await page.goto('/csp/page.html');
  await expect.poll(() => page.evaluate(() => (globalThis as unknown as { errors: string[] }).errors), { timeout: 60_000 })
    .toContainEqual(expect.stringMatching(/Content-Security-Policy does not let onnxruntime compile its WebAssembly: add 'wasm-unsafe-eval' to its script-src/));
});

test('a model replaced while it loads reports nothing of its own failure; the new one is ready', async ({ page, guard }) => {
  test.setTimeout(60_000);
  guard.allowConsoleError(/404|Failed to load resource/);
  await page.goto('/examples/embed.html');
  const seen = await page.evaluate(() => new Promise<string[]>((resolve) => {
    const got: string[] = [];
    const el = document.createElement('talking-face');
    el.setAttribute('model', '/models/no-such-manifest.json');
    el.addEventListener('error', (e) => got.push(`error: ${(e as CustomEvent).detail.message}`));
    el.addEventListener('ready', () => setTimeout(() => resolve([...got, 'ready']), 500));
    document.body.append(el);
    el.setAttribute('model', '/models/manifest.json'); // the page's script sets its own model at once
  }));
  expect(seen).toEqual(['ready']);
});

test('blank model, template and avatar attributes (a template that writes model="{{ url }}" with no url) mean none: the default face is ready', async ({ page }) => {
  test.setTimeout(60_000);
  await page.goto('/examples/embed.html');
  const seen = await page.evaluate(() => new Promise<string[]>((resolve) => {
    const got: string[] = [];
    const el = document.createElement('talking-face');
    for (const name of ['model', 'template', 'avatar']) el.setAttribute(name, '  ');
    el.addEventListener('error', (e) => got.push(`error: ${(e as CustomEvent).detail.message}`));
    el.addEventListener('ready', () => setTimeout(() => resolve([...got, 'ready']), 300));
    document.body.append(el);
  }));
  expect(seen).toEqual(['ready']);
});

test('ready says how many threads the work runs on: onnxruntime\'s only where the page is cross-origin isolated', async ({ page, context }) => {
  test.setTimeout(90_000);
  const threads = () => page.evaluate(() => new Promise<{ isolated: boolean; cores: number; threads: { encoders: number; decoder: number } }>((resolve) => {
    const el = document.createElement('talking-face');
    el.addEventListener('ready', (e) => resolve({ isolated: crossOriginIsolated, cores: navigator.hardwareConcurrency, threads: (e as CustomEvent).detail.threads }));
    document.body.append(el);
  }));
  await page.goto('/examples/embed.html');
  const isolated = await threads();
  expect(isolated.isolated).toBe(true);
  expect(isolated.threads.encoders).toBe(Math.min(4, isolated.cores));
  expect(isolated.threads.decoder).toBeGreaterThanOrEqual(1);
  // The same page without the isolation headers.
  await context.route('**/examples/embed.html', async (r) => {
    const res = await r.fetch();
    const headers = Object.fromEntries(Object.entries(res.headers()).filter(([k]) => !/^cross-origin-(opener|embedder)-policy$/.test(k)));
    await r.fulfill({ response: res, headers });
  });
  await page.goto('/examples/embed.html');
  const plain = await threads();
  expect(plain.isolated).toBe(false);
  expect(plain.threads.encoders).toBe(1);
});

test('backend="cpu" asks the browser for no WebGPU adapter (where there is none, asking logs a warning)', async ({ page }) => {
  await page.addInitScript(() => {
    const g = globalThis as unknown as { adapterRequests: number };
    g.adapterRequests = 0;
    const gpu = navigator.gpu as unknown as { requestAdapter: (...a: unknown[]) => unknown } | undefined;
    if (!gpu) return;
    const request = gpu.requestAdapter.bind(gpu);
    gpu.requestAdapter = (...a: unknown[]) => { g.adapterRequests++; return request(...a); };
  });
  await page.goto('/examples/embed.html');
  const asked = await page.evaluate(() => new Promise<number>((resolve, reject) => {
    document.querySelectorAll('talking-face').forEach((e) => e.remove());
    const el = document.createElement('talking-face');
    el.setAttribute('backend', 'cpu');
    el.addEventListener('ready', () => resolve((globalThis as unknown as { adapterRequests: number }).adapterRequests));
    el.addEventListener('error', (e) => reject(new Error((e as CustomEvent).detail.message)));
    document.body.append(el);
  }));
  expect(await page.evaluate(() => 'gpu' in navigator), 'this browser has WebGPU (the test would prove nothing without)').toBe(true);
  expect(asked).toBe(0);
});
