import { test, expect } from './fixtures';

/**
 * <talking-face> when its files do not arrive (examples/embed.html): a model whose load failed (onnxruntime's runtime
 * not downloaded; a model file's connection dropped) loads on the next speak() once the network is back, and shows
 * its face; the errors name the file; a face whose WebGL context the browser takes (16 a page) says so; the demo
 * served without its sample clips does not offer them.
 */
type El = HTMLElement & { speak(a: unknown): Promise<void>; ready: Promise<unknown> };

const events = (page: import('@playwright/test').Page) => page.evaluate(() => (globalThis as unknown as { seen: string[] }).seen);

for (const [fault, pattern] of [['the runtime (.wasm) is not found', '**/ort/*/ort-wasm-simd-threaded.wasm'], ['a model file\'s connection drops', '**/models/gava.safetensors']] as const) {
  test(`${fault}: an error naming it, then the next speak() loads the model and plays`, async ({ page, context, guard }) => {
    test.setTimeout(120_000);
    // What the browser logs of the failed download (onnxruntime's wasm loader; the failed fetch).
    guard.allowConsoleError(/wasm|WebAssembly|magic word|Aborted\(|ArrayBuffer instantiation|Failed to load resource|ERR_CONNECTION_RESET|net::/);
    await context.route(pattern, (r) => (pattern.endsWith('.wasm') ? r.fulfill({ status: 404, body: 'not here' }) : r.abort('connectionreset')));
    await page.addInitScript(() => {
      const g = globalThis as unknown as { seen: string[] };
      g.seen = [];
      for (const type of ['ready', 'error', 'ended']) {
        document.addEventListener(type, (e) => (e.target as HTMLElement).id === 'left' && g.seen.push(`${type}${type === 'error' ? `:${(e as CustomEvent).detail.stage}:${(e as CustomEvent).detail.message}` : ''}`), true);
      }
    });
    await page.goto('/examples/embed.html');
    await expect.poll(() => events(page), { timeout: 60_000 }).toContainEqual(expect.stringMatching(/^error:model:/));
    const [error] = (await events(page)).filter((e) => e.startsWith('error'));
    expect(error).toMatch(pattern.endsWith('.wasm') ? /ort-wasm/ : /gava\.safetensors/);
    // The parts that did load (ONNX sessions, the decoder's workers) are freed: nothing of the failed load runs on.
    const running = () => page.workers().map((w) => w.url()).filter((u) => /onnx-worker|decoder-worker/.test(u));
    await expect.poll(running, { timeout: 10_000 }).toEqual([]);
    await context.unrouteAll({ behavior: 'ignoreErrors' });
    const spoke = await page.evaluate(() => (document.getElementById('left') as El).speak('/examples/sample.wav').then(() => 'played', (e: Error) => `failed: ${e.message}`));
    expect(spoke).toBe('played');
    const seen = await events(page);
    expect(seen.filter((e) => e === 'ready'), 'ready once the retry loaded').toHaveLength(1);
    expect(seen.at(-1)).toBe('ended');
  });
}

test('a face whose WebGL context the browser takes says so, and again when it is given back, drawn again even at rest', async ({ page, guard }) => {
  test.setTimeout(60_000);
  guard.allowConsoleError(/WebGL|CONTEXT_LOST/);
  // An avatar held still at rest (no blinks): nothing but the restore asks for a frame. Its draw calls are counted
  // (a restored context's drawing buffer is blank until drawn; this headless browser may still show the old one).
  await page.emulateMedia({ reducedMotion: 'reduce' });
  await page.addInitScript(() => {
    const g = globalThis as unknown as { draws: number };
    g.draws = 0;
    const draw = WebGL2RenderingContext.prototype.drawElements;
    WebGL2RenderingContext.prototype.drawElements = function (...args: Parameters<typeof draw>) { g.draws++; return draw.apply(this, args); };
    document.addEventListener('DOMContentLoaded', () => document.getElementById('left')!.setAttribute('avatar', '/examples/avatars/arkit-face.glb'));
  });
  await page.goto('/examples/embed.html');
  await page.evaluate(() => (document.getElementById('left') as El).ready);
  const status = () => page.evaluate(() => document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent);
  await expect.poll(status, { timeout: 30_000 }).toContain('Ready');
  const errors = page.evaluate(() => new Promise<string>((resolve) => document.getElementById('left')!.addEventListener('error', (e) => resolve((e as unknown as CustomEvent).detail.stage), { once: true })));
  const draws = () => page.evaluate(() => (globalThis as unknown as { draws: number }).draws);
  await page.waitForTimeout(1000);
  const atRest = await draws();
  await page.evaluate(() => {
    const gl = document.getElementById('left')!.shadowRoot!.querySelector('canvas')!.getContext('webgl2')!;
    const ext = gl.getExtension('WEBGL_lose_context')!;
    ext.loseContext();
    setTimeout(() => ext.restoreContext(), 500);
  });
  expect(await errors).toBe('render');
  expect(await draws(), 'nothing drawn at rest before the loss').toBe(atRest);
  await expect.poll(status, { timeout: 10_000 }).toBe('The face is drawn again.');
  await expect.poll(draws, { timeout: 2_000, message: 'the avatar is drawn again once the context is back' }).toBeGreaterThan(atRest);
});

test('the demo\'s face whose WebGL context the browser takes says so, and again when it is given back', async ({ page, guard }) => {
  test.setTimeout(60_000);
  guard.allowConsoleError(/WebGL|CONTEXT_LOST/);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-rest', 'shown', { timeout: 60_000 });
  await page.evaluate(() => {
    const ext = (document.getElementById('face-canvas') as HTMLCanvasElement).getContext('webgl2')!.getExtension('WEBGL_lose_context')!;
    ext.loseContext();
    setTimeout(() => ext.restoreContext(), 1000);
  });
  await expect(page.locator('#status')).toContainText('The face can no longer be drawn', { timeout: 5_000 });
  await expect(page.locator('#status')).toHaveText('The face is drawn again.', { timeout: 10_000 });
});

for (const where of ['its worker', 'the page (no Web Workers)', 'the page (its WebGPU build)'] as const) {
  test(`onnxruntime's runtime download brings nothing, in ${where}: the load fails after stallSeconds, naming it, instead of loading forever`, async ({ page, context }) => {
    test.setTimeout(90_000);
    if (where === 'the page (no Web Workers)') await page.addInitScript(() => Object.defineProperty(globalThis, 'Worker', { value: undefined }));
    const webgpu = where === 'the page (its WebGPU build)';
    await context.route(`**/ort/*/ort-wasm-simd-threaded${webgpu ? '.jsep' : ''}.wasm`, () => undefined); // never answered
    await page.goto(`/dev/ort-start.html?stallSeconds=2${webgpu ? '&providers=webgpu' : ''}`);
    await expect(page.locator('body')).toHaveAttribute('data-engine', 'error', { timeout: 45_000 });
    expect(await page.locator('body').getAttribute('data-error')).toMatch(/ort-wasm.*nothing arrived for 2 s/s);
  });
}

test('onnxruntime\'s WebGPU build not served (28 MB, more than some hosts allow a file): the encoders load on the wasm provider', async ({ page, context, guard }) => {
  test.setTimeout(90_000);
  guard.allowConsoleError(/404|Failed to load resource/);
  let asked = 0;
  await context.route('**/ort/*/ort-wasm-simd-threaded.jsep.wasm', (r) => (asked++, r.fulfill({ status: 404, body: 'not here' })));
  const warnings: string[] = [];
  page.on('console', (m) => m.type() === 'warning' && warnings.push(m.text()));
  await page.goto('/dev/ort-start.html?providers=webgpu,wasm');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 45_000 });
  expect(warnings.join('\n')).toMatch(/the webgpu provider failed \(onnxruntime's runtime .*jsep\.wasm could not be downloaded \(HTTP 404/);
  expect(asked, 'asked for once, not again by each of the four sessions').toBe(1);
});

test('the demo served without sample clips offers only what there is', async ({ page, context, guard }) => {
  test.setTimeout(60_000);
  guard.allowConsoleError(/Failed to load resource/);
  await context.route('**/models/samples/index.json', (r) => r.fulfill({ status: 404, body: 'not here' }));
  await page.goto('/');
  await expect(page.locator('#status')).toHaveText('Ready: open or drop an audio file, or press Record.', { timeout: 60_000 });
  await expect(page.locator('#sample-select')).toBeDisabled();
  await expect(page.locator('#sample-select')).toHaveAttribute('title', 'No sample clips: HTTP 404');
});

test('the demo\'s sample whose download hangs: Escape stops it at once, and another sample opens', async ({ page, context }) => {
  test.setTimeout(90_000);
  let hung = '';
  await context.route('**/models/samples/*.wav', (route) => (hung === '' || route.request().url().endsWith(hung)
    ? (hung ||= route.request().url().split('/').pop()!, undefined) : route.continue())); // the first clip's audio never comes
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const options = page.locator('#sample-select option');
  await page.locator('#sample-select').selectOption((await options.nth(1).getAttribute('value'))!);
  await expect(page.locator('#status')).toContainText('Loading the sample');
  await page.waitForTimeout(500);
  await page.keyboard.press('Escape');
  await expect(page.locator('#status')).toContainText('Stopped animating the sample', { timeout: 2_000 });
  // The menu goes back to what is shown (no take yet): choosing that sample again would be a choice, not nothing.
  await expect(page.locator('#sample-select')).toHaveValue('');
  await page.locator('#sample-select').selectOption((await options.nth(2).getAttribute('value'))!);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
});

test('the library finds its workers beside itself (lib/assets/), not at the site root where only the demo has copies', async ({ page, context }) => {
  test.setTimeout(60_000);
  // Deployed as docs/embedding.md says: lib/, models/ and ort/, no /assets/ at the root.
  await context.route((url) => url.pathname.startsWith('/assets/'), (r) => r.fulfill({ status: 404, body: 'not deployed' }));
  await page.goto('/examples/embed.html');
  const ready = await page.evaluate(() => (document.getElementById('left') as HTMLElement & { ready: Promise<{ backendReason: string }> })
    .ready.then((engine) => engine.backendReason));
  expect(ready).not.toMatch(/failed to load/);
  const workers = page.workers().map((w) => new URL(w.url()).pathname);
  expect(workers.some((p) => p.startsWith('/lib/assets/decoder-worker-')), workers.join(', ')).toBe(true);
  expect(workers.some((p) => p.startsWith('/lib/assets/onnx-worker-')), workers.join(', ')).toBe(true);
});
