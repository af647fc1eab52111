/**
 * Inside the mouth: the oral cavity, teeth and tongue, so that parted lips show a mouth and never the page.
 *
 * - The cavity is a closed bag whose rim *is* the inner-lip contour (its triangles index the face's own lip
 *   vertices, like the head shell's seam), so there is no gap between lips and mouth at any opening. Its other
 *   rings lie on an ellipsoid behind the lips; each frame they follow the lips near the front and, on the lower
 *   half, the jaw (jaw.ts), so the floor of the mouth drops with the chin.
 * - Upper teeth are fixed to the skull, just behind the upper lip; lower teeth and the tongue turn with the jaw.
 * - The tongue has one morph target, "raise": its front rises to the ridge behind the upper teeth, as for
 *   /t d n l/ and /th/ (weighted each frame by the content encoder's posteriors of those phones).
 *
 * Sizes come from the inner mouth's width W, so any template gets a fitting mouth.
 */
import * as THREE from 'three';
import { RoundedBoxGeometry } from 'three/addons/geometries/RoundedBoxGeometry.js';
import { mergeGeometries } from 'three/addons/utils/BufferGeometryUtils.js';
import type { FaceTemplate } from '../template/face-template';
import { boundaryLoops } from '../template/mesh-topology';
import { turnAboutHinge, type Hinge } from './jaw';

const BAG_RINGS = 6;

export interface MouthBag {
  /** The inner-lip loop, ordered: the bag's rim. */
  rim: number[];
  /** (B x 3) the bag's rest vertices (template's jaw), after the face's and the shell's in the joined buffer. */
  rest: Float32Array;
  /** (T x 3) triangles in the joined buffer's indices; `first` is the index of the bag's first vertex there. */
  triangles: Uint32Array;
  first: number;
  /** (B) how much each bag vertex follows its rim vertex's motion (1 at the lips, fading back). */
  follow: Float32Array;
  /** (B) how much it turns with the jaw (lower half 1, upper 0). */
  jaw: Float32Array;
  /** (B) the rim vertex each bag vertex belongs to (the back pole: -1). */
  column: Int32Array;
}

/** The mouth's frame: centre of the inner lips, half-width and the inner lips' heights. */
export interface MouthFrame {
  center: [number, number, number];
  W: number;
  upperY: number;
  lowerY: number;
  frontZ: number;
}

export function mouthFrame(t: FaceTemplate): MouthFrame {
  const p = t.positions;
  const { lips_inner_upper: up, lips_inner_lower: lo } = t.regions;
  const inner = [...up, ...lo];
  const mean = (k: number, vs: ArrayLike<number>) => Array.from(vs).reduce((s, v) => s + p[3 * v + k], 0) / vs.length;
  const xs = inner.map((v) => p[3 * v]);
  const upOnly = [...up].filter((v) => !lo.includes(v));
  const loOnly = [...lo].filter((v) => !up.includes(v));
  return {
    center: [mean(0, inner), mean(1, inner), mean(2, inner)],
    W: Math.max(...xs) - Math.min(...xs),
    upperY: mean(1, upOnly),
    lowerY: mean(1, loOnly),
    frontZ: Math.max(...inner.map((v) => p[3 * v + 2])),
  };
}

/** The cavity for a template whose inner lips are a boundary loop (null otherwise: a closed mouth has no inside). */
export function mouthBag(t: FaceTemplate, first: number): MouthBag | null {
  const lips = new Set([...t.regions.lips_inner_upper, ...t.regions.lips_inner_lower]);
  const rim = boundaryLoops(t.triangles).find((l) => l.filter((v) => lips.has(v)).length >= 0.8 * lips.size);
  if (!rim) return null;
  const p = t.positions;
  const f = mouthFrame(t);
  const [cx, cy, cz] = f.center;
  const M = rim.length;
  const B = M * (BAG_RINGS - 1) + 1;
  const rest = new Float32Array(B * 3);
  const follow = new Float32Array(B);
  const jaw = new Float32Array(B);
  const column = new Int32Array(B).fill(-1);
  const depth = 1.3 * f.W;
  const upper = new Set(t.regions.lips_inner_upper), lower = new Set(t.regions.lips_inner_lower);
  rim.forEach((v, i) => {
    const x = p[3 * v], y = p[3 * v + 1], z = p[3 * v + 2];
    const psi = Math.atan2((y - cy) / (0.3 * f.W), (x - cx) / (0.5 * f.W));
    const jw = lower.has(v) && upper.has(v) ? 0.5 : lower.has(v) ? 1 : 0;
    for (let k = 1; k < BAG_RINGS; k++) {
      const s = k / BAG_RINGS;
      // The cross-section: wide enough for the teeth's arch and tall from palate to floor, closing at the back.
      const size = s < 0.3 ? 1 : Math.cos(((s - 0.3) / 0.7) * (Math.PI / 2)) ** 0.6;
      const ex = cx + Math.cos(psi) * 0.62 * f.W * size;
      const ey = cy + Math.sin(psi) * (psi > 0 ? 0.42 : 0.62) * f.W * size;
      const ez = cz - depth * s;
      const b = Math.min(1, s / 0.3);
      const j = (k - 1) * M + i;
      rest.set([x + (ex - x) * b, y + (ey - y) * b, z + (ez - z) * b], 3 * j);
      follow[j] = (1 - s) ** 3;
      jaw[j] = jw;
      column[j] = i;
    }
  });
  rest.set([cx, cy - 0.1 * f.W, cz - depth], 3 * (B - 1));
  jaw[B - 1] = 0.5;
  const id = (r: number, i: number) => (r === 0 ? rim[i % M] : first + (r - 1) * M + (i % M));
  const tris: number[] = [];
  // Wound so the bag's outside faces away from its inside: the viewer sees its inner (back) faces.
  for (let r = 0; r + 1 < BAG_RINGS; r++)
    for (let i = 0; i < M; i++) tris.push(id(r, i), id(r + 1, i + 1), id(r + 1, i), id(r, i), id(r, i + 1), id(r + 1, i + 1));
  for (let i = 0; i < M; i++) tris.push(id(BAG_RINGS - 1, i), id(BAG_RINGS - 1, i + 1), first + B - 1);
  return { rim, rest, triangles: Uint32Array.from(tris), first, follow, jaw, column };
}

const scratch = [0, 0];

/**
 * The bag's vertices for a face frame: each follows its rim vertex's motion (fading back) on top of its rest place,
 * turned with the jaw on the lower half. Writes into `out` (B x 3, the joined buffer's bag part).
 */
export function updateBag(bag: MouthBag, template: Float32Array, face: ArrayLike<number>, hinge: Hinge, jawAngle: number, out: Float32Array): void {
  const r = bag.rest;
  for (let j = 0; j < bag.follow.length; j++) {
    const a = jawAngle * bag.jaw[j];
    turnAboutHinge(hinge, a, r[3 * j + 1], r[3 * j + 2], scratch);
    let x = r[3 * j], y = scratch[0], z = scratch[1];
    const c = bag.column[j];
    if (c >= 0 && bag.follow[j] > 0) {
      const v = bag.rim[c];
      // The lip's own motion beyond what the jaw explains.
      turnAboutHinge(hinge, a, template[3 * v + 1], template[3 * v + 2], scratch);
      x += (face[3 * v] - template[3 * v]) * bag.follow[j];
      y += (face[3 * v + 1] - scratch[0]) * bag.follow[j];
      z += (face[3 * v + 2] - scratch[1]) * bag.follow[j];
    }
    out[3 * j] = x;
    out[3 * j + 1] = y;
    out[3 * j + 2] = z;
  }
}

/**
 * Place teeth along a parabolic arch, z going back as x^2 (x from the midline, both in units of W), each crown
 * centred at its arc length from the midline (the widths before it), so they stand side by side round the curve
 * and the molars end about 0.6 W out and 0.7 W back, inside the cheeks (placed by x alone they reached 1 W out and
 * 1.8 W back, with gaps between the side teeth). The biting edges follow a smooth line, the side teeth's a little
 * further from the bite than the incisors' (a smile's arc).
 */
function arch(f: MouthFrame, upper: boolean): THREE.BufferGeometry {
  const W = f.W;
  // Crown widths of the central incisor, lateral incisor, canine, two premolars and a molar (W = 4.3 cm -> cm).
  const widths = [0.85, 0.68, 0.78, 0.7, 0.68, 0.95].map((w) => (w / 4.3) * W * (upper ? 1 : 0.82));
  const front = f.frontZ - 0.1 * W - (upper ? 0 : 0.075 * W);
  const curve = 1.82 / W; // depth = curve x^2
  const height = (upper ? 0.3 : 0.26) * W;
  const edge = upper ? f.upperY - 0.05 * W : f.lowerY - 0.03 * W;
  const along = widths.reduce((t, w) => t + w, 0);
  const xAt = arcToX(curve, along);
  const parts: THREE.BufferGeometry[] = [];
  for (const side of [-1, 1]) {
    let s = 0;
    widths.forEach((w, k) => {
      const mid = xAt(s + w / 2);
      const rise = 0.03 * W * ((s + w / 2) / along) ** 2; // away from the bite
      s += w;
      const tall = height * (k < 3 ? 1 : 0.8);
      const tooth = new RoundedBoxGeometry(w * 1.02, tall, (k < 2 ? 0.055 : 0.1 + 0.02 * k) * W, 2, w * 0.15);
      tooth.rotateY(side * Math.atan(2 * curve * mid)); // its outer end back, along the arch
      // Each crown hangs from (upper) or stands on (lower) the gum line, its biting edge at `edge`.
      const y = upper ? edge + tall / 2 + rise : edge - tall / 2 - rise;
      tooth.translate(f.center[0] + side * mid, y, front - curve * mid * mid);
      parts.push(tooth);
    });
  }
  const merged = mergeGeometries(parts)!;
  for (const g of parts) g.dispose();
  return merged;
}

/** For the parabola z = curve x^2: x at arc length s from its vertex, for s up to `longest` (a table, linear between). */
function arcToX(curve: number, longest: number): (s: number) => number {
  const step = longest / 400;
  const xs = [0], ss = [0];
  while (ss[ss.length - 1] < longest) {
    const x = xs[xs.length - 1];
    xs.push(x + step);
    ss.push(ss[ss.length - 1] + step * Math.hypot(1, 2 * curve * (x + step / 2)));
  }
  return (s) => {
    let i = 1;
    while (i < ss.length - 1 && ss[i] < s) i++;
    return xs[i - 1] + ((s - ss[i - 1]) / (ss[i] - ss[i - 1])) * step;
  };
}

export function teethGeometry(f: MouthFrame, upper: boolean): THREE.BufferGeometry {
  return arch(f, upper);
}

/**
 * A tongue lying on the floor of the mouth, its tip behind the lower incisors (their inner face is 0.2 to 0.23 W behind the
 * lips' front: arch()), with its "raise" morph target, which lifts the front straight up behind the upper incisors
 * (0.13 W) to the ridge above them, and a little back: never through the teeth.
 */
export function tongueGeometry(f: MouthFrame): THREE.BufferGeometry {
  const W = f.W;
  const g = new THREE.SphereGeometry(1, 28, 14);
  g.scale(0.4 * W, 0.16 * W, 0.56 * W);
  const cy = f.lowerY - 0.19 * W, cz = f.frontZ - 0.8 * W; // the tip at 0.24 W behind the lips' front
  g.translate(f.center[0], cy, cz);
  const pos = g.getAttribute('position') as THREE.BufferAttribute;
  const raise = new Float32Array(pos.count * 3);
  for (let i = 0; i < pos.count; i++) {
    const front = Math.min(1, Math.max(0, (pos.getZ(i) - (cz - 0.1 * W)) / (0.5 * W))); // 0 at the middle, 1 at the tip
    const w = front * front * (3 - 2 * front);
    raise[3 * i + 1] = w * (f.upperY - f.lowerY + 0.34 * W); // up to the ridge behind the upper teeth
    raise[3 * i + 2] = -w * 0.02 * W;
  }
  g.morphAttributes.position = [new THREE.BufferAttribute(raise, 3)];
  g.morphTargetsRelative = true;
  return g;
}

/**
 * The teeth carry the tongue's one morph target, at zero everywhere: three.js then draws teeth and tongue with one
 * shader program, and the first draw links one program fewer (under a software GPU each costs tens of milliseconds
 * of the first frame; issue 18). Only the view does this: the .glb export's teeth have no morph target.
 */
export function shareTongueProgram(head: { tongue: THREE.Mesh; group: THREE.Object3D }): void {
  const targets = head.tongue.geometry.morphAttributes.position?.length ?? 0;
  for (const name of ['teeth_upper', 'teeth_lower']) {
    const teeth = head.group.getObjectByName(name) as THREE.Mesh | undefined;
    if (!teeth || targets === 0) continue;
    const count = teeth.geometry.getAttribute('position').count;
    teeth.geometry.morphAttributes.position = Array.from({ length: targets }, () => new THREE.BufferAttribute(new Float32Array(count * 3), 3));
    teeth.geometry.morphTargetsRelative = head.tongue.geometry.morphTargetsRelative;
    teeth.updateMorphTargets();
  }
}
