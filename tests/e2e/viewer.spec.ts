import { test, expect, imageStats } from './fixtures';
import { reportGpuRenderer } from '../../playwright.config';

test.describe('the face viewer', () => {
  test.beforeEach(async ({ page }) => {
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-ready', 'true');
  });

  test('renders the shaded face filling a sensible part of the frame', async ({ page }) => {
    const canvas = page.locator('#face-canvas');
    // (Without the "Prediction" caption, which sits over the canvas's corner: the box and centre are the face's own.)
    const shot = await canvas.screenshot({ style: '.view figcaption { visibility: hidden; }' });
    const s = await imageStats(page, shot);
    // A shaded face, not a flat fill: many colours, and it covers 15-85% of the canvas, roughly centred.
    expect(s.distinctColours).toBeGreaterThan(50);
    expect(s.foregroundFraction).toBeGreaterThan(0.15);
    expect(s.foregroundFraction).toBeLessThan(0.85);
    const cx = (s.box.x0 + s.box.x1) / 2;
    const cy = (s.box.y0 + s.box.y1) / 2;
    expect(Math.abs(cx - 0.5)).toBeLessThan(0.15);
    expect(Math.abs(cy - 0.5)).toBeLessThan(0.15);
    await test.info().attach('viewer.png', { body: shot, contentType: 'image/png' });
  });

  test('zoom stops before the camera enters the head and before the head is a speck (a pinch has no other way back)', async ({ page }) => {
    const canvas = page.locator('#face-canvas');
    const shown = async () => (await imageStats(page, await canvas.screenshot({ style: '.view figcaption { visibility: hidden; }' }))).foregroundFraction;
    // The camera's distance from what it looks at, in face heights (chin to forehead, about 20 cm).
    const distance = () => page.evaluate(() => {
      const v = (globalThis as unknown as { talkingFace: { view: { camera: { position: { distanceTo(t: unknown): number } }; controls: { target: unknown }; model: { measures: { top: number; chin: number } } } } }).talkingFace.view;
      return v.camera.position.distanceTo(v.controls.target) / (v.model.measures.top - v.model.measures.chin);
    });
    await canvas.focus();
    for (let i = 0; i < 40; i++) await page.keyboard.press('+');
    const [near, nearShown] = [await distance(), await shown()];
    for (let i = 0; i < 80; i++) await page.keyboard.press('-');
    const [far, farShown] = [await distance(), await shown()];
    console.log(`zoomed in all the way: ${near.toFixed(2)} face heights away, the face covers ${(100 * nearShown).toFixed(0)}%; out: ${far.toFixed(1)}, ${(100 * farShown).toFixed(1)}%`);
    expect(near, 'zoomed in all the way: outside the head').toBeGreaterThanOrEqual(1.19);
    expect(far).toBeLessThanOrEqual(8.01);
    expect(farShown, 'zoomed out all the way: the face is still there to see').toBeGreaterThan(0.02);
  });

  test('draws without multisampling where WebGL is software, with it where the renderer is a GPU', async ({ page }) => {
    // Here WebGL is SwiftShader: the canvas's context was made without antialias (src/render/software-gl.ts).
    const antialias = () => document.querySelector<HTMLCanvasElement>('#face-canvas')!.getContext('webgl2')!.getContextAttributes()!.antialias;
    expect(await page.evaluate(antialias)).toBe(false);
    // The same page where the browser names a GPU as its renderer: multisampled, as before.
    await page.addInitScript(reportGpuRenderer);
    await page.reload();
    await expect(page.locator('body')).toHaveAttribute('data-ready', 'true');
    expect(await page.evaluate(antialias)).toBe(true);
  });

  test('finds the WebGPU adapter and says so in the details', async ({ page }) => {
    const gpu = await page.evaluate(() => {
      const g = (globalThis as unknown as { talkingFace: { gpu: { available: boolean; info: { architecture: string } | null } } }).talkingFace.gpu;
      return { available: g.available, architecture: g.info?.architecture };
    });
    expect(gpu.available).toBe(true);
    expect(gpu.architecture).toBe('swiftshader');
    await expect(page.locator('#details')).toContainText('WebGPU adapter: google swiftshader');
  });

  test('draws a whole head: skull and neck around the face, eyes, teeth, tongue, the mouth inside', async ({ page }) => {
    const names = await page.evaluate(() => {
      const v = (globalThis as unknown as { talkingFace: { view: { head: { traverse(f: (o: { name: string }) => void): void } } } }).talkingFace.view;
      const all: string[] = [];
      v.head.traverse((o) => all.push(o.name));
      return all;
    });
    expect(names).toEqual(expect.arrayContaining(['face', 'neck', 'eye_left', 'eye_right', 'eyeball_left', 'teeth_upper', 'jaw_lower', 'teeth_lower', 'tongue']));
  });

  test('follows the window size', async ({ page }) => {
    await page.setViewportSize({ width: 420, height: 800 });
    await expect
      .poll(() => page.evaluate(() => (document.getElementById('face-canvas') as HTMLCanvasElement).width))
      .toBeLessThanOrEqual(420 * 2);
    // The face is redrawn on the next animation frame, which can wait while the model loads.
    await expect.poll(async () => (await imageStats(page, await page.locator('#face-canvas').screenshot())).foregroundFraction).toBeGreaterThan(0.1);
  });
});

test('at phone width every control is reachable without sideways scrolling, and by keyboard', async ({ page }) => {
  await page.setViewportSize({ width: 375, height: 740 });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  expect(await page.evaluate(() => document.documentElement.scrollWidth)).toBeLessThanOrEqual(375);
  for (const id of ['#record-button', '#sample-select', '#play-button', '#scrub', '#paint-select', '#export-video', '#export-glb']) {
    const box = (await page.locator(id).boundingBox())!;
    expect(box.x, id).toBeGreaterThanOrEqual(0);
    expect(box.x + box.width, id).toBeLessThanOrEqual(376);
  }
  // Every control has an accessible name.
  const unnamed = await page.evaluate(() => Array.from(document.querySelectorAll('button, input, select')).filter((el) => {
    const e = el as HTMLInputElement;
    return !(e.labels?.length || e.getAttribute('aria-label') || e.textContent?.trim());
  }).map((el) => el.id));
  expect(unnamed).toEqual([]);
  // Keyboard: tab reaches the record button and Enter presses it (no microphone here: a message, not a hang).
  await page.locator('#file-input').focus();
  await page.keyboard.press('Tab');
  await expect(page.locator('#record-button')).toBeFocused();
  await page.keyboard.press('Enter');
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'error', { timeout: 20_000 });
  expect((await imageStats(page, await page.locator('#face-canvas').screenshot())).foregroundFraction).toBeGreaterThan(0.1);
});

test('on a phone on its side the face leaves room below it: a swipe there scrolls to the controls (one on the face orbits it)', async ({ page }) => {
  await page.setViewportSize({ width: 667, height: 375 });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-ready', 'true');
  const canvas = (await page.locator('#face-canvas').boundingBox())!;
  expect(canvas.y + canvas.height, 'the face ends above the fold, with room under it').toBeLessThan(0.8 * 375);
  await expect(page.locator('#timeline')).toBeInViewport();
});

test('reports a missing template in the page instead of a blank screen', async ({ page, guard }) => {
  guard.allowConsoleError(/404|could not load the face template/i);
  await page.route('**/models/template/template.json', (route) => route.fulfill({ status: 404, body: 'gone' }));
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-ready', 'error');
  await expect(page.locator('#status')).toContainText('could not load the face template');
});
