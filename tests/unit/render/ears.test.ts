/**
 * The ears (src/render/ears.ts) on the shipped template's head: each a closed surface facing outwards, the two
 * mirror images of each other, attached to the head shell (part of each inside the egg it lies on, most outside),
 * from about the brows' height to the nose's base.
 */
import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { earGeometries } from '../../../src/render/ears';
import { headShell, SQUARENESS } from '../../../src/render/head-shell';
import { boundaryLoops } from '../../../src/template/mesh-topology';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

describe('earGeometries', () => {
  it('gives two closed, outward-facing ears, mirror images, attached to the head at the right height', async () => {
    const t = await loadTemplateFile(loadManifest());
    const shell = headShell(t)!;
    const { egg, measures: m } = shell;
    const H = m.top - m.chin;
    const ears = earGeometries(m, egg, new THREE.Color(0xcc9c84));
    expect(ears).toHaveLength(2);
    /** The egg's implicit value at a point (head-shell.ts: 1 on its surface, less inside). */
    const inEgg = (x: number, y: number, z: number) =>
      Math.abs((x - egg.center[0]) / egg.ax) ** SQUARENESS + Math.abs((y - egg.center[1]) / (y >= egg.center[1] ? egg.up : egg.down)) ** SQUARENESS
      + Math.abs((z - egg.center[2]) / (z >= egg.center[2] ? egg.front : egg.back)) ** SQUARENESS;
    const boxes = ears.map((g) => {
      const pos = g.getAttribute('position') as THREE.BufferAttribute;
      const index = Uint32Array.from(g.getIndex()!.array);
      expect(boundaryLoops(index)).toEqual([]); // closed
      // Outward: a closed surface wound outwards encloses a positive volume.
      let volume = 0;
      const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3();
      for (let i = 0; i < index.length; i += 3) {
        a.fromBufferAttribute(pos, index[i]);
        b.fromBufferAttribute(pos, index[i + 1]);
        c.fromBufferAttribute(pos, index[i + 2]);
        volume += a.dot(b.cross(c)) / 6;
      }
      expect(volume).toBeGreaterThan(0);
      const used = [...new Set(index)];
      const inside = used.filter((v) => inEgg(pos.getX(v), pos.getY(v), pos.getZ(v)) < 1).length;
      expect(inside).toBeGreaterThan(0); // attached
      expect(inside).toBeLessThan(0.5 * used.length); // standing out
      return new THREE.Box3().setFromBufferAttribute(pos);
    });
    const [left, right] = boxes;
    expect(left.max.x).toBeLessThan(m.centerX);
    expect(right.min.x).toBeGreaterThan(m.centerX);
    expect(m.centerX - left.min.x).toBeCloseTo(right.max.x - m.centerX, 5);
    for (const box of boxes) {
      expect(box.max.y).toBeGreaterThan(m.eyeY);
      expect(box.max.y).toBeLessThan(m.eyeY + 0.15 * H);
      expect(box.min.y).toBeLessThan(m.eyeY - 0.25 * H);
      expect(box.min.y).toBeGreaterThan(m.cornerY);
    }
  });
});
