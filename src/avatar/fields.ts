/**
 * The deformation fields of a face template, computed as the corpus rig computes them
 * (training/src/talkingface/corpus/rig.py, Rig.__init__): how strongly each vertex follows the upper lip, the
 * lower lip, the mandible, each eyelid and the brows. They are harmonic functions on the mesh graph, so they
 * follow the surface: the upper and the lower lip, which face each other across the opened mouth but share no
 * edge, move independently. The ARKit basis (basis.ts) is built from them, so its shapes move the face the way
 * the rig that made the training corpus moves it.
 *
 * Everything is in millimetres and relative to the inner mouth width W, so any template (468 or 5,023
 * vertices, cm or mm) gets the same shapes.
 */
import { MM_PER_UNIT, type FaceTemplate } from '../template/face-template';
import type { Adjacency } from '../template/mesh-topology';

export interface EyeFields {
  /** Upper and lower lid contours, sorted by x. */
  upper: number[];
  lower: number[];
  /** 1 on the upper (lower) lid contour, fading to 0 away from the eye and on the other lid. */
  wUpper: Float64Array;
  wLower: Float64Array;
  center: [number, number, number];
  width: number;
}

export interface FaceFields {
  n: number;
  /** The template's positions in mm. */
  rest: Float64Array;
  /** Inner mouth width (mm): every magnitude of the basis is a fraction of it. */
  W: number;
  mouthCenter: [number, number, number];
  /** Mean height of the mouth corners (mm). */
  cornerY: number;
  /** Inner-lip contours sorted by x, and the corners they share. */
  upperLip: number[];
  lowerLip: number[];
  corners: number[];
  wUpper: Float64Array;
  wLower: Float64Array;
  /** max(wUpper, wLower): the lips' tissue. */
  wLips: Float64Array;
  /** The mandible: 1 on the lower lip and the chin, 0 on the upper lip and above the cheekbones. */
  wJaw: Float64Array;
  /** The jaw's hinge (mm), as the rig places it: above and well behind the mouth. */
  hinge: [number, number, number];
  /** Subject's left eye (+x) and right eye (-x). */
  eyes: { left: EyeFields; right: EyeFields };
  wBrow: Float64Array;
  /** The tip of the nose (mm): the template's nose_tip region, else its most forward vertex. */
  noseTip: [number, number, number];
  /** Unit vertex normals of the template. */
  normals: Float64Array;
}

/** Solve the graph Laplace equation: w fixed on `fixed`, the mean of its neighbours elsewhere; clipped to [0, 1]. */
export function harmonicWeights(adj: Adjacency, fixed: Map<number, number>): Float64Array {
  const n = adj.offsets.length - 1;
  const w = new Float64Array(n);
  const free: number[] = [];
  const isFree = new Uint8Array(n);
  for (let v = 0; v < n; v++) {
    const value = fixed.get(v);
    if (value !== undefined) w[v] = value;
    else if (adj.offsets[v + 1] > adj.offsets[v]) {
      isFree[v] = 1;
      free.push(v);
    }
  }
  // Conjugate gradients on L_ff x = -L_fk w_k (symmetric positive definite when every free part touches a fixed
  // vertex), Jacobi-preconditioned by the degrees.
  const deg = (v: number) => adj.offsets[v + 1] - adj.offsets[v];
  const apply = (x: Float64Array, out: Float64Array) => {
    for (const v of free) {
      let s = deg(v) * x[v];
      for (let k = adj.offsets[v]; k < adj.offsets[v + 1]; k++) if (isFree[adj.indices[k]]) s -= x[adj.indices[k]];
      out[v] = s;
    }
  };
  const r = new Float64Array(n), z = new Float64Array(n), p = new Float64Array(n), q = new Float64Array(n);
  let bNorm = 0;
  for (const v of free) {
    let b = 0;
    for (let k = adj.offsets[v]; k < adj.offsets[v + 1]; k++) if (!isFree[adj.indices[k]]) b += w[adj.indices[k]];
    r[v] = b; // x starts at 0
    bNorm += b * b;
  }
  let rz = 0;
  for (const v of free) {
    z[v] = r[v] / deg(v);
    p[v] = z[v];
    rz += r[v] * z[v];
  }
  const tol = 1e-20 * Math.max(bNorm, 1e-30);
  for (let it = 0; it < 4 * free.length; it++) { // n steps in exact arithmetic; rounding may need a few more
    let rr = 0;
    for (const v of free) rr += r[v] * r[v];
    if (rr <= tol) break;
    apply(p, q);
    let pq = 0;
    for (const v of free) pq += p[v] * q[v];
    const alpha = rz / pq;
    for (const v of free) {
      w[v] += alpha * p[v];
      r[v] -= alpha * q[v];
    }
    let rzNext = 0;
    for (const v of free) {
      z[v] = r[v] / deg(v);
      rzNext += r[v] * z[v];
    }
    const beta = rzNext / rz;
    rz = rzNext;
    for (const v of free) p[v] = z[v] + beta * p[v];
  }
  for (let v = 0; v < n; v++) w[v] = Math.min(1, Math.max(0, w[v]));
  return w;
}

/** The fields of one template (rig.py's Rig.__init__, step by step). */
export function faceFields(template: FaceTemplate): FaceFields {
  const n = template.vertexCount;
  const s = MM_PER_UNIT[template.units];
  const v = Float64Array.from(template.positions, (x) => x * s);
  const r = template.regions;
  const X = (i: number) => v[3 * i], Y = (i: number) => v[3 * i + 1], Z = (i: number) => v[3 * i + 2];
  const byX = (idx: ArrayLike<number>) => Array.from(idx).sort((a, b) => X(a) - X(b));
  const mean = (idx: number[], k: number) => idx.reduce((t, i) => t + v[3 * i + k], 0) / idx.length;
  const distTo = (set: number[]) => Float64Array.from({ length: n }, (_, i) => {
    let best = Infinity;
    for (const j of set) best = Math.min(best, Math.hypot(X(i) - X(j), Y(i) - Y(j), Z(i) - Z(j)));
    return best;
  });
  const adj = template.adjacency;
  const solve = (...layers: [Iterable<number>, number][]) => {
    const fixed = new Map<number, number>();
    for (const [set, value] of layers) for (const i of set) fixed.set(i, value); // later layers win, as dict.update
    return harmonicWeights(adj, fixed);
  };
  const where = (pred: (i: number) => boolean) => Array.from({ length: n }, (_, i) => i).filter(pred);

  const upperLip = byX(r.lips_inner_upper);
  const lowerLip = byX(r.lips_inner_lower);
  const inner = [...new Set([...upperLip, ...lowerLip])];
  const mouthCenter: [number, number, number] = [mean(inner, 0), mean(inner, 1), mean(inner, 2)];
  const W = Math.max(...inner.map(X)) - Math.min(...inner.map(X));
  const corners = upperLip.filter((i) => lowerLip.includes(i));
  const cornerY = corners.length ? mean(corners, 1) : mouthCenter[1];

  const dInner = distTo(inner);
  const far = where((i) => dInner[i] > 0.55 * W);
  const lipField = (own: number[], other: number[]) => solve([far, 0], [other, 0], [own, 1], [corners, 0.5]);
  const wUpper = lipField(upperLip, lowerLip);
  const wLower = lipField(lowerLip, upperLip);
  const wLips = Float64Array.from(wUpper, (u, i) => Math.max(u, wLower[i]));

  const wJaw = solve(
    [where((i) => Y(i) < cornerY - 0.45 * W), 1], [where((i) => Y(i) > cornerY + 0.3 * W), 0],
    [lowerLip, 1], [upperLip, 0], [corners, 0.5],
  );
  const hinge: [number, number, number] = [mouthCenter[0], cornerY + 0.7 * W, mouthCenter[2] - 2.0 * W];

  const eye = (side: 'left' | 'right'): EyeFields => {
    const up = byX(r[`eye_${side}_upper`]);
    const lo = byX(r[`eye_${side}_lower`]);
    const eyeCorners = up.filter((i) => lo.includes(i));
    const all = [...new Set([...up, ...lo])];
    const width = Math.max(...all.map(X)) - Math.min(...all.map(X));
    const dEye = distTo(all);
    const lid = (own: number[], other: number[], reach: number) => solve(
      [where((i) => dEye[i] > reach * width), 0], [other, 0], [own.filter((i) => !eyeCorners.includes(i)), 1], [eyeCorners, 0],
    );
    return { upper: up, lower: lo, wUpper: lid(up, lo, 0.45), wLower: lid(lo, up, 0.3), center: [mean(all, 0), mean(all, 1), mean(all, 2)], width };
  };
  const eyes = { left: eye('left'), right: eye('right') };
  if (eyes.left.center[0] < eyes.right.center[0]) {
    throw new Error(`template "${template.id}": its eye_left region lies at -x; the basis expects the subject's left eye at +x (docs/templates.md)`);
  }

  const brows = Array.from(r.brows);
  const eyeAll = [eyes.left, eyes.right].flatMap((e) => [...e.upper, ...e.lower]);
  const dBrow = distTo(brows);
  const wBrow = solve([where((i) => dBrow[i] > 0.9 * W), 0], [eyeAll, 0], [brows, 1]);

  let tip = r.nose_tip?.[0] ?? 0;
  if (!r.nose_tip?.length) for (let i = 1; i < n; i++) if (Z(i) > Z(tip)) tip = i;
  return {
    n, rest: v, W, mouthCenter, cornerY, upperLip, lowerLip, corners, wUpper, wLower, wLips, wJaw, hinge, eyes, wBrow,
    noseTip: [X(tip), Y(tip), Z(tip)],
    normals: vertexNormals(v, template.triangles),
  };
}

/** Area-weighted unit vertex normals. */
function vertexNormals(v: Float64Array, triangles: Uint32Array): Float64Array {
  const out = new Float64Array(v.length);
  for (let t = 0; t < triangles.length; t += 3) {
    const [a, b, c] = [triangles[t], triangles[t + 1], triangles[t + 2]];
    const e1 = [v[3 * b] - v[3 * a], v[3 * b + 1] - v[3 * a + 1], v[3 * b + 2] - v[3 * a + 2]];
    const e2 = [v[3 * c] - v[3 * a], v[3 * c + 1] - v[3 * a + 1], v[3 * c + 2] - v[3 * a + 2]];
    const nx = e1[1] * e2[2] - e1[2] * e2[1], ny = e1[2] * e2[0] - e1[0] * e2[2], nz = e1[0] * e2[1] - e1[1] * e2[0];
    for (const i of [a, b, c]) {
      out[3 * i] += nx;
      out[3 * i + 1] += ny;
      out[3 * i + 2] += nz;
    }
  }
  for (let i = 0; i < out.length; i += 3) {
    const len = Math.hypot(out[i], out[i + 1], out[i + 2]) || 1;
    out[i] /= len;
    out[i + 1] /= len;
    out[i + 2] /= len;
  }
  return out;
}

/** np.interp: y at x along the points (xs ascending), clamped to the ends. */
export function interp(x: number, xs: ArrayLike<number>, ys: ArrayLike<number>): number {
  const m = xs.length;
  if (x <= xs[0]) return ys[0];
  if (x >= xs[m - 1]) return ys[m - 1];
  let k = 0;
  while (k < m - 2 && xs[k + 1] < x) k++;
  const t = (x - xs[k]) / (xs[k + 1] - xs[k] || 1);
  return ys[k] + t * (ys[k + 1] - ys[k]);
}
