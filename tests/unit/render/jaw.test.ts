/** The jaw's angle (src/render/jaw.ts): turning the template's lower face about the hinge by a gives a back. */
import { describe, expect, it } from 'vitest';
import { JawEstimator, jawHinge, turnAboutHinge } from '../../../src/render/jaw';
import { faceMeasures, ovalLoop } from '../../../src/render/head-shell';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

describe('JawEstimator', () => {
  it('recovers a rotation of the chin and lower lip, and reads the template as 0', async () => {
    const t = await loadTemplateFile(loadManifest());
    const m = faceMeasures(t, ovalLoop(t)!);
    const hinge = jawHinge(t, m);
    const jaw = new JawEstimator(t, m, hinge);
    expect(jaw.angle(t.positions)).toBeCloseTo(0, 6);
    for (const a of [-0.05, 0.08, 0.2]) {
      const v = t.positions.slice();
      const out = [0, 0];
      for (let i = 0; i < t.vertexCount; i++) {
        if (v[3 * i + 1] > m.cornerY) continue; // the lower face turns; the rest stays
        turnAboutHinge(hinge, a, v[3 * i + 1], v[3 * i + 2], out);
        [v[3 * i + 1], v[3 * i + 2]] = out;
      }
      expect(jaw.angle(v)).toBeCloseTo(a, 4);
    }
    // Opening moves the chin down.
    const out = [0, 0];
    turnAboutHinge(hinge, 0.1, m.chin, t.positions[3 * 152 + 2], out);
    expect(out[0]).toBeLessThan(m.chin);
  });
});
