/**
 * The rest of the head around a face template, generated from the template itself (no third-party mesh): a skull
 * and back of the head that start at the face's outer boundary loop (the oval) and close behind it, and the
 * measures of a neck and shoulders that go with it.
 *
 * The shell's first ring *is* the oval: its triangles index the face's own boundary vertices, so face and shell
 * are one surface (one vertex buffer: the face's N vertices, then the shell's), with smooth normals across the
 * join and no seam however the model moves the oval. The shell is an "egg" (an ellipsoid with its own radius up,
 * down, forward and back) sized from the face; each oval vertex starts a meridian that runs over the egg to its
 * back pole, carrying the oval's distance from the egg and letting it fade, so the shell leaves the face where the
 * face ends. A template that already is a whole head (no oval boundary loop) gets no shell.
 *
 * Pure geometry (no WebGL): the view and the .glb export build meshes from it.
 */
import type { FaceTemplate } from '../template/face-template';
import { boundaryLoops } from '../template/mesh-topology';

/** Rings from the oval to the back pole (the pole is one more vertex); rings after the oval have twice its columns. */
const RINGS = 18;
/** The egg's squareness: 2 is an ellipsoid; more fills out the crown and the temples as a skull does. */
export const SQUARENESS = 2.5;

/** The egg the shell lies on: centre and the four half-axes (template units). */
export interface Egg {
  center: [number, number, number];
  /** Half-width (x), up and down (y), forward and back (z). */
  ax: number;
  up: number;
  down: number;
  front: number;
  back: number;
}

export interface HeadShell {
  /** (S x 3) the shell's own vertices; in the joined buffer they come after the face's N. */
  positions: Float32Array;
  /** (T x 3) triangles of the shell in the joined buffer's indices (face 0..N-1, shell N..N+S-1). */
  triangles: Uint32Array;
  /** The face's outer boundary loop, ordered: the shell's first ring. */
  seam: number[];
  /** (S) how much each shell vertex turns with the jaw (1 under the chin next to the face, 0 on the skull). */
  jawWeights: Float32Array;
  egg: Egg;
  /** Face measures the neck, shoulders and camera are sized from. */
  measures: FaceMeasures;
}

export interface FaceMeasures {
  /** Oval: half-width, top and chin heights, the sides' depth. */
  halfWidth: number;
  top: number;
  chin: number;
  sideZ: number;
  centerX: number;
  /** Mean height of the eye contours. */
  eyeY: number;
  /** Inner mouth width W and the mouth corners' height (the corpus rig's jaw measures). */
  mouthWidth: number;
  cornerY: number;
}

export function faceMeasures(t: FaceTemplate, oval: number[]): FaceMeasures {
  const p = t.positions;
  const r = t.regions;
  const xs = oval.map((v) => p[3 * v]);
  const centerX = (Math.min(...xs) + Math.max(...xs)) / 2;
  const halfWidth = Math.max(...xs.map((x) => Math.abs(x - centerX)));
  const ys = oval.map((v) => p[3 * v + 1]);
  const sides = oval.filter((v) => Math.abs(p[3 * v] - centerX) > 0.85 * halfWidth);
  const eyes = [...r.eye_left_upper, ...r.eye_left_lower, ...r.eye_right_upper, ...r.eye_right_lower];
  const inner = [...r.lips_inner_upper, ...r.lips_inner_lower];
  const ix = inner.map((v) => p[3 * v]);
  const corners = [...r.lips_inner_upper].filter((v) => r.lips_inner_lower.includes(v));
  return {
    halfWidth, centerX,
    top: Math.max(...ys),
    chin: Math.min(...ys),
    sideZ: sides.reduce((s, v) => s + p[3 * v + 2], 0) / sides.length,
    eyeY: eyes.reduce((s, v) => s + p[3 * v + 1], 0) / eyes.length,
    mouthWidth: Math.max(...ix) - Math.min(...ix),
    cornerY: corners.length ? corners.reduce((s, v) => s + p[3 * v + 1], 0) / corners.length : inner.reduce((s, v) => s + p[3 * v + 1], 0) / inner.length,
  };
}

/** The face's outer boundary: the boundary loop holding the most `face_boundary` vertices, or null if none has any. */
export function ovalLoop(t: FaceTemplate): number[] | null {
  const oval = new Set(t.regions.face_boundary);
  let best: number[] | null = null;
  let bestHits = 0;
  for (const loop of boundaryLoops(t.triangles)) {
    const hits = loop.filter((v) => oval.has(v)).length;
    if (hits > bestHits) [best, bestHits] = [loop, hits];
  }
  // A whole head has no open oval: its "face_boundary" lies inside the surface, not on a boundary loop.
  return best && bestHits >= 0.5 * oval.size ? best : null;
}

/**
 * A point of the egg (a superellipsoid with a half-axis per direction) at direction angles theta (around the back
 * axis) and phi (from the back pole): the unit direction u, scaled by the half-axes and pulled onto the surface.
 */
function eggPoint(e: Egg, theta: number, phi: number, out: number[]): void {
  const s = Math.sin(phi);
  const ux = s * Math.cos(theta);
  const uy = s * Math.sin(theta);
  const uz = -Math.cos(phi);
  const k = (Math.abs(ux) ** SQUARENESS + Math.abs(uy) ** SQUARENESS + Math.abs(uz) ** SQUARENESS) ** (-1 / SQUARENESS);
  out[0] = e.center[0] + k * ux * e.ax;
  out[1] = e.center[1] + k * uy * (uy >= 0 ? e.up : e.down);
  out[2] = e.center[2] + k * uz * (uz >= 0 ? e.front : e.back);
}

/** The egg's angles of a point (the inverse of eggPoint's direction: the point's direction in half-axis units). */
function eggAngles(e: Egg, x: number, y: number, z: number): { theta: number; phi: number } {
  const ux = (x - e.center[0]) / e.ax;
  const uy = (y - e.center[1]) / (y >= e.center[1] ? e.up : e.down);
  const uz = (z - e.center[2]) / (z >= e.center[2] ? e.front : e.back);
  const len = Math.hypot(ux, uy, uz) || 1;
  return { theta: Math.atan2(uy, ux), phi: Math.acos(Math.max(-1, Math.min(1, -uz / len))) };
}

/** The egg for a face: proportions of an adult head measured from the face's oval (height chin to hairline H). */
export function eggFor(m: FaceMeasures): Egg {
  const H = m.top - m.chin;
  return {
    center: [m.centerX, m.eyeY - 0.05 * H, m.sideZ],
    ax: 1.02 * m.halfWidth,
    up: 0.62 * H, // the crown, about 11 cm above the eyes on a 17.7 cm face
    down: 0.66 * H,
    front: 0.5 * H,
    back: 0.58 * H, // the back of the head about 20 cm behind the nose tip
  };
}

/** The shell of a template, or null when the template has no open oval (it already is a whole head). */
export function headShell(t: FaceTemplate): HeadShell | null {
  const loop = ovalLoop(t);
  if (!loop) return null;
  const n = t.vertexCount;
  const m = faceMeasures(t, loop);
  const egg = eggFor(m);
  const p = t.positions;
  const M = loop.length;
  const C = 2 * M; // columns after the oval: each oval vertex's meridian and one between it and the next
  const S = C * (RINGS - 1) + 1;
  const positions = new Float32Array(S * 3);
  const jawWeights = new Float32Array(S);
  const q = [0, 0, 0];
  const W = m.mouthWidth;
  // Each oval vertex: its egg angles, its offset from the egg, and how much it turns with the jaw.
  const seam = loop.map((v) => {
    const x = p[3 * v], y = p[3 * v + 1], z = p[3 * v + 2];
    const { theta, phi } = eggAngles(egg, x, y, z);
    eggPoint(egg, theta, phi, q);
    // The corpus rig's mandible: fully turning below corner - 0.45 W, still above corner + 0.3 W.
    return { theta, phi, off: [x - q[0], y - q[1], z - q[2]], jaw: Math.min(1, Math.max(0, (m.cornerY + 0.3 * W - y) / (0.75 * W))) };
  });
  for (let c = 0; c < C; c++) {
    const a = seam[Math.floor(c / 2)], b = seam[(Math.floor(c / 2) + (c % 2)) % M];
    let dTheta = b.theta - a.theta;
    if (dTheta > Math.PI) dTheta -= 2 * Math.PI;
    else if (dTheta < -Math.PI) dTheta += 2 * Math.PI;
    const theta = a.theta + dTheta / 2, phi = (a.phi + b.phi) / 2;
    const off = a.off.map((o, k) => (o + b.off[k]) / 2);
    const jaw = (a.jaw + b.jaw) / 2;
    for (let k = 1; k < RINGS; k++) {
      const s = k / RINGS;
      const fade = s >= 0.5 ? 0 : (1 - 2 * s) ** 2 * (1 + 4 * s); // 1 at the oval, flat there, 0 from halfway
      eggPoint(egg, theta, phi * (1 - s), q);
      const j = (k - 1) * C + c;
      positions[3 * j] = q[0] + off[0] * fade;
      positions[3 * j + 1] = q[1] + off[1] * fade;
      positions[3 * j + 2] = q[2] + off[2] * fade;
      jawWeights[j] = jaw * Math.max(0, 1 - s / 0.3);
    }
  }
  eggPoint(egg, 0, 0, q);
  positions.set(q, 3 * (S - 1));

  // Ring r's column c in the joined buffer (r >= 1), and the oval's vertex i (ring 0).
  const id = (r: number, c: number) => n + (r - 1) * C + (c % C);
  const oval = (i: number) => loop[i % M];
  const tris: number[] = [];
  for (let i = 0; i < M; i++) // the oval's M columns fan out to ring 1's 2M
    tris.push(oval(i), id(1, 2 * i), id(1, 2 * i + 1), oval(i), id(1, 2 * i + 1), oval(i + 1), oval(i + 1), id(1, 2 * i + 1), id(1, 2 * i + 2));
  for (let r = 1; r + 1 < RINGS; r++)
    for (let c = 0; c < C; c++) tris.push(id(r, c), id(r + 1, c), id(r + 1, c + 1), id(r, c), id(r + 1, c + 1), id(r, c + 1));
  for (let c = 0; c < C; c++) tris.push(id(RINGS - 1, c), n + S - 1, id(RINGS - 1, c + 1));
  const triangles = Uint32Array.from(tris);
  orientOutward(triangles, (v) => (v < n ? [p[3 * v], p[3 * v + 1], p[3 * v + 2]] : [positions[3 * (v - n)], positions[3 * (v - n) + 1], positions[3 * (v - n) + 2]]), egg.center);
  return { positions, triangles, seam: loop, jawWeights, egg, measures: m };
}

/** Flip every triangle if most face the egg's centre (the loop's direction decides the winding). */
function orientOutward(tris: Uint32Array, at: (v: number) => number[], c: [number, number, number]): void {
  let score = 0;
  for (let t = 0; t < tris.length; t += 3) {
    const [a, b, d] = [at(tris[t]), at(tris[t + 1]), at(tris[t + 2])];
    const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    const w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    const nrm = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
    score += Math.sign(nrm[0] * (a[0] - c[0]) + nrm[1] * (a[1] - c[1]) + nrm[2] * (a[2] - c[2]));
  }
  if (score >= 0) return;
  for (let t = 0; t < tris.length; t += 3) [tris[t + 1], tris[t + 2]] = [tris[t + 2], tris[t + 1]];
}
