import { test, expect, imageStats } from './fixtures';
import { ARKIT_NAMES } from '../../src/avatar/names';
import { TALKINGHEAD_SHAPES, talkingHeadAngles } from '../../src/avatar/talkinghead';

/**
 * examples/talkinghead.html: TalkingHead 1.7.0 (@met4citizen/talkinghead, served from the page's origin through its
 * import map) loads the project's full-body test avatar (examples/avatars/arkit-full-body.glb), the engine animates
 * examples/sample.wav, and the avatar speaks it twice: frame by frame (TalkingHeadDriver, the realtime values of
 * TalkingHead's mtAvatar) in sync with the audio clock, then through TalkingHead's speakAudio with the take as its
 * anim. Read from TalkingHead's own state at many instants during playback: the influences on the avatar's mesh
 * are the engine's weights for the frame shown (or, with the anim, for the instant of TalkingHead's timeline), and
 * the head's rotation deltas are the predicted head rotation. The fixture fails the test on any request beyond the
 * page's origin and on any console error. TalkingHead itself in Node: tests/unit/avatar/talkinghead.test.ts.
 */

/** Shapes whose influences are compared at each instant (all of TALKINGHEAD_SHAPES are set; these move most). */
const CHECKED = ['jawOpen', 'mouthClose', 'mouthFunnel', 'mouthPucker', 'mouthSmileLeft', 'mouthLowerDownLeft', 'mouthUpperUpRight', 'mouthRollLower'] as const;

interface Sample {
  /** The frame the page set (-1 before the first), and the frame of the heard audio clock at the instant of sampling. */
  frame: number;
  audioFrame: number;
  /** Milliseconds since the last step of TalkingHead's loop (it steps at most 30 times a second, on animation frames). */
  sinceStep: number;
  /** TalkingHead's anim clock relative to the anim's start (ms), when its anim plays. */
  animTime: number | null;
  influences: Record<string, number>;
  realtime: Record<string, number | null>;
  head: { x: number; y: number; z: number };
}

type Page = import('@playwright/test').Page;

/** Sample TalkingHead's state every ~90 ms (timer tasks run between its animation frames) until stopSampling(). */
function startSampling(page: Page, checked: readonly string[]) {
  return page.evaluate((names) => {
    const g = globalThis as unknown as { talkingHeadExample: { head: any; state: any }; samples: unknown[]; sampler: number };
    const { head, state } = g.talkingHeadExample;
    g.samples = [];
    const heard = (c: AudioContext) => c.currentTime - (c.baseLatency || 0) - (c.outputLatency || 0);
    g.sampler = setInterval(() => {
      const mesh = head.morphs[0];
      const anim = head.animQueue.find((a: { template: { name: string } }) => a.template.name === 'blendshapes');
      const d = head.poseDelta.props['Head.quaternion'];
      g.samples.push({
        frame: state.frame,
        // The heard clock, as the page reads it (heardTime: currentTime less the output's latency).
        audioFrame: state.source ? Math.floor((heard(state.context) - state.startedAt) * state.take.fps) : -1,
        sinceStep: performance.now() - head.animTimeLast,
        animTime: anim ? head.animClock - anim.ts[0] : null,
        influences: Object.fromEntries(names.map((n: string) => [n, mesh.morphTargetInfluences[mesh.morphTargetDictionary[n]]])),
        realtime: Object.fromEntries([...names, 'headRotateX'].map((n: string) => [n, head.mtAvatar[n].realtime])),
        // The head bone's rotation delta less TalkingHead's body sway: the head's own turn (its updateMorphTargets).
        head: { x: d.x - head.mtAvatar.bodyRotateX.applied, y: d.y - head.mtAvatar.bodyRotateY.applied, z: d.z - head.mtAvatar.bodyRotateZ.applied },
      });
    }, 90) as unknown as number;
  }, [...checked]);
}

function stopSampling(page: Page): Promise<Sample[]> {
  return page.evaluate(() => {
    const g = globalThis as unknown as { samples: Sample[]; sampler: number };
    clearInterval(g.sampler);
    return g.samples;
  });
}

test('a TalkingHead avatar speaks with the per-frame weights, in sync with the audio, from its own origin', async ({ page, guard }) => {
  test.setTimeout(240_000);
  await page.goto('/examples/talkinghead.html');
  await expect(page.locator('#log')).toHaveText(/^ready: \d+ frames/, { timeout: 150_000 });

  // TalkingHead loaded the project's avatar: its meshes with the 52 ARKit targets under the Armature.
  const loaded = await page.evaluate(() => {
    const head = (globalThis as unknown as { talkingHeadExample: { head: any } }).talkingHeadExample.head;
    return { root: head.armature.name, meshes: head.morphs.length, targets: Object.keys(head.morphs[0].morphTargetDictionary), height: head.avatarHeight };
  });
  expect(loaded.root).toBe('Armature');
  expect(loaded.meshes).toBe(1);
  for (const n of ARKIT_NAMES) expect(loaded.targets).toContain(n);
  expect(loaded.height).toBeGreaterThan(1.6);
  expect((await imageStats(page, await page.locator('#avatar').screenshot())).foregroundFraction, 'the avatar is drawn').toBeGreaterThan(0.02);
  // TalkingHead and its three.js came from the page's origin (any other origin fails the test: fixtures.ts).
  for (const path of ['/examples/vendor/talkinghead/modules/talkinghead.mjs', '/examples/vendor/three/build/three.module.js', '/examples/avatars/arkit-full-body.glb']) {
    expect(guard.requests.some((u) => new URL(u).pathname === path), path).toBe(true);
  }

  const take = await page.evaluate(() => {
    const { take } = (globalThis as unknown as { talkingHeadExample: { state: any } }).talkingHeadExample.state;
    return { frames: take.frames as number, fps: take.fps as number, arkit: Array.from(take.blendshapes.arkit as Float32Array), head: Array.from(take.blendshapes.headRotation as Float32Array) };
  });
  const weight = (name: string, f: number) => take.arkit[f * 52 + ARKIT_NAMES.indexOf(name as never)];

  // 1. Frame by frame: the page sets frame f in TalkingHead's update callback; its loop applies it in the same step.
  await startSampling(page, CHECKED);
  await page.locator('#speak').click();
  await expect(page.locator('#log')).toHaveText(`played ${take.frames} frames`, { timeout: 30_000 });
  const samples = (await stopSampling(page)).filter((s) => s.frame >= 0 && s.audioFrame >= 0 && s.audioFrame < take.frames);
  const frames = [...new Set(samples.map((s) => s.frame))];
  expect(frames.length, `distinct frames sampled: ${frames}`).toBeGreaterThanOrEqual(8);
  expect(Math.max(...frames) - Math.min(...frames), 'samples across the clip').toBeGreaterThan(take.frames / 2);
  // Exactly the take's frame once the take has blended in from TalkingHead's own face: 0.12 s from the first frame
  // shown (talkinghead.ts), whichever frame TalkingHead's loop first reached.
  const blended = Math.min(...frames) + Math.ceil(0.12 * take.fps) + 1;
  expect(samples.filter((s) => s.frame >= blended).length).toBeGreaterThanOrEqual(8);
  for (const s of samples.filter((x) => x.frame >= blended)) {
    for (const n of CHECKED) expect(s.influences[n], `${n} at frame ${s.frame}`).toBeCloseTo(weight(n, s.frame), 6);
    const [x, y, z] = talkingHeadAngles(take.head[3 * s.frame], take.head[3 * s.frame + 1], take.head[3 * s.frame + 2]);
    expect(s.head.x, `head x at frame ${s.frame}`).toBeCloseTo(x, 6);
    expect(s.head.y, `head y at frame ${s.frame}`).toBeCloseTo(y, 6);
    expect(s.head.z, `head z at frame ${s.frame}`).toBeCloseTo(z, 6);
  }
  // In sync: the frame shown is the one the audio clock was at when TalkingHead last stepped: never ahead of the
  // clock, and behind it by no more than the time since that step (plus the frame in progress).
  for (const s of samples) {
    const lag = s.audioFrame - s.frame;
    expect(lag, `frame ${s.frame} shown at the audio clock's frame ${s.audioFrame}`).toBeGreaterThanOrEqual(0);
    expect(lag, `frame ${s.frame} shown at the audio clock's frame ${s.audioFrame}, ${s.sinceStep.toFixed(0)} ms after TalkingHead's last step`)
      .toBeLessThanOrEqual(Math.ceil((s.sinceStep * take.fps) / 1000) + 1);
  }
  const steps = samples.map((s) => s.sinceStep).sort((a, b) => a - b);
  console.log(`frame by frame: ${samples.length} samples of ${frames.length} frames; since TalkingHead's last step: median ${steps[steps.length >> 1].toFixed(0)} ms`);
  // The mouth moved with the speech, and TalkingHead has it back after the take.
  const jaw = samples.map((s) => s.influences.jawOpen);
  expect(Math.max(...jaw) - Math.min(...jaw), 'jawOpen moves').toBeGreaterThan(0.15);
  const released = await page.evaluate((names) => {
    const head = (globalThis as unknown as { talkingHeadExample: { head: any } }).talkingHeadExample.head;
    return names.map((n: string) => head.mtAvatar[n].realtime);
  }, [...TALKINGHEAD_SHAPES, 'headRotateX', 'headRotateY', 'headRotateZ']);
  expect(released.every((r) => r === null), 'released to TalkingHead').toBe(true);

  // 2. Through speakAudio: TalkingHead plays the audio and the anim on its own clock. Past the blend-in (the anim's
  // first key is the first frame at 0.12 s or after, talkingHeadAnim), between the keys of frames k and k + 1 it eases
  // from one to the other: each influence lies between the two frames' weights.
  await startSampling(page, CHECKED);
  await page.locator('#speak-anim').click();
  await expect.poll(() => page.evaluate(() => (globalThis as unknown as { samples: Sample[] }).samples.some((s) => s.animTime !== null)), { timeout: 10_000 }).toBe(true);
  await expect.poll(() => page.evaluate(() => {
    const g = globalThis as unknown as { samples: Sample[] };
    return g.samples.length > 0 && g.samples[g.samples.length - 1].animTime === null;
  }), { timeout: 30_000, message: "the anim ends" }).toBe(true);
  const animSamples = (await stopSampling(page)).filter((s) => s.animTime !== null && s.animTime >= (Math.ceil(0.12 * take.fps) * 1000) / take.fps && s.animTime < ((take.frames - 1) * 1000) / take.fps);
  expect(animSamples.length).toBeGreaterThanOrEqual(8);
  for (const s of animSamples) {
    const k = Math.floor((s.animTime! * take.fps) / 1000);
    for (const n of CHECKED) {
      const [lo, hi] = [weight(n, k), weight(n, k + 1)].sort((a, b) => a - b);
      expect(s.influences[n], `${n} at ${s.animTime!.toFixed(1)} ms (frames ${k}, ${k + 1}: ${lo}..${hi})`).toBeGreaterThanOrEqual(lo - 1e-5);
      expect(s.influences[n], `${n} at ${s.animTime!.toFixed(1)} ms (frames ${k}, ${k + 1}: ${lo}..${hi})`).toBeLessThanOrEqual(hi + 1e-5);
    }
    expect(s.realtime.jawOpen, 'no realtime value while the anim plays').toBeNull();
  }
  const animJaw = animSamples.map((s) => s.influences.jawOpen);
  expect(Math.max(...animJaw) - Math.min(...animJaw), 'jawOpen moves').toBeGreaterThan(0.15);
  await expect(page.locator('#log')).not.toHaveText(/error/);
});

test("TalkingHead refuses a face-only avatar: the page says what it lacks", async ({ page, guard }) => {
  test.setTimeout(60_000);
  guard.allowConsoleError(/Avatar object Armature not found/);
  await page.goto('/examples/talkinghead.html?avatar=/examples/avatars/arkit-face.glb');
  await expect(page.locator('#log')).toHaveText("error: Avatar object Armature not found (TalkingHead needs a full-body avatar with Ready Player Me's bone names)", { timeout: 30_000 });
  await expect(page.locator('#speak')).toBeDisabled();
});
