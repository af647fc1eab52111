/**
 * This project's per-frame output driving a TalkingHead avatar (@met4citizen/talkinghead, MIT) through TalkingHead's
 * own direct blend-shape control (its README, Appendix F), for mouth shapes its 15 visemes cannot give. Two ways:
 *
 * - TalkingHeadDriver: frame by frame, through the `realtime` value of `head.mtAvatar[name]`, which overrides
 *   TalkingHead's own animation of that shape (except a `setFixedValue`) until it is set back to null. Call
 *   `show()` from TalkingHead's `update` option (its animation loop calls it just before it applies the morph
 *   targets), so the frame set is the frame drawn.
 * - talkingHeadAnim: a whole take as the `anim` of `head.speakAudio({ audio, anim })`, which TalkingHead plays on its
 *   own clock with the audio it plays.
 *
 * Which shapes: those the model moves. The eight eyeLook shapes and tongueOut are always 0 (docs/avatar.md, "The
 * solver") and the model's eyeBlink weights stay near 0 (it does not predict blinks): driving them would stop
 * TalkingHead's gaze and blinks, so they are left to TalkingHead. The head turns through TalkingHead's headRotateX /
 * Y / Z, Euler angles (XYZ) about the head bone's own axes (its updatePoseDelta); they are converted from this
 * project's yaw, pitch and roll (R_y R_x R_z), which is exact where the head bone's axes are the face's (+y up,
 * +z forward: Ready Player Me's rig and examples/avatars/arkit-full-body.glb). TalkingHead adds its own body sway
 * (bodyRotateX / Y / Z) on top.
 *
 * No dependency on the package: the driver needs only `mtAvatar` (TalkingHeadLike).
 */
import * as THREE from 'three';
import type { Animation } from '../engine/frames';
import { blendshapesOf, type BlendshapeFrames } from './weights';
import { ARKIT_INDEX, ARKIT_NAMES, type ArkitName } from './names';

/** One shape's state in TalkingHead: `value` what it shows, `realtime` an override of its own animation. */
interface Shape { realtime: number | null; needsUpdate: boolean; value?: number }

/** What the driver uses of a TalkingHead instance: its morph-target state, one entry per name (Appendix F). */
export interface TalkingHeadLike {
  mtAvatar: Record<string, Shape>;
}

/**
 * Seconds over which a take takes over from TalkingHead's own animation (the shapes and the head blend from what
 * TalkingHead showed), as this project's own views blend speech in (face-view.ts): not a jump at the first frame.
 */
const BLEND_IN = 0.12;

/** The ARKit shapes handed to TalkingHead: all but eyeLook*, eyeBlink* and tongueOut (see above). */
export const TALKINGHEAD_SHAPES: readonly ArkitName[] = ARKIT_NAMES.filter((n) => !/^eyeLook|^eyeBlink|^tongueOut$/.test(n));

/** TalkingHead's names for the head's rotation about the head bone's x, y and z axes (radians). */
export const TALKINGHEAD_HEAD = ['headRotateX', 'headRotateY', 'headRotateZ'] as const;

const euler = new THREE.Euler();
const quaternion = new THREE.Quaternion();

/** Yaw, pitch, roll (R = R_y(yaw) R_x(pitch) R_z(roll)) as TalkingHead's [headRotateX, headRotateY, headRotateZ] (Euler XYZ). */
export function talkingHeadAngles(yaw: number, pitch: number, roll: number): [number, number, number] {
  quaternion.setFromEuler(euler.set(pitch, yaw, roll, 'YXZ'));
  euler.setFromQuaternion(quaternion, 'XYZ');
  return [euler.x, euler.y, euler.z];
}

export interface TalkingHeadOptions {
  /** The ARKit shapes to drive (default TALKINGHEAD_SHAPES). */
  shapes?: readonly ArkitName[];
  /** Turn the head with the predicted rotation (default true). */
  head?: boolean;
}

/** Drives a TalkingHead instance's morph targets and head from frames of this project's output, in real time. */
export class TalkingHeadDriver {
  /** The shapes driven that the avatar has (TalkingHead knows a shape only if one of its meshes has it). */
  readonly shapes: readonly ArkitName[];
  /** The shapes asked for that the avatar lacks: they are not shown. */
  readonly missing: readonly ArkitName[];
  private readonly head: boolean;
  private active = false;
  /** When the take took over (performance.now(), ms) and what TalkingHead showed then, by name. */
  private since = 0;
  private readonly from = new Map<string, number>();

  constructor(private readonly talkingHead: TalkingHeadLike, options: TalkingHeadOptions = {}) {
    if (!talkingHead?.mtAvatar || !('headRotateX' in talkingHead.mtAvatar)) {
      throw new Error('TalkingHeadDriver: the TalkingHead instance has no avatar yet: await head.showAvatar(...) first');
    }
    const asked = options.shapes ?? TALKINGHEAD_SHAPES;
    this.shapes = asked.filter((n) => n in talkingHead.mtAvatar);
    this.missing = asked.filter((n) => !(n in talkingHead.mtAvatar));
    this.head = options.head ?? true;
  }

  /** Frame `f` of a take's (or a streamed chunk's) blend-shape output. */
  show(blendshapes: BlendshapeFrames, f: number): void {
    if (!blendshapes?.arkit) throw new TypeError('TalkingHeadDriver.show: the take has no blend shapes: animate it with { blendshapes: true }');
    const A = ARKIT_NAMES.length;
    const w = this.takeOver();
    for (const name of this.shapes) this.set(name, blendshapes.arkit[f * A + ARKIT_INDEX[name]], w);
    if (this.head) {
      const h = blendshapes.headRotation;
      talkingHeadAngles(h[3 * f], h[3 * f + 1], h[3 * f + 2]).forEach((angle, k) => this.set(TALKINGHEAD_HEAD[k], angle, w));
    }
  }

  /** One frame by name, as <talking-face>'s `frame` event carries it (`detail.arkit`, `detail.headRotation`). */
  showNamed(arkit: Partial<Record<ArkitName, number>>, headRotation?: { yaw: number; pitch: number; roll: number }): void {
    if (!arkit) throw new TypeError('TalkingHeadDriver.showNamed: the frame has no ARKit weights: give <talking-face> the blendshapes attribute (or an avatar)');
    const w = this.takeOver();
    for (const name of this.shapes) if (arkit[name] !== undefined) this.set(name, arkit[name], w);
    if (this.head && headRotation) {
      talkingHeadAngles(headRotation.yaw, headRotation.pitch, headRotation.roll).forEach((angle, k) => this.set(TALKINGHEAD_HEAD[k], angle, w));
    }
  }

  /** Hand the shapes and the head back to TalkingHead's own animation (realtime null), after speech. */
  release(): void {
    if (!this.active) return;
    const mt = this.talkingHead.mtAvatar;
    for (const name of this.driven()) if (mt[name]) Object.assign(mt[name], { realtime: null, needsUpdate: true });
    this.active = false;
  }

  private driven(): readonly string[] {
    return this.head ? [...this.shapes, ...TALKINGHEAD_HEAD] : this.shapes;
  }

  /** How far the take has taken over (0 at its first frame, 1 after BLEND_IN); the first frame notes what was shown. */
  private takeOver(): number {
    const now = performance.now();
    if (!this.active) {
      [this.active, this.since] = [true, now];
      for (const name of this.driven()) this.from.set(name, this.talkingHead.mtAvatar[name]?.value ?? 0);
    }
    return Math.min(1, (now - this.since) / (BLEND_IN * 1000));
  }

  /**
   * Shape `name` at `value`, `w` of the way from what TalkingHead showed. A shape the avatar no longer has (another
   * avatar shown since the driver was made: make a new driver for it) is skipped, not a TypeError in TalkingHead's loop.
   */
  private set(name: string, value: number, w: number): void {
    const target = this.talkingHead.mtAvatar[name];
    if (!target) return;
    target.realtime = w >= 1 ? value : (this.from.get(name) ?? 0) + w * (value - (this.from.get(name) ?? 0));
    target.needsUpdate = true;
  }
}

/**
 * A take as TalkingHead's animation template for `speakAudio({ audio, anim })` (Appendix F): `dt` in ms per step,
 * `vs` the values per step by name. TalkingHead prepends the current value to each track and keys value k at the
 * sum of dt[0..k]. So that the take blends in from what TalkingHead showed, as the driver's does (BLEND_IN), the
 * frames before 0.12 s are left out and dt[0] is the first kept frame's time: TalkingHead eases from its current
 * value to that frame over those 0.12 s, and every frame k after is shown k / fps after the audio starts (dt 1000 /
 * fps). Shapes that stay 0 throughout are left out.
 */
export function talkingHeadAnim(animation: Animation, options: TalkingHeadOptions = {}): { name: string; dt: number[]; vs: Record<string, number[]> } {
  const b = blendshapesOf(animation);
  const F = animation.frames;
  const A = ARKIT_NAMES.length;
  const first = Math.max(0, Math.min(Math.ceil(BLEND_IN * animation.fps), F - 1));
  const frames = Array.from({ length: F - first }, (_, i) => first + i);
  const round = (x: number) => Math.round(x * 1e5) / 1e5;
  const vs: Record<string, number[]> = {};
  for (const name of options.shapes ?? TALKINGHEAD_SHAPES) {
    const track = frames.map((f) => round(b.arkit[f * A + ARKIT_INDEX[name]]));
    if (track.some((x) => x > 0)) vs[name] = track;
  }
  if (options.head ?? true) {
    const angles = frames.map((f) => talkingHeadAngles(b.headRotation[3 * f], b.headRotation[3 * f + 1], b.headRotation[3 * f + 2]));
    TALKINGHEAD_HEAD.forEach((name, k) => (vs[name] = angles.map((a) => round(a[k]))));
  }
  return { name: 'blendshapes', dt: frames.map((f, i) => (i === 0 ? f : 1) * 1000 / animation.fps), vs };
}
