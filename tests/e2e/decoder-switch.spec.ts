import { resolve } from 'node:path';
import { test, expect } from './fixtures';
import { framesOf } from './helpers/audio';

/**
 * The demo's Decoder menu changed while a clip is being animated on WebGPU (SwiftShader here, slow enough to change
 * it mid-way): the chunks left go to the CPU decoder and the take is whole; nothing fails.
 */
const SPEECH = resolve(import.meta.dirname, '../fixtures/speech-kal.wav');

test('switching to the CPU decoder during a WebGPU animation finishes the take', async ({ page }) => {
  test.setTimeout(180_000);
  const warnings: string[] = [];
  page.on('console', (m) => m.type() === 'warning' && warnings.push(m.text()));
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const status = page.locator('#status');
  await page.locator('#backend-select').selectOption('webgpu');
  await expect(status).toContainText('Decoding on the WebGPU decoder from now on', { timeout: 60_000 });
  await page.locator('#file-input').setInputFiles(SPEECH);
  // Its first chunk takes the WebGPU decoder tens of seconds here (software); the menu changes while it runs.
  await expect(status).toContainText('speech-kal.wav', { timeout: 30_000 });
  await page.waitForTimeout(3000);
  await expect(page.locator('body')).not.toHaveAttribute('data-take', /./);
  await page.locator('#backend-select').selectOption('cpu');
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 120_000 });
  const take = await page.evaluate(() => {
    const t = (globalThis as unknown as { talkingFace: { take: { animation: { frames: number; pose: Float32Array } } } }).talkingFace.take;
    return { frames: t.animation.frames, finite: t.animation.pose.every(Number.isFinite) };
  });
  expect(take.frames).toBe(framesOf(SPEECH));
  expect(take.finite).toBe(true);
  await expect(status).not.toContainText('Could not');
  // The WebGPU decoder is destroyed once its batch under way is done, not under it.
  expect(warnings.filter((w) => /destroyed/.test(w)), 'WebGPU warnings').toEqual([]);
});

test('a decoder that cannot be used is said, and the menu goes back to the one still decoding', async ({ page }) => {
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const select = page.locator('#backend-select');
  await select.selectOption('cpu');
  await expect(page.locator('#status')).toContainText('Decoding on the CPU decoder from now on');
  await page.evaluate(() => { // as where the WebGPU device cannot be had
    const engine = (globalThis as unknown as { talkingFace: { engine: { setBackend: () => Promise<void> } } }).talkingFace.engine;
    engine.setBackend = () => Promise.reject(new Error('the WebGPU device could not be created'));
  });
  await select.selectOption('webgpu');
  await expect(page.locator('#status')).toContainText('Cannot use webgpu: the WebGPU device could not be created');
  await expect(select).toHaveValue('cpu');
});

test('of two quick choices, the later one is what the menu and the status line say', async ({ page }) => {
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.evaluate(() => { // WebGPU slow to set up, and failing at last: its answer comes after the CPU's
    const engine = (globalThis as unknown as { talkingFace: { engine: { setBackend: (b: string) => Promise<void> } } }).talkingFace.engine;
    const real = engine.setBackend.bind(engine);
    engine.setBackend = (b) => b === 'webgpu'
      ? new Promise((_, reject) => setTimeout(() => reject(new Error('too slow')), 800)) : real(b);
  });
  const select = page.locator('#backend-select');
  await select.selectOption('webgpu');
  await select.selectOption('cpu');
  await expect(page.locator('#status')).toContainText('Decoding on the CPU decoder from now on');
  await page.waitForTimeout(1200); // past the WebGPU answer
  await expect(page.locator('#status')).toContainText('Decoding on the CPU decoder from now on');
  await expect(select).toHaveValue('cpu');
});
