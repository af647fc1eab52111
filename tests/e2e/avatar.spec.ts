import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { test, expect, imageStats, differingFraction } from './fixtures';
import { SPEECH, FPS, phoneSegments } from './helpers/audio';
import { addAvatarFace } from './helpers/avatar';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { VRMAnimationLoaderPlugin, type VRMAnimation } from '@pixiv/three-vrm-animation';
import { GltfAvatar } from '../../src/avatar/gltf-avatar';
import { editGlbJson } from '../../src/avatar/gltf-nodes';
import { ARKIT_NAMES, LIVE_LINK_FACE_COLUMNS } from '../../src/avatar/names';
import { meshopt, readGlb, writeGlb } from '../unit/helpers/glb';

/**
 * <talking-face avatar="..."> with the project's own test avatars (examples/avatars/, npm run make-avatars) on
 * examples/avatar.html: the ARKit one and the viseme-only one speak tests/fixtures/speech-kal.wav; the weights
 * follow its phones (tests/fixtures/speech-kal.phones.json: jawOpen and viseme_aa on the open vowels, mouthClose
 * and viseme_PP on /p b m/); frame events carry them; the avatar's morph targets and head bone move and it
 * blinks; the four exports (JSON, CSV, .glb, .vrma); clear errors for a file that is not glTF and for one with neither naming scheme.
 */
const OPEN_VOWELS = new Set(['AA', 'AE', 'AH', 'AO', 'AW', 'AY']);
const BILABIALS = new Set(['P', 'B', 'M']);
const AVATARS = resolve(import.meta.dirname, '../../examples/avatars');

const mean = (a: number[]) => a.reduce((s, x) => s + x, 0) / a.length;

type FaceEl = HTMLElement & {
  speak(a: Blob | string): Promise<void>;
  currentAnimation: { frames: number; blendshapes?: { arkit: Float32Array; visemes: Float32Array; headRotation: Float32Array } } | null;
  avatar: { gltf: { scene: { traverse(f: (o: unknown) => void): void } }; head: { quaternion: { w: number } } | null } | null;
};

test('an ARKit avatar and a viseme avatar speak through one attribute; the weights follow the phones', async ({ page }) => {
  test.setTimeout(240_000);
  await page.addInitScript(() => {
    const seen: Record<string, unknown[]> = {};
    (globalThis as unknown as { avatarEvents: typeof seen }).avatarEvents = seen;
    for (const type of ['ready', 'frame', 'error']) {
      document.addEventListener(type, (e) => {
        const id = (e.target as HTMLElement).id;
        if (id) (seen[id] ??= []).push({ type, detail: (e as CustomEvent).detail });
      }, true);
    }
  });
  await page.goto('/examples/avatar.html');
  type Event = { type: string; detail: Record<string, any> };
  const events = (id: string) => page.evaluate((i) => ((globalThis as unknown as { avatarEvents: Record<string, Event[]> }).avatarEvents[i] ?? []), id);
  await expect.poll(async () => (await Promise.all(['arkit', 'visemes', 'vrm'].map(async (id) => (await events(id)).some((e) => e.type === 'ready')))).every(Boolean), { timeout: 90_000 }).toBe(true);
  const ready = async (id: string) => (await events(id)).find((e) => e.type === 'ready')!.detail.avatar;
  expect(await ready('arkit')).toEqual({ scheme: 'arkit', matched: [...ARKIT_NAMES], headBone: 'Head' });
  expect((await ready('visemes')).scheme).toBe('visemes');
  expect((await ready('visemes')).matched).toHaveLength(15);
  expect(await ready('vrm')).toEqual({ scheme: 'vrm', matched: ['aa', 'ih', 'ou', 'ee', 'oh', 'blinkLeft', 'blinkRight'], headBone: 'Head' });
  // The three avatars are drawn.
  for (const id of ['#arkit', '#visemes', '#vrm']) expect((await imageStats(page, await page.locator(id).screenshot())).foregroundFraction, id).toBeGreaterThan(0.05);

  // The ARKit avatar blinks (idle blinks through eyeBlinkLeft / eyeBlinkRight): watch its influences every frame.
  await page.evaluate(() => {
    const face = document.getElementById('arkit') as unknown as FaceEl;
    const w = globalThis as unknown as { maxBlink: number; maxJaw: number; headMoved: boolean };
    w.maxBlink = 0; w.maxJaw = 0; w.headMoved = false;
    const meshes: { morphTargetDictionary: Record<string, number>; morphTargetInfluences: number[] }[] = [];
    face.avatar!.gltf.scene.traverse((o) => { if ((o as { morphTargetInfluences?: number[] }).morphTargetInfluences) meshes.push(o as typeof meshes[number]); });
    const watch = () => {
      for (const m of meshes) {
        w.maxBlink = Math.max(w.maxBlink, m.morphTargetInfluences[m.morphTargetDictionary.eyeBlinkLeft]);
        w.maxJaw = Math.max(w.maxJaw, m.morphTargetInfluences[m.morphTargetDictionary.jawOpen]);
      }
      if (face.avatar!.head && Math.abs(face.avatar!.head.quaternion.w - 1) > 1e-6) w.headMoved = true;
      requestAnimationFrame(watch);
    };
    watch();
  });

  const wav = readFileSync(SPEECH).toString('base64');
  await page.evaluate(async (b64) => {
    const blob = new Blob([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], { type: 'audio/wav' });
    const faces = ['arkit', 'visemes'].map((id) => document.getElementById(id) as unknown as FaceEl);
    await Promise.all(faces.map((f) => f.speak(blob)));
  }, wav);

  const take = (id: string) => page.evaluate((i) => {
    const a = (document.getElementById(i) as unknown as FaceEl).currentAnimation!;
    return { frames: a.frames, arkit: Array.from(a.blendshapes!.arkit), visemes: Array.from(a.blendshapes!.visemes) };
  }, id);
  const arkit = await take('arkit');
  const visemes = await take('visemes');
  const open = phoneSegments(OPEN_VOWELS, arkit.frames), closed = phoneSegments(BILABIALS, arkit.frames);
  expect(open.length).toBeGreaterThanOrEqual(5);
  expect(closed.length).toBeGreaterThanOrEqual(5);
  const w = (name: string) => (f: number) => arkit.arkit[f * 52 + ARKIT_NAMES.indexOf(name as never)];
  const v = (k: number) => (f: number) => visemes.visemes[f * 15 + k];
  const [PP, AA] = [1, 10];
  // jawOpen rises on the open vowels; mouthClose (the lips held together against the jaw) on /p b m/.
  const jawOpen = { open: mean(open.flat().map(w('jawOpen'))), closed: mean(closed.flat().map(w('jawOpen'))) };
  expect(jawOpen.open, JSON.stringify(jawOpen)).toBeGreaterThan(0.2);
  expect(jawOpen.open - jawOpen.closed, JSON.stringify(jawOpen)).toBeGreaterThan(0.05);
  const closePeaks = closed.map((seg) => Math.max(...seg.map(w('mouthClose'))));
  const closeOnOpen = mean(open.flat().map(w('mouthClose')));
  expect(mean(closePeaks), `mouthClose: /p b m/ peaks ${closePeaks}, open vowels ${closeOnOpen}`).toBeGreaterThan(2 * closeOnOpen + 0.03);
  // The viseme avatar's weights: viseme_PP on /p b m/, viseme_aa on the open vowels.
  const ppPeaks = closed.map((seg) => Math.max(...seg.map(v(PP))));
  expect(mean(ppPeaks), `viseme_PP peaks on /p b m/: ${ppPeaks}`).toBeGreaterThan(0.5);
  expect(mean(open.flat().map(v(PP)))).toBeLessThan(0.1);
  expect(mean(open.flat().map(v(AA)))).toBeGreaterThan(0.4);
  expect(mean(closed.flat().map(v(AA)))).toBeLessThan(0.2);

  // Frame events carried the weights by name (one per frame drawn: few on a loaded machine), equal to the take's.
  const frames = (await events('arkit')).filter((e) => e.type === 'frame');
  expect(frames.length).toBeGreaterThan(3);
  for (const e of frames) {
    expect(Object.keys(e.detail.arkit)).toEqual([...ARKIT_NAMES]);
    expect(e.detail.arkit.jawOpen).toBeCloseTo(w('jawOpen')(e.detail.frame), 6);
    expect(Object.keys(e.detail.visemes)).toHaveLength(15);
    expect(Number.isFinite(e.detail.headRotation.yaw)).toBe(true);
  }
  // Now that playback has ended the avatar has gone back to the rest's weights (engine.restArkit()), as the model's
  // face goes back to rest (the blinks aside, which may add to eyeBlink).
  const rest = await page.evaluate(async () => Array.from(await (await (document.getElementById('arkit') as unknown as { ready: Promise<{ restArkit(): Promise<Float32Array> }> }).ready).restArkit()));
  const shown = () => page.evaluate(() => {
    const out: Record<string, number> = {};
    (document.getElementById('arkit') as unknown as FaceEl).avatar!.gltf.scene.traverse((o) => {
      const m = o as { morphTargetDictionary?: Record<string, number>; morphTargetInfluences?: number[] };
      if (m.morphTargetDictionary) for (const [name, k] of Object.entries(m.morphTargetDictionary)) out[name] = m.morphTargetInfluences![k];
    });
    return out;
  });
  const speechShapes = ARKIT_NAMES.filter((n) => !n.startsWith('eyeBlink'));
  await expect.poll(async () => { const s = await shown(); return Math.max(...speechShapes.map((n) => Math.abs(s[n] - rest[ARKIT_NAMES.indexOf(n)]))); }, { timeout: 5_000 }).toBeLessThan(1e-6);
  const watched = () => page.evaluate(() => {
    const g = globalThis as unknown as { maxBlink: number; maxJaw: number; headMoved: boolean };
    return { maxBlink: g.maxBlink, maxJaw: g.maxJaw, headMoved: g.headMoved };
  });
  expect((await watched()).maxJaw).toBeGreaterThan(0.1);
  expect((await watched()).headMoved).toBe(true);
  await expect.poll(async () => (await watched()).maxBlink, { timeout: 15_000, message: 'the avatar blinks' }).toBeGreaterThan(0.5);
  for (const id of ['arkit', 'visemes']) expect((await events(id)).filter((e) => e.type === 'error')).toEqual([]);

  // The four exports of the ARKit avatar's take.
  const download = async (button: string) => {
    const [d] = await Promise.all([page.waitForEvent('download'), page.locator(button).click()]);
    return readFileSync((await d.path())!);
  };
  await expect(page.locator('#glb')).toBeEnabled();
  const json = JSON.parse((await download('#json')).toString());
  expect(json.arkitNames).toEqual([...ARKIT_NAMES]);
  expect(json.arkit).toHaveLength(arkit.frames);
  expect(json.arkit[40][ARKIT_NAMES.indexOf('jawOpen')]).toBeCloseTo(arkit.arkit[40 * 52 + ARKIT_NAMES.indexOf('jawOpen')], 4);
  const csv = (await download('#csv')).toString().trim().split('\n');
  expect(csv[0].split(',')).toEqual(['Timecode', 'BlendShapeCount', ...LIVE_LINK_FACE_COLUMNS]);
  expect(csv).toHaveLength(arkit.frames + 1);
  const row = csv[41].split(',');
  expect(row[0]).toBe(`00:00:01:${String(40 - FPS).padStart(2, '0')}.000`);
  expect(Number(row[1])).toBe(61);
  expect(Number(row[2 + LIVE_LINK_FACE_COLUMNS.indexOf('JawOpen')])).toBeCloseTo(arkit.arkit[40 * 52 + ARKIT_NAMES.indexOf('jawOpen')], 5);
  const glb = await download('#glb');
  expect(glb.subarray(0, 4).toString()).toBe('glTF');
  const exported = await GltfAvatar.parse(glb.buffer.slice(glb.byteOffset, glb.byteOffset + glb.byteLength) as ArrayBuffer, 'sample.arkit.glb');
  expect(exported.summary).toEqual({ scheme: 'arkit', matched: [...ARKIT_NAMES], headBone: 'Head' });
  expect(exported.gltf.animations).toHaveLength(1);
  expect(exported.gltf.animations[0].duration).toBeCloseTo((arkit.frames - 1) / FPS, 3);
  expect(exported.gltf.animations[0].tracks.map((t) => t.name).sort()).toEqual(['Head.quaternion', 'face.morphTargetInfluences']);
  // The VRM Animation, as @pixiv/three-vrm-animation reads it (tests/unit/avatar/vrm-animation.test.ts plays one on a VRM).
  const vrma = await download('#vrma');
  const loader = new GLTFLoader();
  loader.register((parser) => new VRMAnimationLoaderPlugin(parser));
  const [motion] = (await loader.parseAsync(vrma.buffer.slice(vrma.byteOffset, vrma.byteOffset + vrma.byteLength) as ArrayBuffer, '')).userData.vrmAnimations as VRMAnimation[];
  expect(motion.duration).toBeCloseTo((arkit.frames - 1) / FPS, 3);
  expect([...motion.expressionTracks.preset.keys()]).toEqual(['aa', 'ih', 'ou', 'ee', 'oh']);
  const aa = motion.expressionTracks.preset.get('aa')!.values;
  expect(mean(open.flat().map((f) => aa[f])), 'aa on the open vowels').toBeGreaterThan(0.4);
});

/** The test avatar with its morph targets renamed (the JSON chunk of the .glb edited, the binary chunk kept). */
function renamedAvatar(rename: (name: string) => string): string {
  return editedAvatar('visemes-face.glb', (gltf) => {
    for (const mesh of gltf.meshes) if (mesh.extras?.targetNames) mesh.extras.targetNames = mesh.extras.targetNames.map(rename);
  });
}

/** A test avatar (base64) with its glTF JSON changed by `edit`. */
function editedAvatar(file: string, edit: (gltf: any) => void): string {
  const b = readFileSync(resolve(AVATARS, file));
  return Buffer.from(editGlbJson(b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer, edit)).toString('base64');
}

test('an avatar file that is not glTF, or has neither naming scheme, gives a clear error; prefixed names match', async ({ page, guard }) => {
  test.setTimeout(120_000);
  guard.allowConsoleError(/404|Failed to load resource/);
  await page.goto('/examples/embed.html');
  const errorOf = (avatar: string, headBone?: string) => page.evaluate(([url, bone]) => new Promise<string>((resolve) => {
    const el = document.createElement('talking-face');
    el.setAttribute('backend', 'cpu');
    el.setAttribute('avatar', url);
    if (bone) el.setAttribute('avatar-head-bone', bone);
    el.addEventListener('error', (e) => resolve(`${(e as unknown as CustomEvent).detail.stage}: ${(e as unknown as CustomEvent).detail.message}`));
    el.addEventListener('ready', (e) => resolve(`ready: ${JSON.stringify((e as CustomEvent).detail.avatar)}`));
    document.body.append(el);
  }), [avatar, headBone ?? ''] as const);
  const blobUrl = (b64: string) => page.evaluate((data) => URL.createObjectURL(new Blob([Uint8Array.from(atob(data), (c) => c.charCodeAt(0))])), b64);

  expect(await errorOf('/examples/sample.wav')).toMatch(/^avatar: the avatar cannot be used: .*sample\.wav is not a glTF file.*starts with "RIFF"/);
  // A missing file: this project's server answers 404; many static hosts answer with their index page instead.
  expect(await errorOf('/examples/avatars/missing.glb')).toMatch(/^avatar: .*could not fetch the avatar .*missing\.glb: HTTP 404/);
  await page.route('**/examples/avatars/spa-fallback.glb', (route) => route.fulfill({ status: 200, contentType: 'text/html', body: '<!doctype html><html><body>app</body></html>' }));
  expect(await errorOf('/examples/avatars/spa-fallback.glb')).toMatch(/^avatar: .*spa-fallback\.glb is not a glTF file but an HTML page, as hosts send for a missing file: is the URL right\?$/);
  const unnamed = await errorOf(await blobUrl(renamedAvatar((n) => n.replace('viseme_', 'mouth_shape_'))));
  expect(unnamed).toMatch(/no morph targets named after ARKit's 52 blend shapes .* or the 15 Oculus visemes/);
  expect(unnamed).toContain('its morph targets are: mouth_shape_sil, mouth_shape_PP, mouth_shape_FF');
  expect(await errorOf('/examples/avatars/arkit-face.glb', 'Neck')).toMatch(/no node named "Neck" \(the head bone asked for: avatar-head-bone, or bind's headBone\); its nodes are: Head, face_arkit/);
  // Exporter prefixes and other spellings still match: "blendShape1.viseme_PP", "Viseme_AA".
  const prefixed = await errorOf(await blobUrl(renamedAvatar((n) => (n === 'viseme_aa' ? 'Viseme_AA' : `blendShape1.${n}`))));
  expect(prefixed).toMatch(/^ready: .*"scheme":"visemes"/);
  expect(JSON.parse(prefixed.slice('ready: '.length)).matched).toHaveLength(15);
  // Compressed: meshopt is decoded (the library's decoder chunk, loaded when a file needs it); Draco is refused plainly.
  const packed = await errorOf(await blobUrl(Buffer.from(await meshopt(resolve(AVATARS, 'arkit-face.glb'))).toString('base64')));
  expect(packed).toMatch(/^ready: /);
  expect(JSON.parse(packed.slice('ready: '.length))).toEqual({ scheme: 'arkit', matched: [...ARKIT_NAMES], headBone: 'Head' });
  const { json, bin } = readGlb(resolve(AVATARS, 'arkit-face.glb'));
  const draco = writeGlb({ ...json, extensionsUsed: ['KHR_draco_mesh_compression'], extensionsRequired: ['KHR_draco_mesh_compression'] }, bin);
  expect(await errorOf(await blobUrl(Buffer.from(draco).toString('base64')))).toMatch(/^avatar: the avatar cannot be used: blob:.* is compressed with Draco \(KHR_draco_mesh_compression\), which this library does not decode/);
});

test('an avatar replaced while its download hangs: the download is stopped, and the new one shown', async ({ page }) => {
  test.setTimeout(90_000);
  await page.route('**/examples/avatars/hung.glb', () => undefined); // never answered (a slow host)
  const [asked, stopped]: string[][] = [[], []];
  page.on('request', (r) => r.url().endsWith('hung.glb') && asked.push(r.url()));
  page.on('requestfailed', (r) => r.url().endsWith('hung.glb') && stopped.push(r.failure()?.errorText ?? '?'));
  await page.goto('/examples/embed.html');
  await page.locator('#left').evaluate((el) => el.setAttribute('avatar', '/examples/avatars/hung.glb'));
  await expect.poll(() => page.evaluate(() => document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent), { timeout: 60_000 }).toContain('Loading the avatar');
  const ready = page.locator('#left').evaluate((el) => new Promise<string>((resolve) => el.addEventListener('ready', (e) => resolve((e as CustomEvent).detail.avatar?.scheme), { once: true })));
  await page.locator('#left').evaluate((el) => el.setAttribute('avatar', '/examples/avatars/arkit-face.glb'));
  expect(await ready).toBe('arkit');
  expect(asked.length).toBeGreaterThan(0);
  await expect.poll(() => stopped, { timeout: 5_000, message: 'every download of the replaced avatar stopped' }).toEqual(asked.map(() => 'net::ERR_ABORTED'));
});

test('avatar-facing="-z" shows an avatar made facing -z (VRM 0.x) as a +z one', async ({ page }) => {
  test.setTimeout(120_000);
  await page.emulateMedia({ reducedMotion: 'reduce' }); // no idle blinks: the pictures compare as they are
  await page.goto('/examples/embed.html');
  // The ARKit test avatar turned half round y at its root: its face looks towards -z.
  const turned = editedAvatar('arkit-face.glb', (gltf) => { for (const n of gltf.scenes[0].nodes) gltf.nodes[n].rotation = [0, 1, 0, 0]; });
  const url = await page.evaluate((data) => URL.createObjectURL(new Blob([Uint8Array.from(atob(data), (c) => c.charCodeAt(0))])), turned);
  const shot = async (avatar: string, facing: string | null) => {
    await addAvatarFace(page, avatar, facing);
    return page.locator('talking-face').screenshot();
  };
  const plain = await shot('/examples/avatars/arkit-face.glb', null);
  const fixed = await shot(url, '-z');
  const away = await shot(url, null);
  const differing = (a: Buffer, b: Buffer) => differingFraction(page, a, b);
  expect(await differing(plain, fixed), 'turned back to the camera: the same picture').toBeLessThan(0.002);
  expect(await differing(plain, away), 'without the attribute: its back').toBeGreaterThan(0.05);
});
