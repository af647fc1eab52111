/**
 * The blink field (src/render/eyelids.ts): fully applied, it closes both eyes, the upper lid passing a little over
 * the lower (lid-seal.test.ts: no gap between them); the corners and the mouth stay.
 */
import { describe, expect, it } from 'vitest';
import { blinkField } from '../../../src/render/eyelids';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

describe('blinkField', () => {
  it('closes each lid opening, the upper lid over the lower by a twentieth to a fifth of its height', async () => {
    const t = await loadTemplateFile(loadManifest());
    const d = blinkField(t);
    const closed = Float32Array.from(t.positions, (p, i) => p + d[i]);
    for (const side of ['left', 'right']) {
      const up = [...t.regions[`eye_${side}_upper`]], lo = [...t.regions[`eye_${side}_lower`]];
      const corners = up.filter((v) => lo.includes(v));
      const mean = (p: Float32Array, vs: number[]) => vs.filter((v) => !corners.includes(v)).reduce((s, v) => s + p[3 * v + 1], 0) / (vs.length - corners.length);
      const open = mean(t.positions, up) - mean(t.positions, lo);
      expect(open).toBeGreaterThan(0);
      const passed = (mean(closed, lo) - mean(closed, up)) / open;
      expect(passed).toBeGreaterThan(0.05);
      expect(passed).toBeLessThan(0.2);
      for (const c of corners) expect(Math.hypot(d[3 * c], d[3 * c + 1], d[3 * c + 2])).toBe(0);
    }
    for (const v of [...t.regions.lips_outer, ...t.regions.lips_inner_upper]) expect(d[3 * v + 1]).toBe(0);
  });
});
