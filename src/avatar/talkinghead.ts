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

/** What the driver uses of a TalkingHead instance: its morph-target state, one entry per name (Appendix F). */
export interface TalkingHeadLike {
  mtAvatar: Record<string, { realtime: number | null; needsUpdate: boolean }>;
}

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
    const A = ARKIT_NAMES.length;
    const mt = this.talkingHead.mtAvatar;
    for (const name of this.shapes) set(mt[name], blendshapes.arkit[f * A + ARKIT_INDEX[name]]);
    if (this.head) {
      const h = blendshapes.headRotation;
      talkingHeadAngles(h[3 * f], h[3 * f + 1], h[3 * f + 2]).forEach((angle, k) => set(mt[TALKINGHEAD_HEAD[k]], angle));
    }
    this.active = true;
  }

  /** One frame by name, as <talking-face>'s `frame` event carries it (`detail.arkit`, `detail.headRotation`). */
  showNamed(arkit: Partial<Record<ArkitName, number>>, headRotation?: { yaw: number; pitch: number; roll: number }): void {
    const mt = this.talkingHead.mtAvatar;
    for (const name of this.shapes) if (arkit[name] !== undefined) set(mt[name], arkit[name]);
    if (this.head && headRotation) {
      talkingHeadAngles(headRotation.yaw, headRotation.pitch, headRotation.roll).forEach((angle, k) => set(mt[TALKINGHEAD_HEAD[k]], angle));
    }
    this.active = true;
  }

  /** Hand the shapes and the head back to TalkingHead's own animation (realtime null), after speech. */
  release(): void {
    if (!this.active) return;
    const mt = this.talkingHead.mtAvatar;
    for (const name of [...this.shapes, ...(this.head ? TALKINGHEAD_HEAD : [])]) Object.assign(mt[name], { realtime: null, needsUpdate: true });
    this.active = false;
  }
}

function set(target: { realtime: number | null; needsUpdate: boolean }, value: number): void {
  target.realtime = value;
  target.needsUpdate = true;
}

/**
 * A take as TalkingHead's animation template for `speakAudio({ audio, anim })` (Appendix F): `dt` in ms per step,
 * `vs` the values per step by name. TalkingHead prepends the current value to each track and keys value k at the
 * sum of dt[0..k], so dt[0] is 0 (frame 0 at the start of the audio) and the rest 1000 / fps. Shapes that stay 0
 * throughout are left out.
 */
export function talkingHeadAnim(animation: Animation, options: TalkingHeadOptions = {}): { name: string; dt: number[]; vs: Record<string, number[]> } {
  const b = blendshapesOf(animation);
  const F = animation.frames;
  const A = ARKIT_NAMES.length;
  const round = (x: number) => Math.round(x * 1e5) / 1e5;
  const vs: Record<string, number[]> = {};
  for (const name of options.shapes ?? TALKINGHEAD_SHAPES) {
    const track = Array.from({ length: F }, (_, f) => round(b.arkit[f * A + ARKIT_INDEX[name]]));
    if (track.some((x) => x > 0)) vs[name] = track;
  }
  if (options.head ?? true) {
    const angles = Array.from({ length: F }, (_, f) => talkingHeadAngles(b.headRotation[3 * f], b.headRotation[3 * f + 1], b.headRotation[3 * f + 2]));
    TALKINGHEAD_HEAD.forEach((name, k) => (vs[name] = angles.map((a) => round(a[k]))));
  }
  return { name: 'blendshapes', dt: Array.from({ length: F }, (_, f) => (f === 0 ? 0 : 1000 / animation.fps)), vs };
}
