import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { test, expect } from './fixtures';
import { SPEECH, FPS } from './helpers/audio';

/**
 * <talking-face avatar="....vrm"> with the project's VRM test avatars (examples/avatars/, npm run make-avatars:
 * VRoid's morph-target names, which only the file's VRM extension ties to the mouth): the element binds the vowel
 * and blink expressions and the humanoid head; the mouth opens on the open vowels of tests/fixtures/speech-kal.wav
 * and closes on /p b m/; it goes back to rest; a VRM 0.x avatar (made facing -z) is turned to the camera unless
 * avatar-facing says otherwise.
 */
type Phone = [string, number, number];
const PHONES: Phone[] = JSON.parse(readFileSync(resolve(import.meta.dirname, '../fixtures/speech-kal.phones.json'), 'utf8')).phones;
const OPEN_VOWELS = new Set(['AA', 'AE', 'AH', 'AO', 'AW', 'AY']);
const BILABIALS = new Set(['P', 'B', 'M']);
const MOUTH = ['Fcl_MTH_A', 'Fcl_MTH_I', 'Fcl_MTH_U', 'Fcl_MTH_E', 'Fcl_MTH_O'];
const mean = (a: number[]) => a.reduce((s, x) => s + x, 0) / a.length;

/** Per segment of `set`: the frames whose instant lies in it. */
function segments(set: Set<string>, frames: number): number[][] {
  return PHONES.filter(([p]) => set.has(p)).map(([, s, e]) => {
    const out: number[] = [];
    for (let f = Math.ceil(s * FPS); f < e * FPS && f < frames; f++) out.push(f);
    return out;
  }).filter((seg) => seg.length > 0);
}

type Mesh = { name: string; morphTargetDictionary?: Record<string, number>; morphTargetInfluences?: number[] };
type FaceEl = HTMLElement & {
  speak(a: Blob): Promise<void>;
  currentAnimation: { frames: number; blendshapes: { arkit: Float32Array; visemes: Float32Array } } | null;
  avatar: { gltf: { scene: { traverse(f: (o: unknown) => void): void } }; setWeights(a: Float32Array, i: number, v: Float32Array, j: number): void } | null;
};

/** Add a <talking-face> with `avatar` (and avatar-facing, if given) to the page, resolving with its ready detail's avatar. */
const add = (page: import('@playwright/test').Page, avatar: string, facing: string | null = null) => page.evaluate(([a, f]) => new Promise<unknown>((resolve, reject) => {
  document.querySelectorAll('talking-face').forEach((e) => e.remove());
  const el = document.createElement('talking-face');
  Object.assign(el.style, { width: '320px', height: '320px', display: 'block' });
  el.setAttribute('backend', 'cpu');
  el.setAttribute('hide-status', '');
  el.setAttribute('avatar', a);
  if (f) el.setAttribute('avatar-facing', f);
  el.addEventListener('ready', (e) => setTimeout(() => resolve((e as CustomEvent).detail.avatar), 500)); // the rest drawn
  el.addEventListener('error', (e) => reject(new Error((e as CustomEvent).detail.message)));
  document.body.prepend(el);
}), [avatar, facing] as const);

/** The avatar's face's mouth influences now (its last primitive's). */
const mouthNow = (page: import('@playwright/test').Page) => page.evaluate((names) => {
  let face: Mesh | null = null;
  (document.querySelector('talking-face') as FaceEl).avatar!.gltf.scene.traverse((o) => { if ((o as Mesh).morphTargetDictionary?.[names[0]] !== undefined) face = o as Mesh; });
  const m = face as unknown as Mesh;
  return names.map((n) => m.morphTargetInfluences![m.morphTargetDictionary![n]]);
}, MOUTH);

test('a VRM avatar speaks through its vowel expressions: open on open vowels, closed on /p b m/, at rest after', async ({ page }) => {
  test.setTimeout(180_000);
  await page.emulateMedia({ reducedMotion: 'reduce' });
  await page.goto('/examples/embed.html');
  expect(await add(page, '/examples/avatars/vrm1-face.vrm')).toEqual({ scheme: 'vrm', matched: ['aa', 'ih', 'ou', 'ee', 'oh', 'blinkLeft', 'blinkRight'], headBone: 'Head' });
  expect(await mouthNow(page)).toEqual([0, 0, 0, 0, 0]);

  // Watch the mouth while the sample plays: the widest opening seen.
  await page.evaluate((names) => {
    const w = globalThis as unknown as { widest: number };
    w.widest = 0;
    const meshes: Mesh[] = [];
    (document.querySelector('talking-face') as FaceEl).avatar!.gltf.scene.traverse((o) => { if ((o as Mesh).morphTargetDictionary?.[names[0]] !== undefined) meshes.push(o as Mesh); });
    const watch = () => {
      for (const m of meshes) w.widest = Math.max(w.widest, names.reduce((s, n) => s + m.morphTargetInfluences![m.morphTargetDictionary![n]], 0));
      requestAnimationFrame(watch);
    };
    watch();
  }, MOUTH);
  const wav = readFileSync(SPEECH).toString('base64');
  await page.evaluate((b64) => (document.querySelector('talking-face') as FaceEl).speak(new Blob([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], { type: 'audio/wav' })), wav);
  expect(await page.evaluate(() => (globalThis as unknown as { widest: number }).widest)).toBeGreaterThan(0.3);
  // Back at rest: the mouth closed (the face at rest has no visemes).
  await expect.poll(async () => Math.max(...(await mouthNow(page))), { timeout: 5_000 }).toBeLessThan(1e-6);

  // Frame by frame, the take's weights through the page's avatar: how far the mouth opens.
  const opening = await page.evaluate((names) => {
    const el = document.querySelector('talking-face') as FaceEl;
    const { frames, blendshapes: b } = el.currentAnimation!;
    const meshes: Mesh[] = [];
    el.avatar!.gltf.scene.traverse((o) => { if ((o as Mesh).morphTargetDictionary?.[names[0]] !== undefined) meshes.push(o as Mesh); });
    const m = meshes[meshes.length - 1]; // (the face's second primitive: each is driven)
    const out: number[] = [];
    for (let f = 0; f < frames; f++) {
      el.avatar!.setWeights(b.arkit, f * 52, b.visemes, f * 15);
      out.push(names.reduce((s, n) => s + m.morphTargetInfluences![m.morphTargetDictionary![n]], 0));
    }
    return out;
  }, MOUTH);
  const open = segments(OPEN_VOWELS, opening.length), closed = segments(BILABIALS, opening.length);
  expect(open.length).toBeGreaterThanOrEqual(5);
  expect(closed.length).toBeGreaterThanOrEqual(5);
  const onOpen = mean(open.flat().map((f) => opening[f]));
  const closedMinima = closed.map((seg) => Math.min(...seg.map((f) => opening[f])));
  expect(onOpen, 'the open vowels open the mouth').toBeGreaterThan(0.4);
  expect(mean(closedMinima), `each /p b m/'s most closed frame: ${closedMinima.map((x) => x.toFixed(2))}; open vowels ${onOpen.toFixed(2)}`).toBeLessThan(0.3 * onOpen);
});

test('a VRM 0.x avatar, made facing -z, is turned to the camera: as a VRM 1.0 one looks, unless avatar-facing says +z', async ({ page }) => {
  test.setTimeout(120_000);
  await page.emulateMedia({ reducedMotion: 'reduce' }); // no idle blinks: the pictures compare as they are
  await page.goto('/examples/embed.html');
  const shot = async (avatar: string, facing: string | null) => {
    await add(page, avatar, facing);
    return page.locator('talking-face').screenshot();
  };
  const v1 = await shot('/examples/avatars/vrm1-face.vrm', null);
  const v0 = await shot('/examples/avatars/vrm0-face.vrm', null);
  const v0back = await shot('/examples/avatars/vrm0-face.vrm', '+z');
  const differing = (a: Buffer, b: Buffer) => page.evaluate(async ([x, y]) => {
    const pixels = async (b64: string) => {
      const bmp = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
      const c = new OffscreenCanvas(bmp.width, bmp.height).getContext('2d')!;
      c.drawImage(bmp, 0, 0);
      return c.getImageData(0, 0, bmp.width, bmp.height).data;
    };
    const [p, q] = [await pixels(x), await pixels(y)];
    let n = 0;
    for (let i = 0; i < p.length; i += 4) if (Math.abs(p[i] - q[i]) + Math.abs(p[i + 1] - q[i + 1]) + Math.abs(p[i + 2] - q[i + 2]) > 24) n++;
    return n / (p.length / 4);
  }, [a.toString('base64'), b.toString('base64')] as const);
  expect(await differing(v1, v0), 'VRM 0.x turned to the camera: the same picture as VRM 1.0').toBeLessThan(0.002);
  expect(await differing(v1, v0back), 'avatar-facing="+z" on a VRM 0.x: its back').toBeGreaterThan(0.05);
});
