/** PartialNormals (src/render/normals.ts) equals three.js's computeVertexNormals after only some vertices moved. */
import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { PartialNormals } from '../../../src/render/normals';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

describe('PartialNormals', () => {
  it('matches a full recomputation when the moving vertices move', async () => {
    const t = await loadTemplateFile(loadManifest());
    const positions = t.positions.slice();
    const moving = (v: number) => positions[3 * v + 1] < -3; // the lower face
    const partial = new PartialNormals(t.triangles, positions, moving);
    const out = new Float32Array(positions.length);
    partial.init(positions, out);
    for (let v = 0; v < t.vertexCount; v++) if (moving(v)) positions[3 * v + 2] += 0.3 * Math.sin(v);
    partial.update(positions, out);
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    g.setIndex(new THREE.BufferAttribute(t.triangles, 1));
    g.computeVertexNormals();
    const ref = g.getAttribute('normal').array as Float32Array;
    let worst = 0;
    for (let i = 0; i < ref.length; i++) worst = Math.max(worst, Math.abs(ref[i] - out[i]));
    expect(worst).toBeLessThan(1e-5);
  });
});
