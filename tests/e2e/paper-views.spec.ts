import { test, expect, imageStats } from './fixtures';
import { FPS, speechSamples, wav } from './helpers/audio';

/**
 * What the paper shows, on a sample clip of the test split with its ground truth: error heat map (Fig. 5),
 * side by side with the ground truth, pose arrows (Fig. 1), attention maps (Fig. 7, Fig. 10); and the
 * exports (.glb re-loaded with three.js; raw frames).
 */
type TF = {
  take: { name: string; animation: { frames: number; fps: number }; truth?: { frames: number } } | null;
  view: { scene: { getObjectByName(n: string): unknown } };
  exportGlb(): Promise<{ bytes: ArrayBuffer; frames: number; encoding: string; morphTargets: number; maxErrorMm: number }>;
  inspectGlb(b: ArrayBuffer): Promise<{ morphTargets: number; targetNames: string[]; weightRange: [number, number]; clips: number; duration: number; vertices: number; parts: string[]; animated: string[]; heightM: number }>;
};
/** Vertices of the whole head's skin buffer (face, then shell and mouth cavity): what the .glb's morphed mesh holds. */
const headVertices = (page: import('@playwright/test').Page) =>
  page.evaluate(() => (globalThis as unknown as { talkingFace: { view: { model: { vertices: Float32Array } } } }).talkingFace.view.model.vertices.length / 3);

test('sample clip: heat map, side by side, pose arrows, attention maps, exports', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(page.locator('#sample-select option')).toHaveCount(4); // "choose…" + the three samples
  const first = await page.locator('#sample-select option').nth(1).getAttribute('value');
  await page.locator('#sample-select').selectOption(first!);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#details')).toContainText(/E_vl on this clip: \d+\.\d\d mm/);
  const take = await page.evaluate(() => ({ frames: (globalThis as unknown as { talkingFace: TF }).talkingFace.take!.animation.frames, truth: (globalThis as unknown as { talkingFace: TF }).talkingFace.take!.truth?.frames }));
  expect(Math.abs(take.frames - take.truth!)).toBeLessThanOrEqual(1);

  // Error heat map (Fig. 5).
  const plain = await imageStats(page, await page.locator('#face-canvas').screenshot());
  await page.locator('#paint-select').selectOption('error');
  await expect(page.locator('#legend')).toContainText('5 mm');
  const heat = await imageStats(page, await page.locator('#face-canvas').screenshot());
  expect(heat.foregroundFraction).toBeGreaterThan(0.15);
  expect(heat.distinctColours).not.toBe(plain.distinctColours);

  // Side by side with the ground truth.
  await page.locator('#side-check').check();
  await expect(page.locator('#gt-view')).toBeVisible();
  await page.locator('#scrub').fill('40');
  const gt = await imageStats(page, await page.locator('#gt-canvas').screenshot());
  expect(gt.foregroundFraction).toBeGreaterThan(0.1);
  await test.info().attach('side-by-side.png', { body: await page.locator('#stage').screenshot(), contentType: 'image/png' });

  // Pose arrows (Fig. 1).
  await page.locator('#arrows-check').check();
  expect(await page.evaluate(() => Boolean((globalThis as unknown as { talkingFace: TF }).talkingFace.view.scene.getObjectByName('pose_arrow_template')))).toBe(true);

  // Attention maps (Fig. 7, Fig. 10), for the paused frame.
  await page.locator('#paint-select').selectOption('pose-attention');
  await expect(page.locator('body')).toHaveAttribute('data-painted', 'pose-attention', { timeout: 30_000 });
  await expect(page.locator('#legend')).toContainText('Fig. 7');
  await page.locator('#paint-select').selectOption('vertex-attention');
  await expect(page.locator('body')).toHaveAttribute('data-painted', 'vertex-attention', { timeout: 30_000 });
  const box = (await page.locator('#face-canvas').boundingBox())!;
  await page.mouse.click(box.x + box.width / 2, box.y + box.height * 0.45);
  await expect(page.locator('#legend')).toContainText(/Vertex \d+'s attention over itself and its \d+ neighbours/);
  // Chosen while the take plays, an attention map waits for a paused frame, and is drawn when it is paused.
  await page.locator('#paint-select').selectOption('none');
  await page.evaluate(() => delete document.body.dataset.painted);
  await page.locator('#loop-check').check(); // so that it is still playing when paused below
  await page.locator('#play-button').click();
  await expect(page.locator('#play-button')).toHaveText('Pause');
  await page.locator('#paint-select').selectOption('pose-attention');
  await expect(page.locator('#legend')).toContainText('pause or scrub');
  await page.locator('#play-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-painted', 'pose-attention', { timeout: 30_000 });
  await test.info().attach('attention.png', { body: await page.locator('#stage').screenshot(), contentType: 'image/png' });

  // .glb: re-loads in three.js with the whole head, one morph target per frame and the clip's duration.
  const glb = await page.evaluate(async () => {
    const g = await (globalThis as unknown as { talkingFace: TF }).talkingFace.exportGlb();
    return { frames: g.frames, encoding: g.encoding, info: await (globalThis as unknown as { talkingFace: TF }).talkingFace.inspectGlb(g.bytes) };
  });
  expect(glb.frames).toBe(take.frames);
  expect(glb.encoding).toBe('per-frame');
  expect(glb.info.morphTargets).toBe(take.frames);
  expect(glb.info.targetNames.slice(0, 2)).toEqual(['frame_0', 'frame_1']);
  expect(glb.info.weightRange).toEqual([0, 1]);
  expect(glb.info.clips).toBe(1);
  expect(glb.info.vertices).toBe(await headVertices(page));
  expect(glb.info.vertices).toBeGreaterThan(468);
  expect(glb.info.duration).toBeCloseTo((take.frames - 1) / FPS, 3);
  expect(glb.info.heightM, 'life-size in metres, glTF\'s unit').toBeGreaterThan(0.2);
  expect(glb.info.heightM).toBeLessThan(1);
  // The new parts are there and animated: the head pose, the face, the jaw (lower teeth, tongue), the tongue's raise, the gaze.
  expect(glb.info.parts).toEqual(expect.arrayContaining(['talking-face', 'face', 'neck', 'eye_left', 'eye_right', 'teeth_upper', 'jaw_lower', 'teeth_lower', 'tongue']));
  expect(glb.info.animated.sort()).toEqual(['eye_left', 'eye_right', 'face', 'jaw_lower', 'talking-face', 'tongue']);

  // Raw frames: float32 frames x N x 3.
  const [download] = await Promise.all([page.waitForEvent('download'), page.locator('#export-raw').click()]);
  expect(download.suggestedFilename()).toBe(`${first}.${take.frames}x468x3.f32`);
  const path = await download.path();
  const { statSync } = await import('node:fs');
  expect(statSync(path!).size).toBe(take.frames * 468 * 3 * 4);

  // A file has no ground truth: the pane goes (it showed the sample's truth, frozen) and the status says why.
  await page.locator('#file-input').setInputFiles({ name: 'speech.wav', mimeType: 'audio/wav', buffer: wav([speechSamples().samples], speechSamples().rate) });
  await page.waitForFunction(() => (globalThis as unknown as { talkingFace: TF }).talkingFace.take?.name === 'speech.wav', null, { timeout: 60_000 });
  await expect(page.locator('#gt-view')).toBeHidden();
  await page.locator('#side-check').uncheck();
  await page.locator('#side-check').check();
  await expect(page.locator('#status')).toContainText('Side by side needs a sample clip');
  await expect(page.locator('#gt-view')).toBeHidden();
});

test('a clip longer than a minute exports whole as a compact .glb: 8 directions of motion, weights within 0..1, the deviation measured', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const { samples, rate } = speechSamples();
  const long = new Float32Array(rate * 70); // 70 s: 2,100 frames, past the per-frame encoding's 300 (and long enough to cancel)
  for (let o = 0; o < long.length; o += samples.length + rate / 4) long.set(samples.subarray(0, Math.min(samples.length, long.length - o)), o);
  await page.locator('#file-input').setInputFiles({ name: 'seventy.wav', mimeType: 'audio/wav', buffer: wav([long], rate) });
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 150_000 });
  const frames = await page.evaluate(() => (globalThis as unknown as { talkingFace: TF }).talkingFace.take!.animation.frames);
  expect(frames).toBeGreaterThan(300);
  const glb = await page.evaluate(async () => {
    const g = await (globalThis as unknown as { talkingFace: TF }).talkingFace.exportGlb();
    return { ...g, bytes: g.bytes.byteLength, info: await (globalThis as unknown as { talkingFace: TF }).talkingFace.inspectGlb(g.bytes) };
  });
  console.log(`70 s clip: ${glb.frames} frames as ${glb.morphTargets} morph targets, ${(glb.bytes / 1e6).toFixed(2)} MB, largest deviation ${glb.maxErrorMm.toFixed(3)} mm`);
  expect(glb.frames).toBe(frames);
  expect(glb.encoding).toBe('components');
  // Eight directions of motion, each a target per side, weighted within 0..1 (Blender keeps shape keys there).
  expect(glb.info.morphTargets).toBe(16);
  expect(glb.info.targetNames.slice(0, 3)).toEqual(['motion_1_plus', 'motion_1_minus', 'motion_2_plus']);
  expect(glb.info.weightRange[0]).toBe(0);
  expect(glb.info.weightRange[1]).toBeCloseTo(1, 6);
  expect(glb.info.vertices).toBe(await headVertices(page));
  expect(glb.info.duration).toBeCloseTo((frames - 1) / FPS, 3);
  expect(glb.bytes).toBeLessThan(2e6); // per-frame targets would be ~100 MB
  expect(glb.maxErrorMm).toBeLessThan(1); // a millimetre at most anywhere on the face, on any frame
  // The page says what it did (after a progress it shows while the page stays live: seconds of work, more on a busy machine).
  const first = page.waitForEvent('download', { timeout: 90_000 });
  await page.locator('#export-glb').click();
  await expect(page.locator('#status')).toContainText(/Preparing the \.glb of \d+ frames: \d+%/);
  await expect(page.locator('#details')).toContainText(/16 morph targets with per-frame weights \(largest deviation from the exact frames: \d+\.\d\d mm\)/, { timeout: 90_000 });
  // The browser reports that download on its own time, after the page has said so: wait for it before counting the next.
  expect((await first).suggestedFilename()).toBe('seventy.glb');
  // Escape cancels one being prepared: nothing is saved, and the page says so.
  const saved: string[] = [];
  page.on('download', (d) => saved.push(d.suggestedFilename()));
  await page.locator('#export-glb').click();
  await expect(page.locator('#status')).toContainText(/Preparing the \.glb of \d+ frames: \d+%… \(Escape cancels\)/);
  await page.keyboard.press('Escape');
  await expect(page.locator('#status')).toContainText('Export cancelled.');
  expect(saved).toEqual([]);
});

test('Pose arrows and Loop ticked while the face loads are applied once it is there (no error meanwhile)', async ({ page }) => {
  await page.addInitScript(() => document.addEventListener('DOMContentLoaded', () => {
    for (const id of ['arrows-check', 'loop-check']) { // ticked by the visitor before the face was drawn
      const box = document.getElementById(id) as HTMLInputElement;
      box.checked = true;
      box.dispatchEvent(new Event('change'));
    }
  }));
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const arrows = await page.evaluate(() => Boolean((globalThis as unknown as { talkingFace: { view: { arrows: unknown } } }).talkingFace.view.arrows));
  expect(arrows, 'the pose arrows drawn').toBe(true);
  // Looping: the short clip is still playing well after its length.
  await page.locator('#file-input').setInputFiles({ name: 'short.wav', mimeType: 'audio/wav', buffer: (({ samples, rate }) => wav([samples.subarray(0, rate)], rate))(speechSamples()) });
  await expect(page.locator('#play-button')).toHaveText('Pause', { timeout: 60_000 });
  await page.waitForTimeout(2500);
  await expect(page.locator('#play-button')).toHaveText('Pause');
});
