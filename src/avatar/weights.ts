/**
 * The avatar stage after posing: per frame, the 52 ARKit weights (the solver on the model's displacement), the
 * 15 Oculus visemes (the content encoder's posteriors) and the head rotation as yaw, pitch and roll. The engine
 * runs it only when asked (`blendshapes: true`), so nothing else gets slower. Library code: no DOM.
 */
import type { FaceTemplate } from '../template/face-template';
import { ARKIT_NAMES, VISEME_NAMES, type ArkitName, type VisemeName } from './names';
import { arkitBasis, type ArkitBasis } from './basis';
import { BlendshapeSolver, type SolverState } from './solver';
import { VisemeMap } from './visemes';

/** What the stage adds to each chunk of frames. */
export interface BlendshapeFrames {
  /** (count x 52) ARKit weights in [0, 1], ARKIT_NAMES order. */
  arkit: Float32Array;
  /** (count x 15) Oculus viseme weights (each row sums to 1), VISEME_NAMES order. */
  visemes: Float32Array;
  /** (count x 3) head yaw, pitch, roll in radians (R = R_y(yaw) R_x(pitch) R_z(roll), the template's axes). */
  headRotation: Float32Array;
}

export class AvatarWeights {
  readonly basis: ArkitBasis;
  readonly solver: BlendshapeSolver;
  private readonly visemeMap: VisemeMap;

  constructor(template: FaceTemplate, contentPhones: readonly string[]) {
    this.basis = arkitBasis(template);
    this.solver = new BlendshapeSolver(this.basis);
    this.visemeMap = new VisemeMap(contentPhones);
  }

  newState(): SolverState {
    return this.solver.newState();
  }

  /**
   * A chunk's weights: `offsets` (count x N x 3) the model's displacement O in mm, `pose` (count x 6) the head
   * pose, `posteriors` (count x classes) each frame's phone posteriors. `state` carries the solver's warm start.
   */
  frames(state: SolverState, offsets: Float32Array, pose: Float32Array, posteriors: Float32Array, count: number): BlendshapeFrames {
    const n3 = this.basis.n * 3;
    const arkit = new Float32Array(count * ARKIT_NAMES.length);
    for (let f = 0; f < count; f++) this.solver.solve(offsets, f * n3, state, arkit, f * ARKIT_NAMES.length);
    const visemes = this.visemeMap.weights(posteriors, count, new Float32Array(count * VISEME_NAMES.length));
    const headRotation = new Float32Array(count * 3);
    for (let f = 0; f < count; f++) yawPitchRoll(pose, f * 6, headRotation, f * 3);
    return { arkit, visemes, headRotation };
  }
}

/**
 * The axis-angle rotation at pose[at..at+3) as yaw (about +y, up), pitch (about +x) and roll (about +z, towards
 * the viewer), radians, in that order of application: R = R_y(yaw) R_x(pitch) R_z(roll), as three.js's 'YXZ'.
 */
export function yawPitchRoll(pose: ArrayLike<number>, at: number, out: Float32Array, outAt: number): void {
  const rx = pose[at], ry = pose[at + 1], rz = pose[at + 2];
  const th = Math.hypot(rx, ry, rz);
  const a = th < 1e-6 ? 1 - (th * th) / 6 : Math.sin(th) / th;
  const b = th < 1e-6 ? 0.5 - (th * th) / 24 : (1 - Math.cos(th)) / (th * th);
  // Rodrigues: R = I + a K + b K^2 (row-major entries used below).
  const r02 = a * ry + b * rx * rz, r12 = -a * rx + b * ry * rz, r22 = 1 - b * (rx * rx + ry * ry);
  const r10 = a * rz + b * rx * ry, r11 = 1 - b * (rx * rx + rz * rz);
  const pitch = Math.asin(Math.min(1, Math.max(-1, -r12)));
  out[outAt] = Math.atan2(r02, r22);
  out[outAt + 1] = pitch;
  out[outAt + 2] = Math.atan2(r10, r11);
}

/** One frame of the output by name, as <talking-face>'s `frame` event carries it. */
/**
 * A take's blend-shape output, or an error that says what was given instead: no take yet (null, e.g. an element's
 * currentAnimation before it has spoken), something that is no take, or a take animated without blend shapes.
 */
export function blendshapesOf(animation: { blendshapes?: BlendshapeFrames; frames?: number } | null | undefined): BlendshapeFrames {
  if (animation == null) throw new TypeError(`no take to export (${animation}): animate or speak first`);
  if (typeof animation !== 'object' || !Number.isInteger(animation.frames)) throw new TypeError('expected a take (an Animation from animate(), or an element\'s currentAnimation)');
  if (!animation.blendshapes) throw new Error('the animation has no blend-shape output: animate with { blendshapes: true }');
  return animation.blendshapes;
}

export interface FrameWeights {
  /** The 52 ARKit weights by ARKit's names (jawOpen, mouthClose, eyeBlinkLeft, ...). */
  arkit: Record<ArkitName, number>;
  /** The 15 Oculus visemes by name (viseme_sil, viseme_PP, ... viseme_U). */
  visemes: Record<VisemeName, number>;
  /** The head's rotation, radians: yaw (about up), pitch (about the ears' axis), roll (about the nose's). */
  headRotation: { yaw: number; pitch: number; roll: number };
}

/** Frame `f` of the output as named values. */
export function frameWeights(b: BlendshapeFrames, f: number): FrameWeights {
  const A = ARKIT_NAMES.length, V = VISEME_NAMES.length;
  return {
    arkit: Object.fromEntries(ARKIT_NAMES.map((n, k) => [n, b.arkit[f * A + k]])) as Record<ArkitName, number>,
    visemes: Object.fromEntries(VISEME_NAMES.map((n, k) => [n, b.visemes[f * V + k]])) as Record<VisemeName, number>,
    headRotation: { yaw: b.headRotation[3 * f], pitch: b.headRotation[3 * f + 1], roll: b.headRotation[3 * f + 2] },
  };
}
