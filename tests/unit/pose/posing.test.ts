/** Posing (src/pose/posing.ts, paper Eq. 2) against PyTorch's posed vertices, and the unit conversion of poseFrames. */
import { describe, expect, it } from 'vitest';
import type { Manifest } from '../../../src/model/manifest';
import { f32 } from '../../../src/model/safetensors';
import { applyPose, poseFrames } from '../../../src/pose/posing';
import { loadFixtures, loadManifest, maxAbsDiff } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);

describe('posing', () => {
  it('y = R (I + O) + t equals PyTorch on the fixture\'s offsets and poses', () => {
    const frames = manifest.fixtures.frames;
    const y = applyPose(f32(fx, 'template_mm'), f32(fx, 'offsets'), f32(fx, 'pose'), frames);
    expect(maxAbsDiff(y, f32(fx, 'vertices'))).toBeLessThan(1e-3); // mm: 1e-4 of the template's cm
  });

  it('a zero pose leaves I + O where it is; poseFrames divides both outputs by mm per unit', () => {
    const template = Float32Array.from([0, 0, 0, 10, 20, 30]);
    const offsets = Float32Array.from([1, 2, 3, -1, -2, -3]);
    const { vertices, unposed } = poseFrames(template, offsets, new Float32Array(6), 1, 10);
    expect(Array.from(vertices)).toEqual([0.1, 0.2, 0.3, 0.9, 1.8, 2.7].map((v) => Math.fround(v)));
    expect(Array.from(unposed)).toEqual(Array.from(vertices));
  });

  it('a quarter turn about y takes +x to -z, and the translation adds', () => {
    const y = applyPose(Float32Array.from([1, 0, 0]), new Float32Array(3), Float32Array.from([0, Math.PI / 2, 0, 5, 6, 7]), 1);
    expect(y[0]).toBeCloseTo(5, 6);
    expect(y[1]).toBeCloseTo(6, 6);
    expect(y[2]).toBeCloseTo(6, 6);
  });
});
