/**
 * The skin stays outside the eyeballs (src/render/eyes.ts): at rest and with the lids closed by a blink, every
 * skin triangle near a ball (its corners, edge midpoints and centre) lies outside it, the push moves the skin by
 * little, and the blink still closes the lids.
 */
import { describe, expect, it } from 'vitest';
import { ballsFor, SkinClearance } from '../../../src/render/eyes';
import { blinkField, lidOpening, lidPairs } from '../../../src/render/eyelids';
import { loadManifest, loadTemplateFile } from '../helpers/exported';
import type { FaceTemplate } from '../../../src/template/face-template';

/** The deepest any sampled point of a skin triangle near a ball goes inside it, as a share of its radius (0: none). */
function deepestInside(t: FaceTemplate, p: Float32Array, balls: ReturnType<typeof ballsFor>): number {
  let worst = 0;
  const tri = t.triangles;
  const at = (w: number[], f: number, k: number) => w.reduce((s, wi, i) => s + wi * p[3 * tri[f + i] + k], 0);
  const samples = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0.5, 0], [0, 0.5, 0.5], [0.5, 0, 0.5], [1 / 3, 1 / 3, 1 / 3]];
  balls.centers.forEach((c, k) => {
    const r = balls.radii[k];
    for (let f = 0; f < tri.length; f += 3) {
      for (const w of samples) {
        const x = at(w, f, 0) - c.x, y = at(w, f, 1) - c.y, z = at(w, f, 2) - c.z;
        if (z <= 0) continue; // the ball's front half: what shows through the lids
        worst = Math.max(worst, (r - Math.hypot(x, y, z)) / r);
      }
    }
  });
  return worst;
}

describe('SkinClearance', () => {
  it('keeps the skin out of the balls at rest and in a blink, moving it by little', async () => {
    const t = await loadTemplateFile(loadManifest());
    const balls = ballsFor(t);
    const clearance = new SkinClearance(t, balls.centers, balls.radii);
    const blink = blinkField(t);
    const pairs = lidPairs(t);
    for (const b of [0, 0.5, 1]) {
      const face = Float32Array.from(t.positions, (q, i) => q + b * blink[i]);
      const kept = face.slice();
      clearance.apply(kept);
      if (b === 0) expect(deepestInside(t, face, balls)).toBeGreaterThan(0.01); // the template's lid corners are inside
      expect(deepestInside(t, kept, balls)).toBeLessThanOrEqual(0);
      let moved = 0;
      for (let v = 0; v < t.vertexCount; v++) moved = Math.max(moved, Math.hypot(kept[3 * v] - face[3 * v], kept[3 * v + 1] - face[3 * v + 1], kept[3 * v + 2] - face[3 * v + 2]));
      expect(moved).toBeLessThan(0.15 * balls.radii[0]);
      if (b === 1) expect(Math.abs(lidOpening(kept, pairs))).toBeLessThan(0.1 * lidOpening(t.positions, pairs));
    }
  });
});
