/**
 * npm run screenshots: the demo's main views, rendered in headless Chromium (SwiftShader WebGL), saved
 * to docs/screenshots/. Builds the app and serves it like the tests do (on port 4192, or SCREENSHOTS_PORT).
 * The head: front, three-quarter and profile at rest, the mouth open on a vowel, the lips closed on /m/, idle.
 */
import { chromium, type Browser, type Page } from '@playwright/test';
import { execSync } from 'node:child_process';
import { mkdirSync } from 'node:fs';
import { resolve } from 'node:path';
import { fakeMicrophone, reportGpuRenderer } from '../playwright.config';
import { envPort, portFree, readOptions, startServer } from './script-cli';

const ROOT = resolve(import.meta.dirname, '..');
const OUT = resolve(ROOT, 'docs/screenshots');
const USAGE = `npm run screenshots   the demo's main views and the head, in headless Chromium -> docs/screenshots/
  SCREENSHOTS_PORT=N      serve the build on port N (default 4192; it must be free)`;
readOptions('screenshots', USAGE, {}); // --help, or a stray option refused before anything is built
const PORT = envPort('screenshots', USAGE, 'SCREENSHOTS_PORT', 4192);
const URL_ = `http://127.0.0.1:${PORT}`;

async function ready(page: Page, attr: string, value: string): Promise<void> {
  await page.waitForSelector(`body[data-${attr}="${value}"]`, { timeout: 120_000 });
}

/** Choose a sample clip in the demo and wait for its take (a no-op when it is the one shown). */
async function showSample(page: Page, sample: string): Promise<void> {
  if ((await page.locator('#sample-select').inputValue()) === sample) return;
  await page.evaluate(() => { delete document.body.dataset.take; });
  await page.locator('#sample-select').selectOption(sample);
  await ready(page, 'take', 'ready');
}

/** Put the demo's camera at `azimuth` (radians about the target, 0 = front) at `distance` times its current distance; aim at y. */
async function orbit(page: Page, azimuth: number, distance: number, aimY?: number): Promise<void> {
  await page.evaluate(`(() => {
    const v = globalThis.talkingFace.view;
    const t = v.controls.target, c = v.camera.position;
    if (${aimY ?? 'null'} !== null) t.y = ${aimY ?? 0};
    const d = c.distanceTo(t) * ${distance};
    c.set(t.x + d * Math.sin(${azimuth}), t.y + d * 0.04, t.z + d * Math.cos(${azimuth}));
    v.controls.update();
    v.requestRender();
  })()`);
  await page.waitForTimeout(500);
}

/** A page of the given size whose views draw as on a GPU, multisampled (playwright.config.ts, reportGpuRenderer). */
async function newPage(browser: Browser, width: number, height: number): Promise<Page> {
  const page = await browser.newPage({ viewport: { width, height } });
  await page.addInitScript(reportGpuRenderer);
  return page;
}

/** The whole head: three angles at rest, idle, an open vowel and a closure on /m/ (a sample clip's frames). */
async function headViews(browser: Browser): Promise<void> {
  const page = await newPage(browser, 760, 980);
  await page.goto(`${URL_}/`);
  await ready(page, 'rest', 'shown');
  await page.waitForTimeout(1500);
  await page.screenshot({ path: resolve(OUT, 'idle.png') });
  const canvas = page.locator('#face-canvas');
  await canvas.screenshot({ path: resolve(OUT, 'head-front.png') });
  await orbit(page, 0.7, 1);
  await canvas.screenshot({ path: resolve(OUT, 'head-three-quarter.png') });
  await orbit(page, Math.PI / 2, 1);
  await canvas.screenshot({ path: resolve(OUT, 'head-profile.png') });
  // Each sample clip's widest-open frame heard as a vowel and most closed frame heard as /p b m/ (the inner-lip gap
  // as training measures it: src/template/lip-gap.ts, which the demo publishes); the vowel from the first clip, the
  // closure from the clip that closes most (the sample clips differ: one /p/ the model misses).
  const measure = async () => (await page.evaluate(`(() => {
    const tf = globalThis.talkingFace, a = tf.take.animation, r = tf.template.regions, names = tf.engine.manifest.content_phones;
    const gaps = tf.innerLipGaps(a.unposed, a.frames, a.unposed.length / a.frames / 3,
      Uint32Array.from(r.lips_inner_upper), Uint32Array.from(r.lips_inner_lower));
    const gap = (f) => gaps[f];
    let vowel = 0, m = -1;
    for (let f = 0; f < a.frames; f++) {
      const p = names[a.phones[f]];
      if (/^(AA|AE|AH|AO|AW|AY|EH|ER|EY|IH|IY|OW|OY|UH|UW)$/.test(p) && gap(f) > gap(vowel)) vowel = f;
      if (/^(P|B|M)$/.test(p) && (m < 0 || gap(f) < gap(m))) m = f;
    }
    return { vowel, m, mGap: m < 0 ? null : gap(m) / tf.engine.unitsPerMm };
  })()`)) as { vowel: number; m: number; mGap: number | null };
  const options = await page.locator('#sample-select option').evaluateAll((os) => os.map((o) => (o as HTMLOptionElement).value).filter(Boolean));
  let vowel: { sample: string; frame: number } | null = null;
  let closure: { sample: string; frame: number; gap: number } | null = null;
  for (const sample of options) {
    await showSample(page, sample);
    const f = await measure();
    vowel ??= { sample, frame: f.vowel };
    if (f.m >= 0 && (closure === null || f.mGap! < closure.gap)) closure = { sample, frame: f.m, gap: f.mGap! };
  }
  if (!vowel || !closure) throw new Error('the sample clips have no vowel or no /p b m/ frame');
  console.log(`mouth-m.png: ${closure.sample} frame ${closure.frame}, inner-lip gap ${closure.gap.toFixed(2)} mm`);
  const mouthY = await page.evaluate(`(() => { const t = globalThis.talkingFace.template, r = t.regions.lips_outer; return Array.from(r).reduce((s, v) => s + t.positions[3 * v + 1], 0) / r.length; })()`) as number;
  await orbit(page, 0.25, 0.45, mouthY);
  for (const [name, { sample, frame }] of [['mouth-vowel.png', vowel], ['mouth-m.png', closure]] as const) {
    await showSample(page, sample);
    await page.locator('#scrub').fill(String(frame));
    await page.waitForTimeout(800); // the speech blend
    await canvas.screenshot({ path: resolve(OUT, name) });
  }
  await page.close();
}

async function main(): Promise<void> {
  // Another server on the port would be photographed instead of this build.
  if (!(await portFree(PORT))) throw new Error(`port ${PORT} is in use: free it, or set SCREENSHOTS_PORT`);
  execSync('npm run --silent build', { cwd: ROOT, stdio: 'inherit' });
  const server = startServer('npx', ['vite', 'preview', '--host', '127.0.0.1', '--port', String(PORT), '--strictPort'], ROOT);
  mkdirSync(OUT, { recursive: true });
  try {
    await server.ready(`${URL_}/`);
    const wav = resolve(ROOT, 'tests/fixtures/speech-kal.wav');
    const browser = await chromium.launch(fakeMicrophone(wav));
    await headViews(browser);
    const page = await newPage(browser, 1100, 760);
    await page.goto(`${URL_}/`);
    await ready(page, 'engine', 'ready');
    const sample = (await page.locator('#sample-select option').nth(1).getAttribute('value'))!;
    await page.locator('#sample-select').selectOption(sample);
    await ready(page, 'take', 'ready');
    await page.locator('#scrub').fill('45');
    await page.screenshot({ path: resolve(OUT, 'sample.png') });
    await page.locator('#timeline').screenshot({ path: resolve(OUT, 'timeline.png') });
    // The status line and, opened, the details under it (the decoder, the take's figures, E_vl).
    await page.locator('#details summary').click();
    await page.screenshot({ path: resolve(OUT, 'details.png') });
    await page.locator('#details summary').click();
    await page.locator('#side-check').check();
    await page.locator('#arrows-check').check();
    await page.locator('#paint-select').selectOption('error');
    await page.waitForTimeout(300);
    await page.screenshot({ path: resolve(OUT, 'error-side-by-side.png') });
    await page.locator('#paint-select').selectOption('pose-attention');
    await ready(page, 'painted', 'pose-attention');
    await page.waitForTimeout(300);
    await page.screenshot({ path: resolve(OUT, 'pose-attention.png') });
    await page.locator('#side-check').uncheck();
    await page.locator('#paint-select').selectOption('vertex-attention');
    await ready(page, 'painted', 'vertex-attention');
    await page.waitForTimeout(300);
    await page.screenshot({ path: resolve(OUT, 'vertex-attention.png') });
    await page.close(); // each page closed once taken: every open page redraws its idle face on the same CPU

    const live = await newPage(browser, 1100, 760);
    await live.goto(`${URL_}/`);
    await ready(live, 'engine', 'ready');
    await live.locator('#record-button').click();
    await ready(live, 'recording', 'true');
    await live.waitForTimeout(2000);
    await live.screenshot({ path: resolve(OUT, 'recording.png') });
    await live.locator('#record-button').click();
    await ready(live, 'take', 'ready');
    await live.close();

    const phone = await newPage(browser, 375, 740);
    await phone.goto(`${URL_}/`);
    await ready(phone, 'engine', 'ready');
    await phone.screenshot({ path: resolve(OUT, 'phone.png') }); // what a phone shows first: the status line stays at its bottom as the page scrolls
    await phone.close();

    const embed = await newPage(browser, 1000, 640);
    await embed.goto(`${URL_}/examples/embed.html`);
    await embed.waitForFunction(() => document.getElementById('log')?.textContent?.includes('ready'), null, { timeout: 120_000 });
    await embed.locator('#speak').click();
    await embed.waitForTimeout(1500);
    await embed.screenshot({ path: resolve(OUT, 'embed.png') });
    await browser.close();
    console.log(`screenshots written to ${OUT}`);
  } finally {
    server.stop();
  }
}

main().catch((e) => {
  console.error(`screenshots: ${(e as Error).message}`);
  process.exit(1);
});
