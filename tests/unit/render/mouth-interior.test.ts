/**
 * The mouth's inside (src/render/mouth-interior.ts): the cavity's rim is the inner-lip loop itself and the bag is
 * closed (lips + bag leave no opening), it follows the lips and the jaw, and the tongue's raise lifts its tip.
 */
import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { mouthBag, mouthFrame, teethGeometry, tongueGeometry, updateBag } from '../../../src/render/mouth-interior';
import { jawHinge } from '../../../src/render/jaw';
import { faceMeasures, ovalLoop } from '../../../src/render/head-shell';
import { boundaryLoops } from '../../../src/template/mesh-topology';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

describe('mouthBag', () => {
  it('closes the mouth behind the lips and follows them and the jaw', async () => {
    const t = await loadTemplateFile(loadManifest());
    const bag = mouthBag(t, t.vertexCount)!;
    expect(new Set(bag.rim)).toEqual(new Set([...t.regions.lips_inner_upper, ...t.regions.lips_inner_lower]));
    const loops = boundaryLoops(Uint32Array.from([...t.triangles, ...bag.triangles]));
    expect(loops.some((l) => l.some((v) => bag.rim.includes(v)))).toBe(false); // the mouth is no longer a hole
    const hinge = jawHinge(t, faceMeasures(t, ovalLoop(t)!));
    const out = new Float32Array(bag.rest.length);
    updateBag(bag, t.positions, t.positions, hinge, 0, out);
    expect(Array.from(out)).toEqual(Array.from(bag.rest));
    // The lower lip drops 1 cm: the bag's first ring under it drops with it, the upper half does not move.
    const face = t.positions.slice();
    const lowerOnly = [...t.regions.lips_inner_lower].filter((v) => !t.regions.lips_inner_upper.includes(v));
    for (const v of lowerOnly) face[3 * v + 1] -= 1;
    updateBag(bag, t.positions, face, hinge, 0.1, out);
    const M = bag.rim.length;
    for (let i = 0; i < M; i++) {
      const dy = out[3 * i + 1] - bag.rest[3 * i + 1];
      if (lowerOnly.includes(bag.rim[i])) expect(dy).toBeLessThan(-0.5);
      else if (bag.jaw[i] === 0) expect(Math.abs(dy)).toBeLessThan(1e-6);
    }
  });

  it('the tongue\'s raise lifts its front, not its back', async () => {
    const t = await loadTemplateFile(loadManifest());
    const f = mouthFrame(t);
    const g = tongueGeometry(f);
    const pos = g.getAttribute('position') as THREE.BufferAttribute;
    const raise = g.morphAttributes.position![0] as THREE.BufferAttribute;
    let tip = 0, back = 0;
    for (let i = 0; i < pos.count; i++) {
      if (pos.getZ(i) > f.frontZ - 0.3 * f.W) tip = Math.max(tip, raise.getY(i));
      if (pos.getZ(i) < f.frontZ - 1.1 * f.W) back = Math.max(back, raise.getY(i));
    }
    expect(tip).toBeGreaterThan(0.5 * f.W * 0.5);
    expect(back).toBe(0);
  });

  it('the tongue stays behind the incisors: at rest behind the lower ones, raised behind the upper ones', async () => {
    const t = await loadTemplateFile(loadManifest());
    const f = mouthFrame(t);
    const g = tongueGeometry(f);
    const pos = g.getAttribute('position') as THREE.BufferAttribute;
    const raise = g.morphAttributes.position![0] as THREE.BufferAttribute;
    /** The inner (back) face of the central incisors: the least z of the teeth within 0.1 W of the midline. */
    const innerFace = (upper: boolean) => {
      const teeth = teethGeometry(f, upper).getAttribute('position') as THREE.BufferAttribute;
      let z = Infinity;
      for (let i = 0; i < teeth.count; i++) if (Math.abs(teeth.getX(i) - f.center[0]) < 0.1 * f.W) z = Math.min(z, teeth.getZ(i));
      return z;
    };
    let rest = -Infinity, raised = -Infinity;
    for (let i = 0; i < pos.count; i++) {
      rest = Math.max(rest, pos.getZ(i));
      raised = Math.max(raised, pos.getZ(i) + raise.getZ(i));
    }
    expect(rest, 'the tip at rest, against the lower incisors\' inner face').toBeLessThan(innerFace(false));
    expect(raised, 'the tip raised, against the upper incisors\' inner face').toBeLessThan(innerFace(true));
  });

  it('the teeth stand round an arch inside the cheeks: the molars about 0.6 W out and 0.7 W back', async () => {
    const t = await loadTemplateFile(loadManifest());
    const f = mouthFrame(t);
    for (const upper of [true, false]) {
      const box = new THREE.Box3().setFromBufferAttribute(teethGeometry(f, upper).getAttribute('position') as THREE.BufferAttribute);
      // Placed by x alone (before), the arch reached 1.04 W out, beyond the mouth's corners, into the cheeks.
      expect(Math.max(box.max.x - f.center[0], f.center[0] - box.min.x) / f.W).toBeGreaterThan(0.5);
      expect(Math.max(box.max.x - f.center[0], f.center[0] - box.min.x) / f.W).toBeLessThan(0.75);
      expect((f.frontZ - box.min.z) / f.W).toBeLessThan(1);
    }
  });
});
