/**
 * A look into an open eye meets something (src/render/eyes.ts, head.ts): parallel rays on a grid over each eye
 * opening, from the front, 55 degrees aside, 35 above, 50 below and 35 below-and-aside (`views`), hit the head's
 * surfaces as three.js draws them (each material's side) or the ball; none goes through to the page. Before the
 * skirts behind the openings, rays past the ball at the inner corners went into the head, whose inside is not drawn.
 */
import { beforeAll, describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { Head } from '../../../src/render/head';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

beforeAll(() => {
  // The eyes' texture is drawn on a canvas, which Node lacks: a blank one will do here.
  if (typeof OffscreenCanvas === 'undefined') {
    Object.assign(globalThis, {
      OffscreenCanvas: class {
        constructor(readonly width: number, readonly height: number) {}
        getContext() {
          return { createImageData: (w: number, h: number) => ({ data: new Uint8ClampedArray(w * h * 4) }), putImageData: () => undefined };
        }
      },
    });
  }
});

const views: Record<string, [number, number]> = { front: [0, 0], aside: [55, 0], above: [0, 35], below: [0, -50], 'below aside': [35, -35] };

describe('the eye openings', () => {
  it('show the ball or the skirt behind it from every side, never the page', async () => {
    const t = await loadTemplateFile(loadManifest());
    const head = new Head(t);
    head.group.updateMatrixWorld(true);
    const ray = new THREE.Raycaster();
    const r = head.eyes.radii[0];
    const escaped: Record<string, number> = {};
    for (const [name, [az, el]] of Object.entries(views)) {
      const [a, e] = [(az * Math.PI) / 180, (el * Math.PI) / 180];
      const toward = new THREE.Vector3(-Math.sin(a) * Math.cos(e), -Math.sin(e), -Math.cos(a) * Math.cos(e)); // into the face
      const u = new THREE.Vector3().crossVectors(toward, new THREE.Vector3(0, 1, 0)).normalize();
      const w = new THREE.Vector3().crossVectors(u, toward);
      let out = 0, total = 0;
      for (const side of ['left', 'right'] as const) {
        // A grid across the opening as seen along `toward` (its lid vertices' extent, a little wider).
        const lids = [...t.regions[`eye_${side}_upper`], ...t.regions[`eye_${side}_lower`]].map((v) => new THREE.Vector3().fromArray(t.positions, 3 * v));
        const mid = lids.reduce((s, q) => s.add(q), new THREE.Vector3()).divideScalar(lids.length);
        const us = lids.map((q) => q.clone().sub(mid).dot(u)), ws = lids.map((q) => q.clone().sub(mid).dot(w));
        const steps = 40;
        for (let i = 0; i <= steps; i++) {
          for (let j = 0; j <= steps; j++) {
            const du = Math.min(...us) * 1.1 + ((Math.max(...us) - Math.min(...us)) * 1.1 * i) / steps;
            const dw = Math.min(...ws) * 1.1 + ((Math.max(...ws) - Math.min(...ws)) * 1.1 * j) / steps;
            const origin = mid.clone().addScaledVector(u, du).addScaledVector(w, dw).addScaledVector(toward, -20 * r);
            ray.set(origin, toward);
            total++;
            if (ray.intersectObject(head.group, true).length === 0) out++;
          }
        }
      }
      escaped[name] = out;
      console.log(`${name}: ${out} of ${total} rays over the openings meet nothing`);
    }
    for (const [name, out] of Object.entries(escaped)) expect(out, `${name}: rays through to the page`).toBe(0);
  }, 120_000);
});
