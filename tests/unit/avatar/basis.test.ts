/**
 * The ARKit basis on the shipped template (src/avatar/basis.ts): each of the 52 shapes moves the part of the face
 * its name says, in the direction it says, and stays inside it; the left / right pairs mirror each other; the
 * neutral face has its lips closed; jawOpen + mouthClose keep them closed; eyeBlink closes the lids; and the basis
 * spans what the corpus rig does to a face (the sample clips' ground truth, other subjects' faces).
 *
 * The regions here are drawn from the template's own regions and geometry, not from the basis's fields.
 */
import { beforeAll, describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { arkitBasis, type ArkitBasis } from '../../../src/avatar/basis';
import { BlendshapeSolver } from '../../../src/avatar/solver';
import { ARKIT_NAMES, type ArkitName } from '../../../src/avatar/names';
import { innerLipGaps } from '../../../src/template/lip-gap';
import { MM_PER_UNIT, lipMask, type FaceTemplate } from '../../../src/template/face-template';
import { MODELS, buf, loadManifest, loadTemplateFile } from '../helpers/exported';

let t: FaceTemplate;
let basis: ArkitBasis;
let P: Float32Array; // template positions, mm
const n = () => t.vertexCount;

beforeAll(async () => {
  t = await loadTemplateFile(loadManifest());
  basis = arkitBasis(t);
  P = Float32Array.from(t.positions, (x) => x * MM_PER_UNIT[t.units]);
});

const shape = (name: ArkitName) => basis.shapes.subarray(ARKIT_NAMES.indexOf(name) * n() * 3, (ARKIT_NAMES.indexOf(name) + 1) * n() * 3);
const len = (d: ArrayLike<number>, v: number) => Math.hypot(d[3 * v], d[3 * v + 1], d[3 * v + 2]);
const centroid = (idx: ArrayLike<number>) => [0, 1, 2].map((k) => Array.from(idx).reduce((s, v) => s + P[3 * v + k], 0) / idx.length);
const nearest = (set: ArrayLike<number>) => (v: number) => Math.min(...Array.from(set, (u) => Math.hypot(P[3 * u] - P[3 * v], P[3 * u + 1] - P[3 * v + 1], P[3 * u + 2] - P[3 * v + 2])));

/** Region masks from the template's regions: where each shape is allowed to move the face. */
function regionMasks(): Record<string, (v: number) => boolean> {
  const r = t.regions;
  const inner = [...r.lips_inner_upper, ...r.lips_inner_lower];
  const xs = inner.map((v) => P[3 * v]);
  const W = Math.max(...xs) - Math.min(...xs);
  const mouth = centroid(inner);
  const corners = [...r.lips_inner_upper].filter((v) => r.lips_inner_lower.includes(v));
  const cornerY = corners.reduce((s, v) => s + P[3 * v + 1], 0) / corners.length;
  const eye = (side: 'left' | 'right') => {
    const loop = [...r[`eye_${side}_upper`], ...r[`eye_${side}_lower`]];
    const width = Math.max(...loop.map((v) => P[3 * v])) - Math.min(...loop.map((v) => P[3 * v]));
    const d = nearest(loop);
    return (v: number) => d(v) < 0.6 * width;
  };
  const dLips = nearest(inner), dBrows = nearest(r.brows);
  const tip = r.nose_tip[0];
  const left = (v: number) => P[3 * v] > mouth[0] - 0.05 * W, right = (v: number) => P[3 * v] < mouth[0] + 0.05 * W;
  const eyeLine = centroid([...r.eye_left_upper, ...r.eye_right_upper])[1];
  const cheek = (v: number) => Math.abs(P[3 * v] - mouth[0]) > 0.3 * W && P[3 * v + 1] < eyeLine && P[3 * v + 1] > cornerY - 0.6 * W;
  const nose = (v: number) => Math.hypot(P[3 * v] - P[3 * tip], P[3 * v + 1] - P[3 * tip + 1]) < 0.75 * W;
  return {
    eye_left: eye('left'), eye_right: eye('right'),
    mouth: (v) => dLips(v) < 0.6 * W,
    jaw: (v) => P[3 * v + 1] < cornerY + 0.35 * W,
    brows: (v) => dBrows(v) < W, brow_left: (v) => dBrows(v) < W && left(v), brow_right: (v) => dBrows(v) < W && right(v),
    cheeks: cheek, cheek_left: (v) => cheek(v) && left(v), cheek_right: (v) => cheek(v) && right(v),
    nose_left: (v) => nose(v) && left(v), nose_right: (v) => nose(v) && right(v),
  };
}

describe('the ARKit basis', () => {
  it('every shape moves the region its name says (at least 0.8 mm somewhere) and keeps 97% of its motion inside it', () => {
    const masks = regionMasks();
    const expected: Record<string, string> = { eye: 'eye', jaw: 'jaw', mouth: 'mouth', brow: 'brow', cheek: 'cheek', nose: 'nose', tongue: 'mouth' };
    ARKIT_NAMES.forEach((name, k) => {
      const region = basis.regions[k];
      const stem = name.match(/^[a-z]+/)![0];
      expect(region.startsWith(expected[stem]), `${name} is in ${region}`).toBe(true);
      if (name.endsWith('Left')) expect(region.endsWith('left') || region === 'mouth' || region === 'jaw', name).toBe(true);
      const d = shape(name);
      let inside = 0, all = 0, most = 0;
      for (let v = 0; v < n(); v++) {
        const e = len(d, v) ** 2;
        all += e;
        if (masks[region](v)) inside += e;
        most = Math.max(most, Math.sqrt(e));
      }
      expect(most, `${name}: largest motion (mm)`).toBeGreaterThan(0.8);
      expect(inside / all, `${name}: share of its motion inside ${region}`).toBeGreaterThan(0.97);
    });
  });

  it("the Left shapes move the subject's left (+x), the Right shapes its right, and mirror each other", () => {
    // The template is left-right symmetric: each vertex's mirror is the vertex nearest (-x, y, z).
    const mirror = Array.from({ length: n() }, (_, v) => {
      let best = 0, bestD = Infinity;
      for (let u = 0; u < n(); u++) {
        const d = Math.hypot(P[3 * u] + P[3 * v], P[3 * u + 1] - P[3 * v + 1], P[3 * u + 2] - P[3 * v + 2]);
        if (d < bestD) [best, bestD] = [u, d];
      }
      return best;
    });
    const cx = centroid([...t.regions.lips_inner_upper, ...t.regions.lips_inner_lower])[0];
    for (const name of ARKIT_NAMES.filter((m) => m.endsWith('Left'))) {
      const L = shape(name), R = shape(name.replace(/Left$/, 'Right') as ArkitName);
      let leftSide = 0, all = 0, worst = 0, scale = 0;
      for (let v = 0; v < n(); v++) {
        const e = len(L, v) ** 2;
        all += e;
        if (P[3 * v] > cx) leftSide += e;
        const m = mirror[v];
        worst = Math.max(worst, Math.hypot(L[3 * v] + R[3 * m], L[3 * v + 1] - R[3 * m + 1], L[3 * v + 2] - R[3 * m + 2]));
        scale = Math.max(scale, Math.sqrt(e));
      }
      // jawLeft and mouthLeft move the whole jaw / mouth towards +x; the others move the left half.
      if (!/^(jaw|mouth)Left$/.test(name)) expect(leftSide / all, `${name}: share on +x`).toBeGreaterThan(0.85);
      expect(worst / scale, `${name} against its mirrored Right`).toBeLessThan(0.02);
    }
  });

  it('each shape moves the way its name says', () => {
    const r = t.regions;
    const mean = (name: ArkitName, idx: ArrayLike<number>, k: number) => Array.from(idx).reduce((s, v) => s + shape(name)[3 * v + k], 0) / idx.length;
    const [X, Y, Z] = [0, 1, 2];
    const leftCorner = [...r.lips_inner_upper].filter((v) => r.lips_inner_lower.includes(v)).sort((a, b) => P[3 * b] - P[3 * a])[0];
    const chin = [...r.jaw].sort((a, b) => P[3 * a + 1] - P[3 * b + 1]).slice(0, 5);
    expect(mean('jawOpen', chin, Y)).toBeLessThan(-10); // the chin drops (mm at jawOpen = 1)
    const upperLip = [...r.lips_inner_upper].filter((v) => !r.lips_inner_lower.includes(v)); // without the corners
    expect(mean('jawOpen', upperLip, Y)).toBeGreaterThan(-0.5); // the upper lip stays
    expect(mean('jawForward', chin, Z)).toBeGreaterThan(2);
    expect(mean('jawLeft', chin, X)).toBeGreaterThan(2);
    expect(mean('mouthLeft', r.lips_inner_lower, X)).toBeGreaterThan(2);
    expect(shape('mouthSmileLeft')[3 * leftCorner + 1]).toBeGreaterThan(1); // the corner goes up
    expect(shape('mouthSmileLeft')[3 * leftCorner]).toBeGreaterThan(0.5); // and out
    expect(shape('mouthFrownLeft')[3 * leftCorner + 1]).toBeLessThan(-1);
    expect(shape('mouthStretchLeft')[3 * leftCorner]).toBeGreaterThan(1.5);
    expect(shape('mouthDimpleLeft')[3 * leftCorner + 2]).toBeLessThan(-1);
    expect(shape('mouthPucker')[3 * leftCorner]).toBeLessThan(-1); // the corners come in
    expect(mean('mouthPucker', r.lips_outer, Z)).toBeGreaterThan(1); // and the lips forward
    expect(mean('mouthFunnel', r.lips_outer, Z)).toBeGreaterThan(1);
    expect(mean('mouthUpperUpLeft', r.lips_inner_upper, Y)).toBeGreaterThan(0.5);
    expect(mean('mouthLowerDownLeft', r.lips_inner_lower, Y)).toBeLessThan(-0.5);
    expect(mean('mouthRollLower', r.lips_inner_lower, Z)).toBeLessThan(-1);
    expect(mean('mouthRollUpper', r.lips_inner_upper, Z)).toBeLessThan(-1);
    expect(mean('mouthShrugLower', r.lips_inner_lower, Y)).toBeGreaterThan(1);
    expect(mean('mouthClose', r.lips_inner_lower, Y)).toBeGreaterThan(1); // the lower lip comes up to the upper
    expect(mean('eyeBlinkLeft', r.eye_left_upper, Y)).toBeLessThan(-1.5);
    expect(mean('eyeWideLeft', r.eye_left_upper, Y)).toBeGreaterThan(0.5);
    expect(mean('eyeSquintLeft', r.eye_left_lower, Y)).toBeGreaterThan(0.3);
    expect(mean('eyeLookDownLeft', r.eye_left_upper, Y)).toBeLessThan(-0.3);
    expect(mean('eyeLookUpLeft', r.eye_left_upper, Y)).toBeGreaterThan(0.2);
    expect(mean('eyeLookInLeft', r.eye_left_upper, X)).toBeLessThan(-0.3); // the left eye looks in towards -x
    expect(mean('eyeLookOutLeft', r.eye_left_upper, X)).toBeGreaterThan(0.3);
    expect(mean('browInnerUp', r.brows, Y)).toBeGreaterThan(0.5);
    expect(mean('browDownLeft', r.brows, Y)).toBeLessThan(-0.5);
    expect(mean('browOuterUpLeft', r.brows, Y)).toBeGreaterThan(0.3);
    let outward = 0;
    for (let v = 0; v < n(); v++) outward += shape('cheekPuff')[3 * v] * Math.sign(P[3 * v]); // the cheeks go out sideways
    expect(outward).toBeGreaterThan(5);
  });

  it("has the lips together at the neutral face and with jawOpen and mouthClose equal; jawOpen alone parts them; eyeBlink shuts the eyes", () => {
    const N = n(), s = MM_PER_UNIT[t.units];
    const face = (weights: Partial<Record<ArkitName, number>>) => {
      const out = Float32Array.from(basis.neutral);
      for (const [name, w] of Object.entries(weights)) { const d = shape(name as ArkitName); for (let i = 0; i < out.length; i++) out[i] += w! * d[i]; }
      return out;
    };
    const gap = (f: Float32Array, up: Uint32Array, lo: Uint32Array) => innerLipGaps(f, 1, N, up, lo)[0];
    const lips = (f: Float32Array) => gap(f, t.regions.lips_inner_upper, t.regions.lips_inner_lower);
    expect(gap(Float32Array.from(t.positions, (x) => x * s), t.regions.lips_inner_upper, t.regions.lips_inner_lower)).toBeGreaterThan(3); // the template's opened mouth
    expect(Math.abs(lips(face({})))).toBeLessThan(0.05);
    expect(lips(face({ jawOpen: 0.4 }))).toBeGreaterThan(4);
    expect(Math.abs(lips(face({ jawOpen: 0.4, mouthClose: 0.4 })))).toBeLessThan(0.3);
    const eye = (f: Float32Array) => gap(f, t.regions.eye_left_upper, t.regions.eye_left_lower);
    expect(eye(face({}))).toBeGreaterThan(3);
    expect(Math.abs(eye(face({ eyeBlinkLeft: 1 })))).toBeLessThan(0.3);
    expect(eye(face({ eyeBlinkRight: 1 }))).toBeCloseTo(eye(face({})), 3); // the other eye stays open
  });

  it('the solver fits every shape but the gaze and the tongue, and the rig\'s articulators are the speech shapes', () => {
    expect(ARKIT_NAMES.filter((_, k) => !basis.fitted[k])).toEqual(['eyeLookDownLeft', 'eyeLookInLeft', 'eyeLookOutLeft', 'eyeLookUpLeft',
      'eyeLookDownRight', 'eyeLookInRight', 'eyeLookOutRight', 'eyeLookUpRight', 'tongueOut']);
    expect(ARKIT_NAMES.filter((_, k) => basis.speech[k])).toContain('jawOpen');
    expect(ARKIT_NAMES.filter((_, k) => basis.speech[k])).not.toContain('mouthFrownLeft');
  });

  it("spans the corpus rig's motion: the sample clips' ground truth (other subjects' faces) is reproduced to a fraction of a mm", () => {
    const index = JSON.parse(readFileSync(resolve(MODELS, 'samples/index.json'), 'utf8'));
    const solver = new BlendshapeSolver(basis);
    const lips = lipMask(t);
    for (const c of index.clips) {
      const bytes = buf(`samples/${c.ground_truth}`);
      const micrometres = new Int16Array(bytes, n() * 12, c.frames * n() * 3);
      const state = solver.newState();
      const w = new Float32Array(52);
      let mean = 0, lipMax = 0;
      for (let f = 0; f < c.frames; f++) {
        const O = Float32Array.from({ length: n() * 3 }, (_, i) => micrometres[f * n() * 3 + i] / 1000);
        solver.solve(O, 0, state, w);
        const R = solver.reconstruct(w);
        let worst = 0;
        for (let v = 0; v < n(); v++) {
          const e = Math.hypot(R[3 * v] - O[3 * v], R[3 * v + 1] - O[3 * v + 1], R[3 * v + 2] - O[3 * v + 2]);
          mean += e / n();
          if (lips[v]) worst = Math.max(worst, e);
        }
        lipMax += worst;
      }
      expect(mean / c.frames, `${c.name}: mean vertex error (mm)`).toBeLessThan(0.15);
      expect(lipMax / c.frames, `${c.name}: largest lip error per frame (mm)`).toBeLessThan(1.2);
    }
  });
});
