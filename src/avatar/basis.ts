/**
 * ARKit's 52 blend shapes defined on the face template by this project's own code (docs/avatar.md, shape by
 * shape). Where the corpus rig has an articulator for the motion (training/src/talkingface/corpus/rig.py: jaw,
 * lip_open, round, protrude, spread, close, blink, brow) the shape is that articulator on the rig's own fields
 * (fields.ts); the rest are geometric definitions on the same fields and the template's regions.
 *
 * Shapes are displacements in mm at weight 1 from a neutral face: the template with its lips closed by the
 * rig's closure (the template's mouth is opened so the lips can part; ARKit's neutral has them together).
 * Magnitudes are fractions of the inner mouth width W, so any template gets the same shapes.
 */
import type { FaceTemplate } from '../template/face-template';
import { ARKIT_NAMES, type ArkitName } from './names';
import { faceFields, interp, type EyeFields, type FaceFields } from './fields';

/**
 * jawOpen = 1 turns the mandible this far about the rig's hinge: a wide speaking opening (the rig's jaw = 1 is 8
 * degrees, its AA 0.95 of that), so speech lands at ARKit-like jawOpen values (0.2 to 0.6).
 */
export const JAW_OPEN_DEGREES = 12;
/** The rotation is linearised at a speech-sized opening, where the model's frames lie, not at jawOpen = 1. */
const JAW_LINEARISED_AT_DEGREES = 4;

/** mouthUpperUp and mouthLowerDown at 1 move the middle of the upper (lower) lip this far (fractions of W). */
const LIP_PART = { upper: 0.15, lower: 0.2 };

/** mouthPucker and mouthFunnel: how much of the lips' half-width they take in, and how far forward (in W) they push. */
export const PUCKER = { narrow: 0.28, forward: 0.07 };
export const FUNNEL = { narrow: 0.1, forward: 0.09 };

/** Where a shape moves the face: what the basis test checks it moves, and stays inside. */
export type ShapeRegion = 'eye_left' | 'eye_right' | 'mouth' | 'jaw' | 'brow_left' | 'brow_right' | 'brows'
  | 'cheek_left' | 'cheek_right' | 'cheeks' | 'nose_left' | 'nose_right';

export interface ArkitBasis {
  /** Vertices of the template. */
  n: number;
  /** The neutral face (template positions in mm with the lips closed). */
  neutral: Float32Array;
  /** neutral minus template (mm): what the model's frames are measured from. */
  neutralOffset: Float32Array;
  /** (52 x N x 3) displacement (mm) of each shape at weight 1, in ARKIT_NAMES order. */
  shapes: Float32Array;
  /** Per shape: whether the solver fits it (gaze and the tongue are not in the mesh; they stay 0). */
  fitted: boolean[];
  /** Per shape: whether it is one of the rig's articulators (speech), not an expression the rig never makes. */
  speech: boolean[];
  regions: ShapeRegion[];
  /** Inner mouth width (mm). */
  mouthWidth: number;
}

/** Not fitted: the template has no eyeballs and no tongue, and the corpus moves neither (docs/avatar.md). */
const NOT_FITTED = new Set<ArkitName>(['eyeLookDownLeft', 'eyeLookInLeft', 'eyeLookOutLeft', 'eyeLookUpLeft',
  'eyeLookDownRight', 'eyeLookInRight', 'eyeLookOutRight', 'eyeLookUpRight', 'tongueOut']);

/** The shapes that span the rig's articulators (jaw, lip opening, rounding, protrusion, spreading, closure, the lower lip to the teeth, blinks, brows). */
const SPEECH = new Set<ArkitName>(['jawOpen', 'mouthClose', 'mouthFunnel', 'mouthPucker', 'mouthSmileLeft', 'mouthSmileRight',
  'mouthStretchLeft', 'mouthStretchRight', 'mouthRollLower', 'mouthLowerDownLeft', 'mouthLowerDownRight', 'mouthUpperUpLeft',
  'mouthUpperUpRight', 'eyeBlinkLeft', 'eyeBlinkRight', 'browInnerUp', 'browOuterUpLeft', 'browOuterUpRight', 'browDownLeft', 'browDownRight']);

type Vec = [number, number, number];

/** Build the basis of a template (a few hundred ms for 468 vertices: the harmonic fields dominate). */
export function arkitBasis(template: FaceTemplate): ArkitBasis {
  const f = faceFields(template);
  const { n, W } = f;
  const neutral = Float64Array.from(f.rest);
  add(neutral, closure(f.rest, f.upperLip, f.lowerLip, f.wUpper, f.wLower, 0.5));
  const shapes = new Float32Array(ARKIT_NAMES.length * n * 3);
  const regions: ShapeRegion[] = [];
  const defs = definitions(f, neutral);
  ARKIT_NAMES.forEach((name, k) => {
    const d = defs[name];
    shapes.set(d.shape, k * n * 3);
    regions.push(d.region);
  });
  return {
    n,
    neutral: Float32Array.from(neutral),
    neutralOffset: Float32Array.from(neutral, (x, i) => x - f.rest[i]),
    shapes,
    fitted: ARKIT_NAMES.map((name) => !NOT_FITTED.has(name)),
    speech: ARKIT_NAMES.map((name) => SPEECH.has(name)),
    regions,
    mouthWidth: W,
  };
}

/** One shape per ARKit name: its displacement (mm) and its region. */
function definitions(f: FaceFields, neutral: Float64Array): Record<ArkitName, { shape: Float64Array; region: ShapeRegion }> {
  const { n, W, mouthCenter: c } = f;
  const X = (i: number) => neutral[3 * i], Y = (i: number) => neutral[3 * i + 1];
  // field(w, vector per vertex): the displacement w_i * vec(i).
  const field = (w: (i: number) => number, vec: (i: number) => Vec) => {
    const d = new Float64Array(3 * n);
    for (let i = 0; i < n; i++) {
      const wi = w(i);
      if (wi === 0) continue;
      const [x, y, z] = vec(i);
      d[3 * i] = wi * x;
      d[3 * i + 1] = wi * y;
      d[3 * i + 2] = wi * z;
    }
    return d;
  };
  const k = (x: number, y: number, z: number): (() => Vec) => () => [x * W, y * W, z * W];
  const dx = (i: number) => X(i) - c[0];
  const sgn = (i: number) => Math.sign(dx(i));
  // The subject's left (+x) and right halves, blended over the middle fifth of the mouth width.
  const left = (i: number) => smoothstep(-0.1 * W, 0.1 * W, dx(i));
  const right = (i: number) => 1 - left(i);
  const sides = (make: (side: (i: number) => number) => Float64Array) => [make(left), make(right)];
  // The mouth corners' tissue: the lips' field, growing towards the corners (the rig's spread weight).
  const cornerW = (i: number) => f.wLips[i] * Math.min(1, Math.abs(dx(i)) / (0.5 * W)) ** 2;

  // Jaw: the rig's mandible rotation about its hinge, linearised at a speech-sized angle.
  const jawOpen = field((i) => f.wJaw[i], (i) => {
    const a = (JAW_LINEARISED_AT_DEGREES * Math.PI) / 180;
    const ry = neutral[3 * i + 1] - f.hinge[1], rz = neutral[3 * i + 2] - f.hinge[2];
    const scale = JAW_OPEN_DEGREES / JAW_LINEARISED_AT_DEGREES;
    return [0, scale * (Math.cos(a) * ry - Math.sin(a) * rz - ry), scale * (Math.sin(a) * ry + Math.cos(a) * rz - rz)];
  });
  // mouthClose: the rig's lip closure on the jaw-open face: jawOpen + mouthClose at equal weights keeps the lips together.
  const opened = Float64Array.from(neutral, (x, i) => x + jawOpen[i]);
  const mouthClose = closure(opened, f.upperLip, f.lowerLip, f.wUpper, f.wLower, 0.5);

  const eye = (e: EyeFields, inward: number) => {
    const gap = lidGap(neutral, e);
    const lids = (up: number, lo: number) => field(() => 1, (i) => [0, (up * e.wUpper[i] + lo * e.wLower[i]) * gap[i], 0]);
    return {
      blink: closure(f.rest, e.upper, e.lower, e.wUpper, e.wLower, 0.85),
      lookDown: lids(-0.25, -0.1),
      lookUp: lids(0.15, 0.1),
      lookIn: field((i) => Math.max(e.wUpper[i], e.wLower[i]), () => [inward * 0.06 * e.width, 0, 0]),
      lookOut: field((i) => Math.max(e.wUpper[i], e.wLower[i]), () => [-inward * 0.06 * e.width, 0, 0]),
      squint: lids(0, 0.35),
      wide: lids(0.3, -0.05),
    };
  };
  const L = eye(f.eyes.left, -1);
  const R = eye(f.eyes.right, 1);

  // Brows: the rig's brow raise split into its inner part and each side's outer part (they sum to the rig's).
  const browHalf = Math.max(...Array.from(f.wBrow.keys()).filter((i) => f.wBrow[i] === 1).map((i) => Math.abs(dx(i))));
  const inner = (i: number) => 1 - smoothstep(0.25 * browHalf, 0.6 * browHalf, Math.abs(dx(i)));
  const [browDownLeft, browDownRight] = sides((s) => field((i) => f.wBrow[i] * s(i), (i) => [-sgn(i) * 0.02 * W, -0.06 * W, 0]));
  const [browOuterUpLeft, browOuterUpRight] = sides((s) => field((i) => f.wBrow[i] * (1 - inner(i)) * s(i), k(0, 0.08, 0)));

  // Cheeks and nose: smooth bumps around points placed from the regions.
  const bump = (at: [number, number], radius: number) => {
    const v = nearestVertex(neutral, at);
    const p: Vec = [neutral[3 * v], neutral[3 * v + 1], neutral[3 * v + 2]];
    return (i: number) => {
      const d2 = (X(i) - p[0]) ** 2 + (Y(i) - p[1]) ** 2 + (neutral[3 * i + 2] - p[2]) ** 2;
      return d2 > radius * radius ? 0 : (1 - d2 / (radius * radius)) ** 2;
    };
  };
  const normal = (i: number): Vec => [f.normals[3 * i], f.normals[3 * i + 1], f.normals[3 * i + 2]];
  const cheek = (side: number) => bump([c[0] + side * 0.85 * W, f.cornerY + 0.3 * W], 0.5 * W);
  const underEye = (e: EyeFields) => bump([e.center[0], e.center[1] - 0.55 * e.width], 0.4 * W);
  const tip = f.noseTip;
  const ala = (side: number) => bump([tip[0] + side * 0.3 * W, tip[1] - 0.15 * W], 0.3 * W);
  const cheekPuffL = cheek(1), cheekPuffR = cheek(-1);

  const shape = (s: Float64Array, region: ShapeRegion) => ({ shape: s, region });
  // The corner shapes share the corners' field and differ in direction, and each also moves its own neighbourhood,
  // so no one of them is a mix of the others: smiling lifts the cheek above the corner, frowning pulls the skin below
  // it down, stretching draws the lower lip down with it, a dimple is the corner alone (its field squared).
  const nearCorner = (side: number, up: number) => bump([c[0] + side * 0.55 * W, f.cornerY + up * W], 0.3 * W);
  const aboveL = nearCorner(1, 0.2), aboveR = nearCorner(-1, 0.2), belowL = nearCorner(1, -0.25), belowR = nearCorner(-1, -0.25);
  const [smileL, smileR] = sides((s) => add(field((i) => cornerW(i) * s(i), (i) => [sgn(i) * 0.06 * W, 0.07 * W, -0.03 * W]),
    field((i) => (aboveL(i) + aboveR(i)) * s(i), k(0, 0.03, 0.01))));
  const [frownL, frownR] = sides((s) => add(field((i) => cornerW(i) * s(i), (i) => [sgn(i) * 0.01 * W, -0.07 * W, 0]),
    field((i) => (belowL(i) + belowR(i)) * s(i), k(0, -0.03, 0))));
  const [dimpleL, dimpleR] = sides((s) => field((i) => cornerW(i) ** 2 * s(i), (i) => [sgn(i) * 0.05 * W, 0, -0.12 * W]));
  const [stretchL, stretchR] = sides((s) => add(field((i) => cornerW(i) * s(i), (i) => [sgn(i) * 0.1 * W, -0.03 * W, -0.03 * W]),
    field((i) => f.wLower[i] * s(i), k(0, -0.02, 0))));
  const [pressL, pressR] = sides((s) => field((i) => s(i), (i) => [0, 0.02 * W * (f.wLower[i] - f.wUpper[i]), -0.015 * W * f.wLips[i]]));
  // Each lip parting from the closed neutral: half the closure undone (most at the middle, none at the corners,
  // the depths parting too), half the rig's lip opening (the whole lip alike); the middle of the lip moves LIP_PART * W.
  const none = new Float64Array(n);
  const parting = (upper: boolean, size: number) => {
    const d = closure(f.rest, f.upperLip, f.lowerLip, upper ? f.wUpper : none, upper ? none : f.wLower, 0.5);
    const w = upper ? f.wUpper : f.wLower;
    let most = 0;
    for (let i = 0; i < n; i++) most = Math.max(most, Math.abs(d[3 * i + 1]));
    const sign = upper ? 1 : -1;
    return (i: number): Vec => [0, size * W * (0.5 * sign * Math.abs(d[3 * i + 1]) / most + 0.5 * sign * w[i]), (-0.5 * size * W * d[3 * i + 2]) / most];
  };
  const upperParting = parting(true, LIP_PART.upper), lowerParting = parting(false, LIP_PART.lower);
  const [lowerDownL, lowerDownR] = sides((s) => field(s, lowerParting));
  const [upperUpL, upperUpR] = sides((s) => field(s, upperParting));
  return {
    eyeBlinkLeft: shape(L.blink, 'eye_left'), eyeLookDownLeft: shape(L.lookDown, 'eye_left'),
    eyeLookInLeft: shape(L.lookIn, 'eye_left'), eyeLookOutLeft: shape(L.lookOut, 'eye_left'),
    eyeLookUpLeft: shape(L.lookUp, 'eye_left'), eyeSquintLeft: shape(L.squint, 'eye_left'), eyeWideLeft: shape(L.wide, 'eye_left'),
    eyeBlinkRight: shape(R.blink, 'eye_right'), eyeLookDownRight: shape(R.lookDown, 'eye_right'),
    eyeLookInRight: shape(R.lookIn, 'eye_right'), eyeLookOutRight: shape(R.lookOut, 'eye_right'),
    eyeLookUpRight: shape(R.lookUp, 'eye_right'), eyeSquintRight: shape(R.squint, 'eye_right'), eyeWideRight: shape(R.wide, 'eye_right'),
    jawForward: shape(field((i) => f.wJaw[i], k(0, 0, 0.1)), 'jaw'),
    jawLeft: shape(field((i) => f.wJaw[i], k(0.1, 0, 0)), 'jaw'),
    jawRight: shape(field((i) => f.wJaw[i], k(-0.1, 0, 0)), 'jaw'),
    jawOpen: shape(jawOpen, 'jaw'),
    mouthClose: shape(mouthClose, 'mouth'),
    // The rig's protrusion (with a little narrowing), and its rounding with a little protrusion.
    mouthFunnel: shape(field((i) => f.wLips[i], (i) => [-FUNNEL.narrow * dx(i), 0, FUNNEL.forward * W]), 'mouth'),
    mouthPucker: shape(field((i) => f.wLips[i], (i) => [-PUCKER.narrow * dx(i), 0, PUCKER.forward * W]), 'mouth'),
    mouthLeft: shape(field((i) => f.wLips[i], k(0.1, 0, 0)), 'mouth'),
    mouthRight: shape(field((i) => f.wLips[i], k(-0.1, 0, 0)), 'mouth'),
    mouthSmileLeft: shape(smileL, 'mouth'), mouthSmileRight: shape(smileR, 'mouth'),
    mouthFrownLeft: shape(frownL, 'mouth'), mouthFrownRight: shape(frownR, 'mouth'),
    mouthDimpleLeft: shape(dimpleL, 'mouth'), mouthDimpleRight: shape(dimpleR, 'mouth'),
    mouthStretchLeft: shape(stretchL, 'mouth'), mouthStretchRight: shape(stretchR, 'mouth'),
    mouthRollLower: shape(field((i) => f.wLower[i] ** 2, k(0, 0.03, -0.08)), 'mouth'),
    mouthRollUpper: shape(field((i) => f.wUpper[i] ** 2, k(0, -0.03, -0.08)), 'mouth'),
    mouthShrugLower: shape(field((i) => f.wLower[i], k(0, 0.05, 0.03)), 'mouth'),
    mouthShrugUpper: shape(field((i) => f.wUpper[i], k(0, 0.03, 0.03)), 'mouth'),
    mouthPressLeft: shape(pressL, 'mouth'), mouthPressRight: shape(pressR, 'mouth'),
    mouthLowerDownLeft: shape(lowerDownL, 'mouth'), mouthLowerDownRight: shape(lowerDownR, 'mouth'),
    mouthUpperUpLeft: shape(upperUpL, 'mouth'), mouthUpperUpRight: shape(upperUpR, 'mouth'),
    browDownLeft: shape(browDownLeft, 'brow_left'), browDownRight: shape(browDownRight, 'brow_right'),
    browInnerUp: shape(field((i) => f.wBrow[i] * inner(i), k(0, 0.08, 0)), 'brows'),
    browOuterUpLeft: shape(browOuterUpLeft, 'brow_left'), browOuterUpRight: shape(browOuterUpRight, 'brow_right'),
    cheekPuff: shape(field((i) => cheekPuffL(i) + cheekPuffR(i), (i) => normal(i).map((x) => 0.08 * W * x) as Vec), 'cheeks'),
    cheekSquintLeft: shape(field(underEye(f.eyes.left), k(0, 0.05, 0.01)), 'cheek_left'),
    cheekSquintRight: shape(field(underEye(f.eyes.right), k(0, 0.05, 0.01)), 'cheek_right'),
    noseSneerLeft: shape(field(ala(1), k(0, 0.05, -0.01)), 'nose_left'),
    noseSneerRight: shape(field(ala(-1), k(0, 0.05, -0.01)), 'nose_right'),
    // No tongue in the mesh: the lower lip pushed down and out, as a tongue over it pushes it.
    tongueOut: shape(field((i) => f.wLower[i], k(0, -0.05, 0.06)), 'mouth'),
  };
}

/**
 * The rig's closure (rig.py, Rig._close): two facing contours brought together, the upper one taking `upperShare`
 * of the gap at each vertex's x, the depths meeting halfway; spread over the tissue by the two fields.
 */
export function closure(p: Float64Array, upper: number[], lower: number[], wUp: Float64Array, wLo: Float64Array, upperShare: number): Float64Array {
  const along = (idx: number[], k: number) => {
    const order = [...idx].sort((a, b) => p[3 * a] - p[3 * b]);
    return { xs: order.map((i) => p[3 * i]), ys: order.map((i) => p[3 * i + k]) };
  };
  const uy = along(upper, 1), ly = along(lower, 1), uz = along(upper, 2), lz = along(lower, 2);
  const d = new Float64Array(p.length);
  for (let i = 0; i < p.length / 3; i++) {
    const x = p[3 * i];
    const gap = Math.max(interp(x, uy.xs, uy.ys) - interp(x, ly.xs, ly.ys), 0);
    const zu = interp(x, uz.xs, uz.ys), zl = interp(x, lz.xs, lz.ys);
    const meet = 0.5 * (zu + zl);
    d[3 * i + 1] = gap * (-upperShare * wUp[i] + (1 - upperShare) * wLo[i]);
    d[3 * i + 2] = (meet - zu) * wUp[i] + (meet - zl) * wLo[i];
  }
  return d;
}

/** The opening between an eye's lids at each vertex's x (0 beyond the corners). */
function lidGap(p: Float64Array, e: EyeFields): Float64Array {
  const ux = e.upper.map((i) => p[3 * i]), uy = e.upper.map((i) => p[3 * i + 1]);
  const lx = e.lower.map((i) => p[3 * i]), ly = e.lower.map((i) => p[3 * i + 1]);
  return Float64Array.from({ length: p.length / 3 }, (_, i) => {
    const x = p[3 * i];
    if (x < ux[0] || x > ux[ux.length - 1]) return 0;
    return Math.max(0, interp(x, ux, uy) - interp(x, lx, ly));
  });
}

/** The vertex nearest (x, y) in the face's plane: the surface point in front of it. */
function nearestVertex(p: Float64Array, at: [number, number]): number {
  let best = 0, bestD = Infinity;
  for (let i = 0; i < p.length / 3; i++) {
    const d = Math.hypot(p[3 * i] - at[0], p[3 * i + 1] - at[1]);
    if (d < bestD) [best, bestD] = [i, d];
  }
  return best;
}

function smoothstep(a: number, b: number, x: number): number {
  const t = Math.min(1, Math.max(0, (x - a) / (b - a)));
  return t * t * (3 - 2 * t);
}

function add(a: Float64Array, b: Float64Array): Float64Array {
  for (let i = 0; i < a.length; i++) a[i] += b[i];
  return a;
}
