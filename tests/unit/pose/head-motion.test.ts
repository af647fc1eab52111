/**
 * The head's own motion (src/pose/head-motion.ts) against the Python sampler's fixture (the exporter draws seed 0 on
 * the fixture clip: models/fixtures), chunked = whole, and the statistics the process is meant to have.
 */
import { describe, expect, it } from 'vitest';
import { f32, parseSafetensors } from '../../../src/model/safetensors';
import { HeadMotion, checkedScale, headMotionParams, headNormal } from '../../../src/pose/head-motion';
import { buf, loadFixtures, loadManifest, maxAbsDiff } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);
const m = manifest.model.config;
const params = headMotionParams(parseSafetensors(buf(manifest.files.decoder_weights)).tensors, m);

describe.skipIf(!manifest.head_motion)('the head\'s own motion', () => {
  const head = new HeadMotion(params!, m.d_model);
  const frames = manifest.fixtures.frames;
  const poseToken = f32(fx, 'pose_token');

  it('refuses a process that does not settle (its poses would be NaN), naming the axis', () => {
    const tensors = parseSafetensors(buf(manifest.files.decoder_weights)).tensors;
    for (const ar of [[1.5, -0.5], [1.2, -0.1], [0.2, -1]]) {
      const bad = Float32Array.from(f32(tensors, 'head_motion.ar'));
      bad.set(ar, 2);
      const t = new Map(tensors).set('head_motion.ar', { dtype: 'F32', shape: [3, 2], data: bad });
      expect(() => headMotionParams(t, m)).toThrow(/axis 1's AR\(2\) .* does not settle/);
    }
    expect(headMotionParams(tensors, m)).not.toBeNull(); // the shipped one settles (0.988 to 0.993)
  });

  it('draws the same residuals as the Python sampler for seed 0, and turns the poses the same way', () => {
    const residual = head.residuals(head.start(0), 0, poseToken, frames);
    expect(maxAbsDiff(residual, f32(fx, 'head_residual'))).toBeLessThan(1e-4); // degrees; the fixture is float32
    const pose = f32(fx, 'pose').slice();
    head.compose(pose, residual, frames);
    expect(maxAbsDiff(pose, f32(fx, 'pose_sampled'))).toBeLessThan(1e-5);
  });

  it('scales the residual it turns the poses by: 0 leaves the mean pose, 2 is the residual doubled', () => {
    const residual = head.residuals(head.start(0), 0, poseToken, frames);
    const mean = f32(fx, 'pose');
    const still = mean.slice();
    head.compose(still, residual, frames, 0);
    expect(maxAbsDiff(still, mean)).toBeLessThan(1e-6);
    const scaled = mean.slice(), doubled = mean.slice();
    head.compose(scaled, residual, frames, 2);
    head.compose(doubled, residual.map((x) => 2 * x), frames);
    expect(maxAbsDiff(scaled, doubled)).toBeLessThan(1e-6);
    expect(maxAbsDiff(scaled, mean)).toBeGreaterThan(0.01);
  });

  it('in chunks equals whole, and another seed draws other motion', () => {
    const whole = head.residuals(head.start(7), 0, poseToken, frames);
    const state = head.start(7);
    const a = head.residuals(state, 0, poseToken.subarray(0, 5 * m.d_model), 5);
    const b = head.residuals(state, 5, poseToken.subarray(5 * m.d_model), frames - 5);
    expect(maxAbsDiff([...a, ...b], whole)).toBe(0);
    expect(maxAbsDiff(head.residuals(head.start(8), 0, poseToken, frames), whole)).toBeGreaterThan(0.01);
  });

  it('has the spread of its stationary distribution over a long run', () => {
    const n = 20000;
    const tokens = new Float32Array(n * m.d_model);
    for (let i = 0; i < n; i++) tokens.set(poseToken.subarray(0, m.d_model), i * m.d_model);
    const r = head.residuals(head.start(1), 0, tokens, n);
    for (let k = 0; k < 3; k++) {
      const a1 = params!.ar[2 * k], a2 = params!.ar[2 * k + 1];
      let x = params!.sigmaB[k];
      for (let j = 0; j < m.d_model; j++) x += params!.sigmaW[k * m.d_model + j] * poseToken[j];
      const step = params!.gain[k] * Math.log1p(Math.exp(x));
      const want = step * Math.sqrt((1 - a2) / ((1 + a2) * ((1 - a2) ** 2 - a1 ** 2)));
      let s = 0, s2 = 0;
      for (let i = 0; i < n; i++) { s += r[3 * i + k]; s2 += r[3 * i + k] ** 2; }
      const sd = Math.sqrt(s2 / n - (s / n) ** 2);
      expect(sd / want).toBeGreaterThan(0.85);
      expect(sd / want).toBeLessThan(1.15);
    }
  });
});

describe('headNormal', () => {
  it('is a standard normal: mean 0, variance 1, no correlation between neighbouring frames', () => {
    const z = Array.from({ length: 30000 }, (_, i) => headNormal(3, i, i % 3));
    const mean = z.reduce((a, b) => a + b, 0) / z.length;
    const variance = z.reduce((a, b) => a + (b - mean) ** 2, 0) / z.length;
    let lag = 0;
    for (let i = 1; i < z.length; i++) lag += (z[i] - mean) * (z[i - 1] - mean);
    expect(Math.abs(mean)).toBeLessThan(0.03);
    expect(Math.abs(variance - 1)).toBeLessThan(0.04);
    expect(Math.abs(lag / z.length)).toBeLessThan(0.03);
  });
});

describe('checkedScale', () => {
  it('passes a head-motion scale from 0 to 3 (or none) and names the range otherwise', () => {
    expect(checkedScale(undefined)).toBeUndefined();
    expect(checkedScale(0)).toBe(0);
    expect(checkedScale(1.5)).toBe(1.5);
    for (const bad of [-0.1, 3.5, Number.NaN, Number.POSITIVE_INFINITY]) expect(() => checkedScale(bad)).toThrow(/from 0 to 3/);
  });
});
