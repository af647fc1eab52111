/**
 * Playing the engine's output on a glTF avatar with no renderer (src/avatar/avatar-driver.ts), as a page with its own
 * three.js scene does and as <talking-face avatar> does through avatar-view.ts: the rest before speech, the blend in
 * and out, the head bone turned by the pose, idle blinks on top, and the takes it refuses.
 */
import { beforeEach, describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import * as THREE from 'three';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { AvatarDriver, BLEND_IN_SECONDS, BLEND_OUT_SECONDS } from '../../../src/avatar/avatar-driver';
import { LIVE_REST_FRAMES } from '../../../src/encoders/voice-activity';
import { ARKIT_INDEX, ARKIT_NAMES, VISEME_NAMES } from '../../../src/avatar/names';
import { ROOT } from '../helpers/exported';

const bytes = readFileSync(resolve(ROOT, 'examples/avatars/arkit-face.glb'));

/** A two-frame take: frame 0 silent, frame 1 the jaw open by 0.6 and the head nodded 0.2 rad about x. */
function take() {
  const arkit = new Float32Array(2 * ARKIT_NAMES.length);
  arkit[ARKIT_NAMES.length + ARKIT_INDEX.jawOpen] = 0.6;
  const visemes = new Float32Array(2 * VISEME_NAMES.length);
  visemes[0] = 1;
  visemes[VISEME_NAMES.length + 10] = 1;
  const pose = new Float32Array(12);
  pose[6] = 0.2;
  return { fps: 30, frames: 2, pose, blendshapes: { arkit, visemes, headRotation: new Float32Array(6) } };
}

describe('AvatarDriver', () => {
  let avatar: GltfAvatar, driver: AvatarDriver, weight: (name: string) => number, nod: () => number;
  beforeEach(async () => {
    avatar = await GltfAvatar.parse(bytes, 'arkit-face.glb');
    let mesh!: THREE.Mesh;
    avatar.gltf.scene.traverse((o) => { if ((o as THREE.Mesh).morphTargetInfluences) mesh = o as THREE.Mesh; });
    weight = (name) => mesh.morphTargetInfluences![mesh.morphTargetDictionary![name]];
    const rest = avatar.head!.quaternion.clone();
    nod = () => avatar.head!.quaternion.angleTo(rest);
    driver = new AvatarDriver(avatar, 0, () => 0.5);
    driver.blinking = false;
  });

  it('shows the rest before speech, blends a frame in over BLEND_IN_SECONDS and back out over BLEND_OUT_SECONDS', () => {
    const rest = new Float32Array(ARKIT_NAMES.length);
    rest[ARKIT_INDEX.mouthRollLower] = 0.16;
    driver.setRest(rest);
    expect(weight('mouthRollLower')).toBeCloseTo(0.16, 6);
    const t = take();
    driver.show(t, 1);
    expect(weight('jawOpen')).toBe(0); // not yet blended in
    driver.update(0);
    driver.update(1000 * BLEND_IN_SECONDS / 2);
    expect(weight('jawOpen')).toBeCloseTo(0.3, 5);
    expect(weight('mouthRollLower')).toBeCloseTo(0.08, 5);
    expect(nod()).toBeCloseTo(0.1, 5);
    driver.update(1000 * BLEND_IN_SECONDS);
    expect(driver.speechWeight).toBe(1);
    expect(weight('jawOpen')).toBeCloseTo(0.6, 6);
    expect(nod()).toBeCloseTo(0.2, 5);
    driver.show(t, 0); // at full weight, a frame is shown as it is
    expect(weight('jawOpen')).toBe(0);
    expect(nod()).toBeLessThan(1e-6);
    driver.show(t, 1.7); // a fractional frame (seconds x fps) is its floor
    expect(weight('jawOpen')).toBeCloseTo(0.6, 6);
    expect(driver.update(2000)).toBe(false); // nothing moves: a page that renders on change does not
    driver.setSpeaking(false);
    driver.update(3000);
    driver.update(3000 + 1000 * BLEND_OUT_SECONDS / 4);
    expect(weight('jawOpen')).toBeCloseTo(0.45, 5);
    driver.update(3000 + 1000 * BLEND_OUT_SECONDS);
    expect([driver.speechWeight, weight('jawOpen'), weight('mouthRollLower')]).toEqual([0, 0, expect.closeTo(0.16, 6)]);
    expect(nod()).toBeLessThan(1e-6);
  });

  it('blinks on top of the weights when blinking, and not when not', () => {
    const seen = (on: boolean) => {
      driver.blinking = on;
      let most = 0;
      for (let ms = 0; ms < 20000; ms += 10) { driver.update(ms); most = Math.max(most, weight('eyeBlinkLeft')); }
      return most;
    };
    expect(seen(false)).toBe(0);
    expect(seen(true)).toBeGreaterThan(0.9);
  });

  it('refuses a take without blend shapes, a frame out of range, and a rest of the wrong length, saying so', () => {
    const t = take();
    expect(() => driver.show({ pose: t.pose }, 0)).toThrow(/no blend-shape output: animate .* with \{ blendshapes: true \}/);
    expect(() => driver.show(t, 2)).toThrow(/frame 2 is outside 0\.\.1/);
    expect(() => driver.show(t, -1)).toThrow(RangeError);
    expect(() => driver.show(t, NaN)).toThrow(RangeError);
    expect(() => driver.setRest(new Float32Array(15))).toThrow(/expected 52 ARKit weights, got 15/);
  });

  it("turns the head on top of the page's own animation of it, once per update, with headOnTop", () => {
    driver.headOnTop = true;
    const head = avatar.head!, t = take();
    driver.show(t, 1);
    driver.update(0);
    driver.update(1000); // blended in: the take's nod of 0.2 rad
    const animated = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 1, 0), 0.3);
    for (const now of [1100, 1200, 1300]) {
      head.quaternion.copy(animated); // the page's mixer sets the bone each frame
      driver.show(t, 1); // the driver's show() leaves it to update()
      expect(head.quaternion.angleTo(animated)).toBeLessThan(1e-6);
      driver.update(now);
      // The nod on top of the animated rotation (the avatar's root and the bone's parents are not turned here).
      const want = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(1, 0, 0), 0.2).multiply(animated);
      expect(head.quaternion.angleTo(want), `at ${now} ms`).toBeLessThan(1e-6);
    }
  });

  it('goes back to rest after LIVE_REST_FRAMES live frames without speech, and speaks again when speech comes', () => {
    const t = { ...take(), speech: Float32Array.from([0, 0.9]) }; // frame 0 quiet, frame 1 speech
    driver.showLive(t, 0);
    driver.update(0);
    driver.update(1000);
    expect(driver.speechWeight, 'no speech heard yet: at rest').toBe(0);
    driver.showLive(t, 1);
    driver.update(2000);
    driver.update(3000);
    expect(driver.speechWeight).toBe(1);
    for (let k = 1; k < LIVE_REST_FRAMES; k++) driver.showLive(t, 0); // a breath between words
    driver.update(4000);
    expect(driver.speechWeight).toBe(1);
    driver.showLive(t, 0); // the LIVE_REST_FRAMES-th quiet frame
    driver.update(5000);
    driver.update(6000);
    expect(driver.speechWeight).toBe(0);
    driver.showLive(t, 1);
    driver.update(7000);
    driver.update(8000);
    expect(driver.speechWeight).toBe(1);
  });

  it('with headOnTop and nothing animating the head, the turn stays one turn and goes when speech ends', () => {
    driver.headOnTop = true;
    const head = avatar.head!, rest = head.quaternion.clone(), t = take();
    driver.show(t, 1);
    for (let ms = 0; ms <= 1000; ms += 100) driver.update(ms); // no clip sets the bone between updates
    expect(head.quaternion.angleTo(rest)).toBeCloseTo(0.2, 5);
    driver.setSpeaking(false);
    for (let ms = 1000; ms <= 2000; ms += 100) driver.update(ms);
    expect(head.quaternion.angleTo(rest)).toBeLessThan(1e-6);
  });

  it('says what it takes when given something else', () => {
    expect(() => new AvatarDriver({ scene: {} } as never)).toThrow(/AvatarDriver takes a GltfAvatar: new AvatarDriver\(GltfAvatar\.bind\(gltf, name\)\)/);
  });
});
