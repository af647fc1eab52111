/**
 * This project's output driving a TalkingHead avatar (src/avatar/talkinghead.ts): the real-time driver on a
 * stand-in for TalkingHead's morph-target state, the head angles, the `anim` for speakAudio; then TalkingHead 1.7.0
 * itself, run in Node (helpers/talkinghead.ts): it refuses the face-only test avatars, loads the full-body one
 * (examples/avatars/arkit-full-body.glb) and stands it on the floor, shows the frame the driver sets in the same
 * step of its loop, and plays the anim with frame k of the take at k / fps after the audio starts. The browser
 * page and the sync with audio playback: tests/e2e/talkinghead.spec.ts.
 */
import { afterEach, beforeAll, beforeEach, describe, expect, it, vi } from 'vitest';
import * as THREE from 'three';
import type { TalkingHead } from '@met4citizen/talkinghead';
import { avatarUrl, talkingHeadInNode } from '../helpers/talkinghead';
import { TALKINGHEAD_SHAPES, TalkingHeadDriver, talkingHeadAngles, talkingHeadAnim } from '../../../src/avatar/talkinghead';
import { ARKIT_NAMES } from '../../../src/avatar/names';
import { emptyBlendshapes, type Animation } from '../../../src/engine/frames';

/** 40 frames at 30 fps: jawOpen = f / 40, mouthRight = 0.5, eyeBlinkLeft only at frame 7; head yaw 0.01 f, pitch -0.005 f. */
function take(): Animation {
  const F = 40;
  const b = emptyBlendshapes(F);
  for (let f = 0; f < F; f++) {
    b.arkit[f * 52 + ARKIT_NAMES.indexOf('jawOpen')] = f / F;
    b.arkit[f * 52 + ARKIT_NAMES.indexOf('mouthRight')] = 0.5;
    b.headRotation.set([0.01 * f, -0.005 * f, 0], f * 3);
  }
  b.arkit[7 * 52 + ARKIT_NAMES.indexOf('eyeBlinkLeft')] = 1;
  return { fps: 30, frames: F, vertices: new Float32Array(0), pose: new Float32Array(F * 6), phones: new Uint8Array(F), tongue: new Float32Array(F), speech: new Float32Array(F), blendshapes: b };
}

/** performance.now() as the tests set it (ms): the driver blends a take in over its first 0.12 s. */
let now = 0;
beforeEach(() => {
  now = 1000;
  vi.spyOn(performance, 'now').mockImplementation(() => now);
});
afterEach(() => vi.restoreAllMocks());

/** TalkingHead's morph-target state as showAvatar leaves it, for an avatar with these shapes. */
function stateFor(names: readonly string[]) {
  const mt: Record<string, { realtime: number | null; needsUpdate: boolean }> = {};
  for (const n of [...names, 'headRotateX', 'headRotateY', 'headRotateZ', 'bodyRotateX']) mt[n] = { realtime: null, needsUpdate: false };
  return { mtAvatar: mt };
}

describe('TalkingHeadDriver', () => {
  it("sets the realtime value of each shape the model moves, and the head's three angles", () => {
    const head = stateFor(ARKIT_NAMES);
    const driver = new TalkingHeadDriver(head);
    expect(driver.shapes).toEqual(TALKINGHEAD_SHAPES);
    expect(TALKINGHEAD_SHAPES).toHaveLength(52 - 8 - 2 - 1);
    // The take blends in from what TalkingHead showed, over 0.12 s: no jump at its first frame.
    Object.assign(head.mtAvatar.mouthRight, { value: 0.1 });
    driver.show(take().blendshapes!, 10);
    expect(head.mtAvatar.mouthRight.realtime).toBe(0.1);
    expect(head.mtAvatar.jawOpen.realtime).toBe(0);
    now += 60;
    driver.show(take().blendshapes!, 10);
    expect(head.mtAvatar.mouthRight.realtime).toBeCloseTo(0.3, 9);
    expect(head.mtAvatar.jawOpen.realtime).toBeCloseTo(0.125, 9);
    now += 60;
    driver.show(take().blendshapes!, 10);
    expect(head.mtAvatar.jawOpen).toEqual({ realtime: 0.25, needsUpdate: true });
    expect(head.mtAvatar.mouthRight.realtime).toBe(0.5);
    expect(head.mtAvatar.mouthLeft.realtime).toBe(0); // driven, at 0
    // The eyes' gaze and blinks, and the tongue, stay TalkingHead's.
    for (const n of ['eyeBlinkLeft', 'eyeLookInLeft', 'eyeLookDownRight', 'tongueOut']) expect(head.mtAvatar[n]).toEqual({ realtime: null, needsUpdate: false });
    expect(head.mtAvatar.headRotateY.realtime).toBeCloseTo(0.1, 3);
    expect(head.mtAvatar.headRotateX.realtime).toBeCloseTo(-0.05, 3);
    expect(head.mtAvatar.bodyRotateX.realtime).toBeNull(); // TalkingHead's body sway stays
    driver.release();
    for (const n of [...TALKINGHEAD_SHAPES, 'headRotateX', 'headRotateY', 'headRotateZ']) expect(head.mtAvatar[n]).toMatchObject({ realtime: null, needsUpdate: true });
    // The next take blends in again.
    driver.show(take().blendshapes!, 10);
    expect(head.mtAvatar.jawOpen.realtime).toBe(0);
  });

  it('another avatar shown under a driver: the shapes it lacks are skipped, not a TypeError in TalkingHead\'s loop', () => {
    const head = stateFor(ARKIT_NAMES);
    const driver = new TalkingHeadDriver(head);
    head.mtAvatar = stateFor(['jawOpen']).mtAvatar; // head.showAvatar(another) replaces the state
    driver.show(take().blendshapes!, 10);
    now += 200;
    driver.show(take().blendshapes!, 10);
    expect(head.mtAvatar.jawOpen.realtime).toBe(0.25);
    expect(() => driver.release()).not.toThrow();
    expect(head.mtAvatar.jawOpen.realtime).toBeNull();
  });

  it('a frame without weights says what to give', () => {
    const driver = new TalkingHeadDriver(stateFor(ARKIT_NAMES));
    expect(() => driver.showNamed(undefined as never)).toThrow(/blendshapes attribute/);
    expect(() => driver.show(undefined as never, 0)).toThrow(/blendshapes: true/);
  });

  it('by name, as a frame event carries it; shapes the avatar lacks are listed, not set', () => {
    const head = stateFor(['jawOpen', 'mouthClose']);
    const driver = new TalkingHeadDriver(head, { head: false });
    expect(driver.shapes).toEqual(['jawOpen', 'mouthClose']);
    expect(driver.missing).toContain('mouthFunnel');
    driver.showNamed({ jawOpen: 0.4, mouthClose: 0.1, mouthFunnel: 0.3 }, { yaw: 0.2, pitch: 0, roll: 0 });
    now += 200;
    driver.showNamed({ jawOpen: 0.4, mouthClose: 0.1, mouthFunnel: 0.3 }, { yaw: 0.2, pitch: 0, roll: 0 });
    expect(head.mtAvatar.jawOpen.realtime).toBe(0.4);
    expect(head.mtAvatar.mouthFunnel).toBeUndefined();
    expect(head.mtAvatar.headRotateY.realtime).toBeNull(); // head: false
  });

  it('says what to do when the instance has no avatar yet', () => {
    expect(() => new TalkingHeadDriver({ mtAvatar: {} })).toThrow(/await head\.showAvatar/);
  });
});

describe('talkingHeadAngles', () => {
  it("gives the same rotation in TalkingHead's XYZ order as yaw, pitch, roll in YXZ", () => {
    const [yaw, pitch, roll] = [0.3, -0.2, 0.15];
    const [x, y, z] = talkingHeadAngles(yaw, pitch, roll);
    const ours = new THREE.Quaternion().setFromEuler(new THREE.Euler(pitch, yaw, roll, 'YXZ'));
    const theirs = new THREE.Quaternion().setFromEuler(new THREE.Euler(x, y, z, 'XYZ'));
    expect(Math.abs(ours.dot(theirs))).toBeCloseTo(1, 9);
    expect(talkingHeadAngles(0.02, 0.01, 0)).toEqual([expect.closeTo(0.01, 3), expect.closeTo(0.02, 3), expect.closeTo(0, 3)]);
  });
});

describe('talkingHeadAnim', () => {
  it('the shapes that move and the head from the first frame at 0.12 s or after, keyed at its time, then 1000 / fps', () => {
    const a = talkingHeadAnim(take());
    expect(a.name).toBe('blendshapes');
    expect(a.dt).toHaveLength(36); // frames 4 to 39: the take blends in from TalkingHead's own values until frame 4
    expect(a.dt[0]).toBeCloseTo(4000 / 30, 9);
    expect(a.dt[1]).toBeCloseTo(1000 / 30, 9);
    expect(Object.keys(a.vs).sort()).toEqual(['headRotateX', 'headRotateY', 'headRotateZ', 'jawOpen', 'mouthRight']); // no eyeBlinkLeft
    expect(a.vs.jawOpen[10 - 4]).toBeCloseTo(0.25, 5);
    expect(talkingHeadAnim({ ...take(), frames: 2 }).dt).toEqual([1000 / 30]); // a take shorter than the blend: its last frame
    expect(() => talkingHeadAnim({ ...take(), blendshapes: undefined })).toThrow(/animate with \{ blendshapes: true \}/);
  });
});

describe('TalkingHead 1.7.0 itself (in Node) with the test avatars', () => {
  let head: TalkingHead;
  const step = (n = 1) => { for (let i = 0; i < n; i++) head.animate(1000 / 30); };
  const influence = (name: string) => head.morphs[0].morphTargetInfluences[head.morphs[0].morphTargetDictionary[name]];
  beforeAll(async () => {
    head = await talkingHeadInNode();
    await head.showAvatar({ url: avatarUrl('arkit-full-body.glb'), body: 'M', avatarMood: 'neutral' });
  });

  it('refuses the face-only avatars: it needs a root "Armature" and then every bone of a full body', async () => {
    for (const file of ['arkit-face.glb', 'visemes-face.glb']) {
      await expect((await talkingHeadInNode()).showAvatar({ url: avatarUrl(file) })).rejects.toThrow('Avatar object Armature not found');
    }
    await expect((await talkingHeadInNode({ modelRoot: 'Head' })).showAvatar({ url: avatarUrl('arkit-face.glb') })).rejects.toThrow('Avatar object Hips not found');
  });

  it("loads the full-body one: the face's 52 ARKit targets, standing on the floor, the eyes at head height", () => {
    expect(head.morphs).toHaveLength(1);
    for (const name of ARKIT_NAMES) expect(head.morphs[0].morphTargetDictionary, name).toHaveProperty(name);
    for (const name of ARKIT_NAMES) expect(head.mtAvatar, name).toHaveProperty(name);
    step(60);
    head.armature.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(head.armature);
    expect(Math.abs(box.min.y), 'the lowest point, on the floor').toBeLessThan(0.03);
    const eye = head.armature.getObjectByName('LeftEye')!.getWorldPosition(new THREE.Vector3());
    expect(eye.y).toBeGreaterThan(1.5);
    expect(eye.y).toBeLessThan(1.75);
    expect(head.avatarHeight).toBeCloseTo(eye.y + 0.2, 1);
  });

  it('shows the frame the driver sets in the same step of its loop, head included; release hands the face back', () => {
    const b = take().blendshapes!;
    const driver = new TalkingHeadDriver(head);
    expect(driver.missing).toEqual([]);
    driver.show(b, 0);
    now += 200; // past the blend-in
    for (const f of [5, 20, 39]) {
      driver.show(b, f);
      step();
      expect(influence('jawOpen'), `jawOpen at frame ${f}`).toBeCloseTo(f / 40, 6);
      expect(influence('mouthRight')).toBeCloseTo(0.5, 6);
      expect(influence('mouthLeft')).toBe(0);
      const [x, y] = talkingHeadAngles(0.01 * f, -0.005 * f, 0);
      expect(head.mtAvatar.headRotateY.applied).toBeCloseTo(y, 6);
      // The head bone's delta: the head's own turn plus TalkingHead's body sway.
      const delta = head.poseDelta.props['Head.quaternion'];
      expect(delta.y - head.mtAvatar.bodyRotateY.applied).toBeCloseTo(y, 6);
      expect(delta.x - head.mtAvatar.bodyRotateX.applied).toBeCloseTo(x, 6);
    }
    expect(head.mtAvatar.eyeBlinkLeft.realtime).toBeNull();
    driver.release();
    step(60);
    expect(influence('jawOpen'), 'back to its rest').toBeLessThan(0.05);
  });

  it("plays speakAudio's anim with frame k of the take at k / fps after the audio starts, on its own clock", async () => {
    const t = take();
    head.speakAudio({ audio: { duration: t.frames / t.fps }, anim: talkingHeadAnim(t) }, { isRaw: true });
    await new Promise((r) => setTimeout(r, 0)); // startSpeaking and playAudio are async
    const anim = head.animQueue.find((a) => a.template.name === 'blendshapes');
    expect(anim, 'the anim is queued when the audio starts').toBeDefined();
    expect(anim!.ts[0]).toBeCloseTo(head.animClock, 6);
    for (let k = 1; k < t.frames; k++) {
      step();
      if (k % 7 === 0 || k === t.frames - 1) expect(influence('jawOpen'), `frame ${k}`).toBeCloseTo(k / 40, 3);
    }
    expect(influence('mouthRight')).toBeCloseTo(0.5, 3);
  });

  it("blends speakAudio's anim in from what TalkingHead showed over 0.12 s, not a jump at its first frame", async () => {
    head = await talkingHeadInNode(); // a TalkingHead of its own: another's speakAudio waits for the last take's audio to end
    await head.showAvatar({ url: avatarUrl('arkit-full-body.glb'), body: 'M', avatarMood: 'neutral' });
    step(30);
    const t = take();
    const jaw = ARKIT_NAMES.indexOf('jawOpen');
    for (let f = 0; f < t.frames; f++) t.blendshapes!.arkit[f * 52 + jaw] = 0.6;
    const before = influence('jawOpen');
    head.speakAudio({ audio: { duration: t.frames / t.fps }, anim: talkingHeadAnim(t) }, { isRaw: true });
    await new Promise((r) => setTimeout(r, 0)); // startSpeaking and playAudio are async
    expect(head.animQueue.some((a) => a.template.name === 'blendshapes')).toBe(true);
    const seen = Array.from({ length: 6 }, () => (step(), influence('jawOpen')));
    expect(before).toBeLessThan(0.05);
    expect(seen[0], 'one step in').toBeLessThan(0.35);
    for (let k = 1; k < 4; k++) expect(seen[k], `step ${k + 1}`).toBeGreaterThan(seen[k - 1]);
    expect(seen[5]).toBeCloseTo(0.6, 2);
  });
});
