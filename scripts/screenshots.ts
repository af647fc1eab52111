/**
 * npm run screenshots: the demo's main views, rendered in headless Chromium (SwiftShader WebGL), saved
 * to docs/screenshots/. Builds the app and serves it like the tests do (on port 4192, or SCREENSHOTS_PORT).
 */
import { chromium, type Page } from '@playwright/test';
import { spawn, execSync } from 'node:child_process';
import { mkdirSync } from 'node:fs';
import { resolve } from 'node:path';
import { fakeMicrophone } from '../playwright.config';

const ROOT = resolve(import.meta.dirname, '..');
const OUT = resolve(ROOT, 'docs/screenshots');
const PORT = Number(process.env.SCREENSHOTS_PORT ?? 4192);
const URL_ = `http://127.0.0.1:${PORT}`;

async function ready(page: Page, attr: string, value: string): Promise<void> {
  await page.waitForSelector(`body[data-${attr}="${value}"]`, { timeout: 120_000 });
}

async function main(): Promise<void> {
  execSync('npm run --silent build', { cwd: ROOT, stdio: 'inherit' });
  const server = spawn('npx', ['vite', 'preview', '--host', '127.0.0.1', '--port', String(PORT), '--strictPort'], { cwd: ROOT, stdio: 'ignore', detached: true });
  mkdirSync(OUT, { recursive: true });
  try {
    for (let i = 0; ; i++) {
      try {
        if ((await fetch(`${URL_}/`)).ok) break;
      } catch {
        if (i > 100) throw new Error('the preview server did not start');
        await new Promise((r) => setTimeout(r, 200));
      }
    }
    const wav = resolve(ROOT, 'tests/fixtures/speech-kal.wav');
    const browser = await chromium.launch(fakeMicrophone(wav));
    const page = await browser.newPage({ viewport: { width: 1100, height: 760 } });
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

    const live = await browser.newPage({ viewport: { width: 1100, height: 760 } });
    await live.goto(`${URL_}/`);
    await ready(live, 'engine', 'ready');
    await live.locator('#record-button').click();
    await ready(live, 'recording', 'true');
    await live.waitForTimeout(2000);
    await live.screenshot({ path: resolve(OUT, 'recording.png') });
    await live.locator('#record-button').click();
    await ready(live, 'take', 'ready');

    const phone = await browser.newPage({ viewport: { width: 375, height: 740 } });
    await phone.goto(`${URL_}/`);
    await ready(phone, 'engine', 'ready');
    await phone.screenshot({ path: resolve(OUT, 'phone.png'), fullPage: true });

    const embed = await browser.newPage({ viewport: { width: 1000, height: 640 } });
    await embed.goto(`${URL_}/examples/embed.html`);
    await embed.waitForFunction(() => document.getElementById('log')?.textContent?.includes('ready'), null, { timeout: 120_000 });
    await embed.locator('#speak').click();
    await embed.waitForTimeout(1500);
    await embed.screenshot({ path: resolve(OUT, 'embed.png') });
    await browser.close();
    console.log(`screenshots written to ${OUT}`);
  } finally {
    try {
      process.kill(-server.pid!);
    } catch {
      /* already gone */
    }
  }
}

main().catch((e) => {
  console.error(`screenshots: ${(e as Error).message}`);
  process.exit(1);
});
