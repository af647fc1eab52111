import { describe, expect, it } from 'vitest';
import { motionBasis } from '../../../src/app/motion-basis';

/** frames x dims displacements: `rank` fixed directions with smooth, independent weights, plus `noise`. */
function motion(frames: number, points: number, rank: number, noise: number): Float32Array {
  const dims = points * 3;
  const D = new Float32Array(frames * dims);
  for (let f = 0; f < frames; f++)
    for (let r = 0; r < rank; r++) {
      const w = Math.sin(f * (0.05 + 0.031 * r) + r) * (1 + r) ** -0.5;
      for (let i = 0; i < dims; i++) D[f * dims + i] += w * Math.cos(i * (0.7 + 0.13 * r) + 2 * r) + (r === 0 ? 0.3 : 0);
    }
  for (let i = 0; i < D.length; i++) D[i] += noise * Math.sin(i * 12.9898) * 0.5;
  return D;
}

function reconstructionError(D: Float32Array, frames: number, dims: number, m: Awaited<ReturnType<typeof motionBasis>>): number {
  let worst = 0;
  for (let f = 0; f < frames; f++)
    for (let i = 0; i < dims; i += 3) {
      const e = [0, 1, 2].map((a) => {
        let r = m.mean[i + a];
        for (let k = 0; k < m.components; k++) r += m.coefficients[f * m.components + k] * m.basis[k * dims + i + a];
        return D[f * dims + i + a] - r;
      });
      worst = Math.max(worst, Math.hypot(...e));
    }
  return worst;
}

describe('motion components for the compact .glb', () => {
  it('recovers a motion of rank <= K exactly, and reports its error honestly when the rank is higher', async () => {
    const frames = 500, points = 60, dims = points * 3;
    const low = motion(frames, points, 6, 0);
    const m = await motionBasis(low, frames, dims, 8);
    expect(m.components).toBe(8);
    expect(m.maxError).toBeLessThan(1e-4);
    expect(reconstructionError(low, frames, dims, m)).toBeLessThan(1e-4);
    // Orthonormal directions, strongest first.
    for (let a = 0; a < 8; a++)
      for (let b = 0; b < 8; b++) {
        let dot = 0;
        for (let i = 0; i < dims; i++) dot += m.basis[a * dims + i] * m.basis[b * dims + i];
        if (m.basis.subarray(a * dims, (a + 1) * dims).some((v) => v !== 0) && m.basis.subarray(b * dims, (b + 1) * dims).some((v) => v !== 0)) {
          expect(dot).toBeCloseTo(a === b ? 1 : 0, 5);
        }
      }
    const power = (k: number) => Array.from({ length: frames }, (_, f) => m.coefficients[f * 8 + k] ** 2).reduce((s, v) => s + v, 0);
    for (let k = 1; k < 6; k++) expect(power(k)).toBeLessThanOrEqual(power(k - 1) * (1 + 1e-6));

    const high = motion(frames, points, 14, 0.01);
    const h = await motionBasis(high, frames, dims, 8);
    const actual = reconstructionError(high, frames, dims, h);
    expect(h.maxError).toBeGreaterThan(1e-3);
    expect(h.maxError).toBeCloseTo(actual, 4);
    // More components, less error.
    expect((await motionBasis(high, frames, dims, 14)).maxError).toBeLessThan(h.maxError);
  });

  it('handles fewer frames than components and a still face', async () => {
    const dims = 30;
    const two = motion(2, 10, 3, 0);
    expect((await motionBasis(two, 2, dims, 8)).maxError).toBeLessThan(1e-5);
    const still = new Float32Array(100 * dims).fill(0.25);
    const s = await motionBasis(still, 100, dims, 8);
    expect(s.maxError).toBeLessThan(1e-6);
    expect(s.mean.every((v) => Math.abs(v - 0.25) < 1e-7)).toBe(true);
    await expect(motionBasis(still, 99, dims, 8)).rejects.toThrow(/not 99 x 30/);
  });

  it('finds the directions on a spread of the frames, and projects every frame on them (a long clip)', async () => {
    const frames = 3000, points = 40, dims = points * 3;
    const low = motion(frames, points, 6, 0);
    const seen: number[] = [];
    const m = await motionBasis(low, frames, dims, 8, { fitFrames: 200, onProgress: (d) => seen.push(d) });
    expect(m.maxError, 'rank 6 from 200 of 3,000 frames').toBeLessThan(1e-4);
    expect(reconstructionError(low, frames, dims, m)).toBeLessThan(1e-4);
    expect(m.coefficients).toHaveLength(frames * 8);
    expect(seen.at(-1)).toBe(1);
    expect(seen.every((d, i) => i === 0 || d >= seen[i - 1])).toBe(true);
    // Aborted: it stops (at its next yield) with the signal's reason.
    await expect(motionBasis(low, frames, dims, 8, { signal: AbortSignal.abort() })).rejects.toThrow();
  });
});
