import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { SPEECH } from './helpers/audio';
import { ARKIT_NAMES } from '../../src/avatar/names';

/**
 * examples/own-scene.html: a page with its own three.js scene (the project's three.js through its import map) loads
 * the test avatar with its own GLTFLoader, places it turned, and has the package's build for bundlers without the
 * element (dist/lib/npm/engine.js, three.js external) drive it: GltfAvatar.bind + AvatarDriver, frame by frame on
 * the audio clock, and live from a (fake) microphone. Read from the avatar itself at many instants: its morph
 * targets are the take's weights for the frame shown and its head bone, relative to the avatar's root, is the
 * predicted rotation on top of its rest, although the page turned the avatar. One three.js, from the page's origin,
 * and no element defined; no console error (fixtures.ts). A VRM 0.x avatar (?avatar=...vrm) is loaded with
 * @pixiv/three-vrm, driven through its expressions and normalized head, which vrm.update() applies to the model: its
 * morph targets open on speech and its own head bone turns as the take says, in the avatar's own axes (facing -z).
 */
test.use({ launchOptions: fakeMicrophone(SPEECH) });

const CHECKED = ['jawOpen', 'mouthClose', 'mouthFunnel', 'mouthRollLower', 'mouthSmileLeft'] as const;

interface Sample {
  frame: number;
  speech: number;
  influences: number[];
  /** The head bone's rotation relative to gltf.scene, less its rest: [x, y, z, w]. */
  turn: number[];
}

type Page = import('@playwright/test').Page;

/**
 * Read the avatar every ~70 ms until collect() is called: the morph targets `names` and the head's turn (of the
 * driver's head bone, or of the node named `headName`: a three-vrm model's own head, which vrm.update() turns).
 */
async function sample(page: Page, names: readonly string[], headName: string | null = null) {
  await page.evaluate(([names, headName]) => {
    const g = globalThis as any;
    const { state, THREE } = g.ownSceneExample;
    const avatar = state.driver.avatar, root = avatar.gltf.scene, head = headName ? root.getObjectByName(headName) : avatar.head;
    let mesh: any;
    root.traverse((o: any) => { if (o.morphTargetDictionary?.[names[0]] !== undefined) mesh = o; });
    const restInverse = head.quaternion.clone().invert(); // sampled at rest: the head bone's own rest rotation
    const parentInRoot = () => root.getWorldQuaternion(new THREE.Quaternion()).invert().multiply(head.parent.getWorldQuaternion(new THREE.Quaternion()));
    g.samples = [];
    g.sampler = setInterval(() => {
      const p = parentInRoot();
      // head = P^-1 D P rest  =>  D = P head rest^-1 P^-1 (the turn in the avatar's own axes)
      const d = p.clone().multiply(head.quaternion).multiply(restInverse).multiply(p.clone().invert());
      g.samples.push({
        frame: state.source ? state.frame : -1,
        speech: state.driver.speechWeight,
        influences: names.map((n: string) => mesh.morphTargetInfluences[mesh.morphTargetDictionary[n]]),
        turn: [d.x, d.y, d.z, d.w],
      });
    }, 70);
  }, [[...names], headName] as const);
}
const collect = (page: Page): Promise<Sample[]> => page.evaluate(() => {
  const g = globalThis as any;
  clearInterval(g.sampler);
  return g.samples;
});

/** Open the example (with `query`) and wait until it is ready; the console's warnings, collected from the start. */
async function openExample(page: Page, query = ''): Promise<string[]> {
  const warnings: string[] = [];
  page.on('console', (m) => { if (m.type() === 'warning') warnings.push(m.text()); });
  await page.goto(`/examples/own-scene.html${query}`);
  await expect(page.locator('#log')).toHaveText(/^ready: \d+ frames of the sample/, { timeout: 150_000 });
  return warnings;
}

test('an avatar in the page\'s own three.js scene speaks a take frame by frame, and what the microphone hears', async ({ page, guard }) => {
  test.setTimeout(180_000);
  const warnings = await openExample(page);
  // The page's three.js is the project's, from its origin, and the only one: the library did not bring its own.
  const paths = guard.requests.map((u) => new URL(u).pathname);
  expect(paths).toContain('/examples/vendor/three-project/build/three.module.js');
  expect(paths).toContain('/lib/npm/engine.js');
  expect(paths.filter((p) => p.endsWith('/talking-face.js')), 'the element\'s entries').toEqual([]);
  expect(await page.evaluate(() => customElements.get('talking-face')), 'no element defined').toBeUndefined();
  expect(warnings.filter((w) => /Multiple instances of Three/.test(w))).toEqual([]);
  expect(await page.evaluate(() => (globalThis as any).ownSceneExample.scene.getObjectByName('Head') !== undefined)).toBe(true);

  const take = await page.evaluate(() => {
    const { take } = (globalThis as any).ownSceneExample.state;
    return { frames: take.frames as number, arkit: Array.from(take.blendshapes.arkit as Float32Array), pose: Array.from(take.pose as Float32Array) };
  });

  // 1. The take, on the audio clock.
  await sample(page, CHECKED);
  await page.locator('#speak').click();
  await expect(page.locator('#log')).toHaveText(`played ${take.frames} frames`, { timeout: 30_000 });
  const played = (await collect(page)).filter((s) => s.frame >= 0 && s.speech === 1);
  expect(new Set(played.map((s) => s.frame)).size, 'distinct frames sampled at full weight').toBeGreaterThanOrEqual(8);
  let nodded = 0;
  for (const s of played) {
    CHECKED.forEach((n, k) => expect(s.influences[k], `${n} at frame ${s.frame}`).toBeCloseTo(take.arkit[s.frame * 52 + ARKIT_NAMES.indexOf(n)], 6));
    const [rx, ry, rz] = take.pose.slice(s.frame * 6, s.frame * 6 + 3);
    const angle = Math.hypot(rx, ry, rz), sin = Math.sin(angle / 2) / (angle || 1);
    const want = [rx * sin, ry * sin, rz * sin, Math.cos(angle / 2)];
    const dot = Math.abs(want.reduce((a, w, i) => a + w * s.turn[i], 0));
    expect(2 * Math.acos(Math.min(1, dot)), `the head's turn at frame ${s.frame}`).toBeLessThan(1e-4);
    nodded = Math.max(nodded, angle);
  }
  expect(nodded, 'the head turns').toBeGreaterThan(0.01);
  const jaw = played.map((s) => s.influences[0]);
  expect(Math.max(...jaw) - Math.min(...jaw), 'jawOpen moves').toBeGreaterThan(0.15);
  // After the take the face goes back to its rest (blended out over 0.4 s), the head to neutral.
  await expect.poll(() => page.evaluate(() => (globalThis as any).ownSceneExample.state.driver.speechWeight)).toBe(0);

  // 2. Live: the fake microphone plays speech; the jaw moves, and Stop releases the microphone.
  await sample(page, CHECKED);
  await page.locator('#listen').click();
  await expect(page.locator('#log')).toHaveText('listening');
  await page.waitForTimeout(4000);
  const live = await collect(page);
  const liveJaw = live.map((s) => s.influences[0]);
  expect(Math.max(...liveJaw) - Math.min(...liveJaw), 'jawOpen moves live').toBeGreaterThan(0.1);
  expect(Math.max(...live.map((s) => s.speech)), 'blended in').toBe(1);
  await page.locator('#stop').click();
  await expect(page.locator('#log')).toHaveText('stopped listening');
  await expect.poll(() => page.evaluate(() => (globalThis as any).ownSceneExample.state.driver.speechWeight)).toBe(0);
});

test('a VRM 0.x avatar loaded with @pixiv/three-vrm in the page\'s own scene speaks through its expressions and turns its head', async ({ page, guard }) => {
  test.setTimeout(180_000);
  const warnings = await openExample(page, '?avatar=/examples/avatars/vrm0-face.vrm');
  expect(guard.requests.map((u) => new URL(u).pathname)).toContain('/examples/vendor/three-vrm/three-vrm.module.js');
  const bound = await page.evaluate(() => {
    const { state } = (globalThis as any).ownSceneExample;
    return { metaVersion: state.vrm?.meta?.metaVersion, summary: state.driver.avatar.summary, facing: state.driver.avatar.facing };
  });
  expect(bound).toEqual({ metaVersion: '0', summary: { scheme: 'vrm', matched: ['aa', 'ih', 'ou', 'ee', 'oh', 'blinkLeft', 'blinkRight'], headBone: 'Normalized_Head' }, facing: '-z' });
  const take = await page.evaluate(() => {
    const { take } = (globalThis as any).ownSceneExample.state;
    return { frames: take.frames as number, pose: Array.from(take.pose as Float32Array) };
  });

  await sample(page, ['Fcl_MTH_A', 'Fcl_MTH_I', 'Fcl_MTH_U', 'Fcl_MTH_E', 'Fcl_MTH_O'], 'Head');
  await page.locator('#speak').click();
  await expect(page.locator('#log')).toHaveText(`played ${take.frames} frames`, { timeout: 30_000 });
  const played = (await collect(page)).filter((s) => s.frame >= 0 && s.speech === 1);
  expect(new Set(played.map((s) => s.frame)).size, 'distinct frames sampled at full weight').toBeGreaterThanOrEqual(8);
  const opening = played.map((s) => s.influences.reduce((a, x) => a + x, 0));
  expect(Math.max(...opening) - Math.min(...opening), 'the mouth opens and closes').toBeGreaterThan(0.3);
  let nodded = 0;
  for (const s of played) {
    // The turn in gltf.scene's axes: the avatar faces -z there, so its own x and z are the scene's -x and -z.
    const [rx, ry, rz] = take.pose.slice(s.frame * 6, s.frame * 6 + 3);
    const angle = Math.hypot(rx, ry, rz), sin = Math.sin(angle / 2) / (angle || 1);
    const want = [-rx * sin, ry * sin, -rz * sin, Math.cos(angle / 2)];
    const dot = Math.abs(want.reduce((a, w, i) => a + w * s.turn[i], 0));
    expect(2 * Math.acos(Math.min(1, dot)), `the model's head's turn at frame ${s.frame}`).toBeLessThan(1e-4);
    nodded = Math.max(nodded, angle);
  }
  expect(nodded, 'the head turns').toBeGreaterThan(0.01);
  await expect.poll(() => page.evaluate(() => (globalThis as any).ownSceneExample.state.driver.speechWeight)).toBe(0);
  // Neither three-vrm nor three.js had anything to say (THREE.Clock, deprecated, warned at each load).
  expect(warnings.filter((w) => !/GPU stall due to ReadPixels/.test(w))).toEqual([]);
});

test('speech streamed in pieces (speakStream) drives the avatar in the page\'s own scene as it plays; its take is the offline one; Stop rests it', async ({ page }) => {
  test.setTimeout(180_000);
  await openExample(page);
  const JAW = ARKIT_NAMES.indexOf('jawOpen');
  // Each frame handed to the driver (its jawOpen), and the avatar's jawOpen every ~70 ms with how many had been handed.
  const watch = () => page.evaluate((jaw) => {
    const g = globalThis as any;
    const { state } = g.ownSceneExample;
    let mesh: any;
    state.driver.avatar.gltf.scene.traverse((o: any) => { if (o.morphTargetDictionary?.jawOpen !== undefined) mesh = o; });
    const show = state.driver.show.bind(state.driver);
    g.handed = [];
    state.driver.show = (frames: any, f: number, speaking: boolean) => {
      g.handed.push({ jaw: frames.blendshapes.arkit[f * 52 + jaw], speaking });
      show(frames, f, speaking);
    };
    g.seen = [];
    g.sampler = setInterval(() => g.seen.push({ jaw: mesh.morphTargetInfluences[mesh.morphTargetDictionary.jawOpen], handed: g.handed.length,
      full: state.driver.speechWeight === 1 }), 70);
  }, JAW);
  await watch();
  await page.locator('#stream').click();
  await page.evaluate(() => ((globalThis as any).speech = (globalThis as any).ownSceneExample.state.stream));
  await expect(page.locator('#log')).toHaveText(/^streamed \d+ frames, \d+ ms behind the pieces$/, { timeout: 60_000 });
  const r = await page.evaluate(() => {
    const g = globalThis as any;
    clearInterval(g.sampler);
    const { take } = g.ownSceneExample.state, streamed = g.speech.take.animation;
    let pose = 0, arkit = 0;
    for (let i = 0; i < take.pose.length; i++) pose = Math.max(pose, Math.abs(take.pose[i] - streamed.pose[i]));
    for (let i = 0; i < take.blendshapes.arkit.length; i++) arkit = Math.max(arkit, Math.abs(take.blendshapes.arkit[i] - streamed.blendshapes.arkit[i]));
    return { frames: [take.frames, streamed.frames], pose, arkit, handed: g.handed, seen: g.seen, log: document.getElementById('log')!.textContent };
  });
  console.log(`streamed to the page's avatar: ${r.log}; ${r.handed.length} frames shown; largest difference from the offline take: `
    + `pose ${r.pose.toExponential(1)}, ARKit weights ${r.arkit.toExponential(1)}`);
  expect(r.frames[1]).toBe(r.frames[0]);
  expect(r.pose).toBeLessThan(1e-4);
  expect(r.arkit).toBeLessThan(1e-3);
  expect(r.handed.length).toBeGreaterThan(10);
  expect(r.handed.at(-1).speaking, 'the last frame at rest').toBe(false);
  // At full weight the avatar shows the frame the stream handed over last (or the one before: the page's loop may
  // draw before the stream's animation frame hands over the next).
  const full = r.seen.filter((s: { full: boolean; handed: number }) => s.full && s.handed >= 2);
  expect(full.length).toBeGreaterThanOrEqual(8);
  for (const s of full) {
    const near = [r.handed[s.handed - 1].jaw, r.handed[s.handed - 2].jaw].some((w: number) => Math.abs(w - s.jaw) < 1e-6);
    expect(near, `jawOpen ${s.jaw} after ${s.handed} frames handed`).toBe(true);
  }
  const jaws = full.map((s: { jaw: number }) => s.jaw);
  expect(Math.max(...jaws) - Math.min(...jaws), 'jawOpen moves').toBeGreaterThan(0.15);
  await expect.poll(() => page.evaluate(() => (globalThis as any).ownSceneExample.state.driver.speechWeight)).toBe(0);

  // Stopped mid-stream: the sound stops, one last frame at rest, nothing shown after it; the avatar back to rest.
  await watch();
  await page.locator('#stream').click();
  await expect.poll(() => page.evaluate(() => (globalThis as any).handed.length), { timeout: 30_000 }).toBeGreaterThan(5);
  await page.locator('#stop').click();
  await expect(page.locator('#log')).toHaveText('stopped streaming');
  const atStop = await page.evaluate(() => (globalThis as any).handed.length);
  await page.waitForTimeout(1000);
  const after = await page.evaluate(() => (globalThis as any).handed.slice(-2));
  expect(await page.evaluate(() => (globalThis as any).handed.length)).toBe(atStop);
  expect(after[1].speaking).toBe(false);
  await expect.poll(() => page.evaluate(() => (globalThis as any).ownSceneExample.state.driver.speechWeight)).toBe(0);
});

test("speakStream on the page's own context, which the page closes while it plays: done rejects saying so, the avatar rests", async ({ page }) => {
  test.setTimeout(120_000);
  await openExample(page);
  const outcome = await page.evaluate(async () => {
    const { speakStream } = await import('/lib/npm/engine.js' as string);
    const { state } = (globalThis as any).ownSceneExample;
    const context = new AudioContext();
    const shown: boolean[] = [];
    const speech = speakStream(state.engine, { sampleRate: 16000, context, show: (_f: unknown, _k: number, speaking: boolean) => shown.push(speaking) });
    const wav = await (await fetch('/examples/sample.wav')).arrayBuffer();
    speech.write(new Uint8Array(wav, 44, (wav.byteLength - 44) & ~1));
    while (shown.length < 10) await new Promise((r) => setTimeout(r, 50));
    const started = performance.now();
    await context.close();
    const said = await speech.done.then(() => 'resolved', (e: Error) => e.message);
    return { said, ms: performance.now() - started, last: shown.at(-1), open: speech.open };
  });
  expect(outcome.said).toBe('speakStream: its audio context was closed: nothing more can play on it');
  expect(outcome.ms, 'at once, not when the sound would have ended').toBeLessThan(1000);
  expect([outcome.last, outcome.open]).toEqual([false, false]);
});
