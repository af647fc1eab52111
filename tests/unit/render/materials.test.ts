/**
 * The head's colours (src/render/materials.ts, headColors): hair on the crown and the back of the head, and skin round
 * each ear (ears.ts, earPlace), where before the hair came down to the top of the ear.
 */
import { describe, expect, it } from 'vitest';
import { headColors, SKIN } from '../../../src/render/materials';
import { headShell } from '../../../src/render/head-shell';
import { earPlace } from '../../../src/render/ears';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

describe('headColors', () => {
  it('leaves skin just above the ears and hair higher up', async () => {
    const t = await loadTemplateFile(loadManifest());
    const shell = headShell(t)!;
    const ear = earPlace(shell.measures, shell.egg);
    const colors = headColors(t, shell.positions, shell.egg, ear);
    const p = shell.positions, n = t.vertexCount, { center, ax } = shell.egg;
    /** Each side's shell vertices at (dy, dz) from the ear's middle (in its height and width) within the ranges given. */
    const near = (dy: [number, number], dz: [number, number]) => {
      const found: number[][] = [[], []];
      for (let i = 0; i < p.length / 3; i++) {
        const x = p[3 * i] - center[0], y = (p[3 * i + 1] - ear.y) / ear.height, z = (p[3 * i + 2] - ear.z) / ear.width;
        if (Math.abs(x) > 0.5 * ax && y >= dy[0] && y <= dy[1] && z >= dz[0] && z <= dz[1]) found[x > 0 ? 1 : 0].push(i);
      }
      return found;
    };
    const fromSkin = (i: number) => Math.hypot(colors[3 * (n + i)] - SKIN.r, colors[3 * (n + i) + 1] - SKIN.g, colors[3 * (n + i) + 2] - SKIN.b);
    // Just above the ear's top (at half its height): skin, on both sides.
    for (const side of near([0.52, 0.62], [-0.2, 0.2])) {
      expect(side.length).toBeGreaterThan(0);
      for (const i of side) expect(fromSkin(i), 'just above the ear').toBeLessThan(0.05);
    }
    // Half an ear higher: hair.
    for (const side of near([0.9, 1.1], [-0.5, 0.5])) {
      expect(side.length).toBeGreaterThan(0);
      for (const i of side) expect(fromSkin(i), 'above the ear').toBeGreaterThan(0.5);
    }
  });
});
