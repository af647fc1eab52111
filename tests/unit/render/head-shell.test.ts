/**
 * The head shell (src/render/head-shell.ts) on the shipped template: it shares the face's oval vertices, closes
 * the head (every edge of face + shell is used twice, except the eyes' and mouth's openings), faces outwards, and
 * a template that is already a whole head gets none.
 */
import { beforeAll, describe, expect, it } from 'vitest';
import { headShell, ovalLoop } from '../../../src/render/head-shell';
import { templateFromMesh, type FaceTemplate } from '../../../src/template/face-template';
import { boundaryLoops } from '../../../src/template/mesh-topology';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

let t: FaceTemplate;
beforeAll(async () => {
  t = await loadTemplateFile(loadManifest());
});

describe('headShell', () => {
  it('starts at the face oval itself and leaves only the eyes and mouth open', () => {
    const shell = headShell(t)!;
    const oval = ovalLoop(t)!;
    expect(new Set(oval)).toEqual(new Set(t.regions.face_boundary));
    // The seam: shell triangles index the oval's own vertices, and no other face vertex.
    const used = new Set([...shell.triangles].filter((v) => v < t.vertexCount));
    expect(used).toEqual(new Set(oval));
    const joined = Uint32Array.from([...t.triangles, ...shell.triangles]);
    const loops = boundaryLoops(joined).map((l) => l.length).sort((a, b) => a - b);
    const inner = new Set([...t.regions.lips_inner_upper, ...t.regions.lips_inner_lower]).size;
    expect(loops).toEqual([t.regions.eye_left_upper.length + t.regions.eye_left_lower.length - 2, t.regions.eye_right_upper.length + t.regions.eye_right_lower.length - 2, inner].sort((a, b) => a - b));
  });

  it('faces outwards, and reaches behind and above the face as a head does', () => {
    const shell = headShell(t)!;
    const n = t.vertexCount;
    const at = (v: number) => (v < n ? t.positions.subarray(3 * v, 3 * v + 3) : shell.positions.subarray(3 * (v - n), 3 * (v - n) + 3));
    let outward = 0;
    const c = shell.egg.center;
    for (let i = 0; i < shell.triangles.length; i += 3) {
      const [a, b, d] = [at(shell.triangles[i]), at(shell.triangles[i + 1]), at(shell.triangles[i + 2])];
      const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
      const nx = u[1] * w[2] - u[2] * w[1], ny = u[2] * w[0] - u[0] * w[2], nz = u[0] * w[1] - u[1] * w[0];
      if (nx * (a[0] - c[0]) + ny * (a[1] - c[1]) + nz * (a[2] - c[2]) > 0) outward++;
    }
    expect(outward / (shell.triangles.length / 3)).toBeGreaterThan(0.98);
    const z = Array.from({ length: shell.positions.length / 3 }, (_, i) => shell.positions[3 * i + 2]);
    const y = Array.from({ length: shell.positions.length / 3 }, (_, i) => shell.positions[3 * i + 1]);
    const faceZ = Array.from({ length: n }, (_, i) => t.positions[3 * i + 2]);
    const H = shell.measures.top - shell.measures.chin;
    // The back of the head 18-22 cm behind the nose tip, the crown 2-6 cm above the face's top (the template is in cm).
    expect(Math.max(...faceZ) - Math.min(...z)).toBeGreaterThan(18);
    expect(Math.max(...faceZ) - Math.min(...z)).toBeLessThan(22);
    expect(Math.max(...y) - shell.measures.top).toBeGreaterThan(0.1 * H);
    expect(Math.max(...y) - shell.measures.top).toBeLessThan(0.35 * H);
  });

  it('a template without an open oval (a whole head) gets no shell', () => {
    // The face with its oval closed by a fan to one extra vertex behind it.
    const oval = ovalLoop(t)!;
    const positions = new Float32Array([...t.positions, 0, 0, -10]);
    const tris = [...t.triangles];
    for (let i = 0; i < oval.length; i++) tris.push(oval[(i + 1) % oval.length], oval[i], t.vertexCount);
    const closed = templateFromMesh('closed', 'cm', positions, Uint32Array.from(tris), null, t.regions);
    expect(headShell(closed)).toBeNull();
  });
});
