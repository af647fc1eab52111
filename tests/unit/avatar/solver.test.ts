/**
 * The ARKit solver (src/avatar/solver.ts): bounded least squares, exact, the same answer from any warm start,
 * weights inside [0, 1], the unfitted shapes at 0, and fast enough for the streaming path.
 */
import { beforeAll, describe, expect, it } from 'vitest';
import { arkitBasis, type ArkitBasis } from '../../../src/avatar/basis';
import { BlendshapeSolver } from '../../../src/avatar/solver';
import { ARKIT_NAMES, type ArkitName } from '../../../src/avatar/names';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

let basis: ArkitBasis;
let solver: BlendshapeSolver;
beforeAll(async () => {
  basis = arkitBasis(await loadTemplateFile(loadManifest()));
  solver = new BlendshapeSolver(basis);
});

const weightsOf = (w: Partial<Record<ArkitName, number>>) => Float32Array.from(ARKIT_NAMES, (n) => w[n] ?? 0);
/** The displacement O (from the template, mm) that weights make. */
const displacement = (w: Partial<Record<ArkitName, number>>) => solver.reconstruct(weightsOf(w));

describe('BlendshapeSolver', () => {
  it('recovers the weights that made a face (speech shapes to within 0.04, the rest to within 0.06: the L1 term shrinks them a little)', () => {
    const truth = { jawOpen: 0.4, mouthClose: 0.25, mouthFunnel: 0.5, mouthSmileLeft: 0.3, mouthUpperUpRight: 0.35, eyeBlinkRight: 0.8,
      browInnerUp: 0.6, mouthFrownRight: 0.4, cheekSquintRight: 0.5, noseSneerLeft: 0.7 } as const;
    const w = new Float32Array(52);
    solver.solve(displacement(truth), 0, solver.newState(), w);
    ARKIT_NAMES.forEach((name, k) => {
      const want = (truth as Partial<Record<ArkitName, number>>)[name] ?? 0;
      expect(Math.abs(w[k] - want), `${name}: ${w[k]} for ${want}`).toBeLessThan(basis.speech[k] ? 0.04 : 0.06);
    });
  });

  it('keeps every weight in [0, 1]: twice jawOpen gives 1, a closing jaw 0', () => {
    const w = new Float32Array(52);
    solver.solve(displacement({ jawOpen: 2 }), 0, solver.newState(), w);
    expect(w[ARKIT_NAMES.indexOf('jawOpen')]).toBe(1);
    solver.solve(displacement({ jawOpen: -0.5, mouthPucker: 0.5 }), 0, solver.newState(), w);
    expect(w[ARKIT_NAMES.indexOf('jawOpen')]).toBe(0);
    expect(w[ARKIT_NAMES.indexOf('mouthPucker')]).toBeGreaterThan(0.4);
    expect(Math.min(...w)).toBeGreaterThanOrEqual(0);
    expect(Math.max(...w)).toBeLessThanOrEqual(1);
  });

  it('gives the same weights from any warm start (the minimiser is unique), in a few solves when warm', () => {
    const face = displacement({ jawOpen: 0.3, mouthClose: 0.1, mouthPucker: 0.6, mouthStretchLeft: 0.2, browDownRight: 0.3 });
    const cold = new Float32Array(52), warm = new Float32Array(52), again = new Float32Array(52);
    solver.solve(face, 0, solver.newState(), cold);
    const coldSolves = solver.lastSolves;
    const state = { weights: Float32Array.from({ length: 52 }, (_, k) => (k * 0.37) % 1) };
    solver.solve(face, 0, state, warm);
    for (let k = 0; k < 52; k++) expect(Math.abs(warm[k] - cold[k]), ARKIT_NAMES[k]).toBeLessThan(1e-6);
    solver.solve(face, 0, state, again); // the previous answer as the start: done at once
    expect(solver.lastSolves).toBe(1);
    expect(coldSolves).toBeGreaterThan(1);
  });

  it('leaves the gaze and the tongue at 0 whatever the face', () => {
    const w = new Float32Array(52);
    solver.solve(displacement({ eyeLookDownLeft: 1, tongueOut: 1, jawOpen: 0.2 }), 0, solver.newState(), w);
    for (const name of ['eyeLookDownLeft', 'eyeLookUpRight', 'tongueOut'] as const) expect(w[ARKIT_NAMES.indexOf(name)]).toBe(0);
  });

  it('costs well under a millisecond a frame along a moving face (warm-started)', () => {
    const state = solver.newState();
    const w = new Float32Array(52);
    const frames = Array.from({ length: 120 }, (_, f) => displacement({
      jawOpen: 0.3 + 0.25 * Math.sin(f / 3), mouthClose: Math.max(0, 0.2 * Math.sin(f / 5)), mouthFunnel: Math.max(0, 0.4 * Math.cos(f / 7)),
      mouthSmileLeft: 0.1, mouthSmileRight: 0.1, mouthLowerDownLeft: 0.3 + 0.2 * Math.sin(f / 4), mouthLowerDownRight: 0.3 + 0.2 * Math.sin(f / 4),
    }));
    for (const d of frames.slice(0, 20)) solver.solve(d, 0, state, w); // warm the JIT
    const t = performance.now();
    for (const d of frames) solver.solve(d, 0, state, w);
    expect((performance.now() - t) / frames.length).toBeLessThan(1);
  });
});
