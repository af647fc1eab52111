import { test, expect } from './fixtures';

/**
 * An avatar at rest (<talking-face avatar="...">, examples/embed.html as the host page): the rest is the weights of
 * the model's own face in silence (engine.restArkit()), which silence gets and the avatar shows before it speaks;
 * audio without speech (a tone) keeps it at rest, as the face; stop() brings it back to rest instead of freezing it
 * mid-word; an avatar that cannot be loaded makes speak() fail saying why, and one replaced while it loaded says
 * nothing.
 */
type El = HTMLElement & {
  speak(a: unknown): Promise<void>;
  stop(): void;
  ready: Promise<{ restArkit(): Promise<Float32Array> }>;
  currentAnimation: { frames: number; blendshapes?: { arkit: Float32Array; visemes: Float32Array } } | null;
  avatar: { gltf: { scene: { traverse(f: (o: unknown) => void): void } }; head: { quaternion: { x: number; y: number; z: number; w: number } } | null } | null;
};

/** Add <talking-face id=... avatar=...> and collect its events (type: detail message) in globalThis.seen[id]. */
async function addAvatar(page: import('@playwright/test').Page, id: string, avatar: string): Promise<void> {
  await page.evaluate(([id, avatar]) => {
    const g = globalThis as unknown as { seen: Record<string, string[]> };
    g.seen ??= {};
    g.seen[id] = [];
    const el = document.createElement('talking-face');
    el.id = id;
    el.setAttribute('backend', 'cpu');
    for (const type of ['ready', 'error', 'ended']) el.addEventListener(type, (e) => g.seen[id].push(`${type}: ${(e as CustomEvent).detail?.message ?? ''}`));
    el.setAttribute('avatar', avatar);
    document.body.append(el);
  }, [id, avatar]);
}

const seen = (page: import('@playwright/test').Page, id: string) =>
  page.evaluate((i) => (globalThis as unknown as { seen: Record<string, string[]> }).seen[i], id);
const status = (page: import('@playwright/test').Page, id: string) =>
  page.evaluate((i) => document.getElementById(i)!.shadowRoot!.querySelector('p.status')!.textContent!, id);

/** The avatar's morph-target influences by name, blinks left out (idle blinks come and go), and its head's rotation. */
const shown = (page: import('@playwright/test').Page, id: string) => page.evaluate((i) => {
  const a = (document.getElementById(i) as unknown as El).avatar!;
  const out: Record<string, number> = {};
  a.gltf.scene.traverse((o) => {
    const m = o as { morphTargetDictionary?: Record<string, number>; morphTargetInfluences?: number[] };
    if (m.morphTargetDictionary) for (const [name, k] of Object.entries(m.morphTargetDictionary)) if (!name.startsWith('eyeBlink')) out[name] = m.morphTargetInfluences![k];
  });
  const q = a.head!.quaternion;
  return { weights: out, jawOpen: out.jawOpen, head: [q.x, q.y, q.z, q.w] };
}, id);

test('an avatar rests in silence and where no speech is found, and goes back to neutral when stopped', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/examples/embed.html');
  await addAvatar(page, 'a', '/examples/avatars/arkit-face.glb');
  await expect.poll(() => seen(page, 'a'), { timeout: 90_000 }).toContain('ready: ');
  const neutralHead = (await shown(page, 'a')).head;
  const rest: Record<string, number> = await page.evaluate(async () => {
    const w = await (await (document.getElementById('a') as unknown as El).ready).restArkit();
    const names = (await import('/lib/talking-face.js' as string)).ARKIT_NAMES as string[];
    return Object.fromEntries(names.map((n, k) => [n, w[k]]));
  });
  /** How far the avatar's morph targets are from the rest's weights (blinks aside). */
  const fromRest = (w: Record<string, number>) => Math.max(...Object.entries(w).map(([n, x]) => Math.abs(x - rest[n])));
  console.log(`the rest's largest weights: ${Object.entries(rest).sort((a, b) => b[1] - a[1]).slice(0, 3).map(([n, x]) => `${n} ${x.toFixed(3)}`).join(', ')}`);
  await expect.poll(async () => fromRest((await shown(page, 'a')).weights), { message: 'shown before speech' }).toBeLessThan(1e-6);

  // A second of digital silence: every frame's weights are the rest's.
  const silence = await page.evaluate(async (rest) => {
    const el = document.getElementById('a') as unknown as El;
    await el.speak(new AudioBuffer({ length: 16_000, sampleRate: 16_000 }));
    const b = el.currentAnimation!.blendshapes!;
    const r = Object.values(rest);
    return Math.max(...Array.from(b.arkit, (x, i) => Math.abs(x - r[i % 52])));
  }, rest);
  console.log(`silence: largest departure from the rest's weights ${silence.toFixed(4)}`);
  expect(silence).toBeLessThan(0.02);

  // A 220 Hz tone: no speech, so the face and the weights stay at rest (the visemes at viseme_sil).
  const tone = await page.evaluate(async (rest) => {
    const el = document.getElementById('a') as unknown as El;
    const buffer = new AudioBuffer({ length: 32_000, sampleRate: 16_000 });
    buffer.getChannelData(0).forEach((_, i, x) => (x[i] = 0.3 * Math.sin((2 * Math.PI * 220 * i) / 16_000)));
    await el.speak(buffer);
    const b = el.currentAnimation!.blendshapes!;
    const sil = Array.from({ length: el.currentAnimation!.frames }, (_, f) => b.visemes[f * 15]);
    const r = Object.values(rest);
    return { departure: Math.max(...Array.from(b.arkit, (x, i) => Math.abs(x - r[i % 52]))), silence: Math.min(...sil) };
  }, rest);
  expect(await status(page, 'a')).toContain('no speech was found');
  expect(tone).toEqual({ departure: 0, silence: 1 });
  expect(fromRest((await shown(page, 'a')).weights)).toBeLessThan(1e-6);

  // Speech stopped mid-clip: back to neutral (weights and head) within the fade, not frozen on the frame shown.
  await page.evaluate(() => void (document.getElementById('a') as unknown as El).speak('/examples/sample.wav'));
  await expect.poll(async () => (await shown(page, 'a')).jawOpen, { timeout: 60_000, intervals: [50] }).toBeGreaterThan(0.05);
  await page.evaluate(() => (document.getElementById('a') as unknown as El).stop());
  await page.waitForTimeout(1000);
  const after = await shown(page, 'a');
  expect(fromRest(after.weights), 'the weights after stop()').toBeLessThan(1e-6);
  after.head.forEach((q, k) => expect(q, 'the head after stop()').toBeCloseTo(neutralHead[k], 5));
  expect(await status(page, 'a')).toBe('Stopped.');
});

test('an avatar that cannot be loaded makes speak() fail saying why; one replaced while it loaded says nothing', async ({ page, guard }) => {
  test.setTimeout(120_000);
  guard.allowConsoleError(/404|Failed to load resource/);
  await page.route('**/slow-missing.glb', async (route) => {
    await new Promise((r) => setTimeout(r, 2500));
    await route.fulfill({ status: 404, body: 'not here' });
  });
  await page.goto('/examples/embed.html');
  await addAvatar(page, 'bad', '/examples/avatars/missing.glb');
  await expect.poll(() => seen(page, 'bad'), { timeout: 90_000 }).toContainEqual(expect.stringMatching(/^error: the avatar cannot be used: .*missing\.glb: HTTP 404/));
  const failed = await page.evaluate(() => (document.getElementById('bad') as unknown as El).speak('/examples/sample.wav').then(() => 'resolved', (e: Error) => e.message));
  expect(failed).toMatch(/the avatar cannot be used: .*missing\.glb: HTTP 404/);
  expect(await status(page, 'bad')).toMatch(/the avatar cannot be used/);

  await addAvatar(page, 'replaced', '/slow-missing.glb');
  await page.waitForTimeout(300);
  await page.evaluate(() => document.getElementById('replaced')!.setAttribute('avatar', '/examples/avatars/arkit-face.glb'));
  await expect.poll(() => seen(page, 'replaced'), { timeout: 90_000 }).toContain('ready: ');
  await page.waitForTimeout(3500); // the first avatar's 404 has arrived by now
  expect((await seen(page, 'replaced')).filter((e) => e.startsWith('error'))).toEqual([]);
  expect(await status(page, 'replaced')).toMatch(/^Ready/);
});

test('speech blends in on an avatar: its weights and head go from the rest to the first frame over 0.12 s, not in one jump', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/examples/embed.html');
  await addAvatar(page, 'b', '/examples/avatars/arkit-full-body.glb');
  await expect.poll(() => seen(page, 'b'), { timeout: 90_000 }).toContain('ready: ');
  // The speech weight and the time at every animation frame from before speak() until it first reaches 1.
  const samples = await page.evaluate(() => new Promise<[number, number][]>((resolve) => {
    const el = document.getElementById('b') as unknown as El & { stage: { view: { speechWeight: number } } };
    const out: [number, number][] = [];
    const sample = () => {
      out.push([performance.now(), el.stage.view.speechWeight]);
      if (out.at(-1)![1] >= 1 || out.length > 600) resolve(out);
      else requestAnimationFrame(sample);
    };
    sample();
    void el.speak('/examples/sample.wav');
  }));
  console.log(`speech weight per animation frame: ${samples.filter(([, w]) => w > 0).map(([t, w]) => `${w.toFixed(2)}@${t.toFixed(0)}`).join(' ')}`);
  expect(samples[0][1], 'at rest before speech').toBe(0);
  expect(samples.at(-1)![1], 'speaking').toBe(1);
  // No faster than 1 per 0.12 s. The view and this sampler run in either order within a frame, so a sample may show
  // the frame before's weight: a rise between two samples is bounded by the time from the frame before the first.
  for (let i = 1; i < samples.length; i++) {
    const rise = samples[i][1] - samples[i - 1][1], since = samples[i][0] - samples[Math.max(0, i - 2)][0];
    expect(rise, `the rise in the ${since.toFixed(0)} ms to ${samples[i][0].toFixed(0)} ms`).toBeLessThanOrEqual((since + 5) / 120);
  }
});
