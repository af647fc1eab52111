import { describe, expect, it } from 'vitest';
import { parseObj, parsePly, templateFromUserMesh, type MasksFile } from '../../../src/template/mesh-import';
import { REQUIRED_REGIONS } from '../../../src/template/face-template';

/** A 3x3 vertex grid, 8 triangles: small enough to check by hand, big enough to have interior vertices. */
function grid(): { positions: number[]; triangles: number[] } {
  const positions: number[] = [];
  for (let j = 0; j < 3; j++) for (let i = 0; i < 3; i++) positions.push(i, j, 0.5 * i * j);
  const triangles: number[] = [];
  for (let j = 0; j < 2; j++)
    for (let i = 0; i < 2; i++) {
      const a = j * 3 + i;
      triangles.push(a, a + 1, a + 4, a, a + 4, a + 3);
    }
  return { positions, triangles };
}

const masks: MasksFile = {
  units: 'mm',
  regions: Object.fromEntries(REQUIRED_REGIONS.map((r, k) => [r, [k % 9]])),
};
const enc = (s: string) => new TextEncoder().encode(s).buffer as ArrayBuffer;

describe('OBJ import', () => {
  it('reads vertices, quads and per-corner UVs', () => {
    const text = ['v 0 0 0', 'v 1 0 0', 'v 1 1 0', 'v 0 1 0', 'vt 0 0', 'vt 1 0', 'vt 1 1', 'vt 0 1', 'f 1/1 2/2 3/3 4/4'].join('\n');
    const m = parseObj(text);
    expect(m.positions.length).toBe(12);
    expect(Array.from(m.triangles)).toEqual([0, 1, 2, 0, 2, 3]);
    expect(Array.from(m.uvs!)).toEqual([0, 0, 1, 0, 1, 1, 0, 1]);
  });

  it('builds a template whose adjacency follows the faces', () => {
    const g = grid();
    const obj = [...Array.from({ length: 9 }, (_, v) => `v ${g.positions.slice(3 * v, 3 * v + 3).join(' ')}`)];
    for (let t = 0; t < g.triangles.length; t += 3) obj.push(`f ${g.triangles.slice(t, t + 3).map((v) => v + 1).join(' ')}`);
    const tpl = templateFromUserMesh('grid', 'grid.obj', enc(obj.join('\n')), masks);
    expect(tpl.vertexCount).toBe(9);
    expect(tpl.units).toBe('mm');
    // The centre vertex 4 touches all 8 others except the two corners its diagonals skip (2 and 6).
    const c = tpl.adjacency;
    expect(Array.from(c.indices.subarray(c.offsets[4], c.offsets[5]))).toEqual([0, 1, 3, 5, 7, 8]);
  });

  it('rejects a face that points at no vertex', () => {
    expect(() => parseObj('v 0 0 0\nv 1 0 0\nf 1 2 3')).toThrow(/refers to no vertex/);
  });
});

describe('PLY import', () => {
  it('reads ascii and binary little-endian to the same mesh', () => {
    const g = grid();
    const header = (format: string) =>
      `ply\nformat ${format} 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\nelement face 8\nproperty list uchar int vertex_indices\nend_header\n`;
    let ascii = header('ascii');
    for (let v = 0; v < 9; v++) ascii += g.positions.slice(3 * v, 3 * v + 3).join(' ') + '\n';
    for (let t = 0; t < 8; t++) ascii += `3 ${g.triangles.slice(3 * t, 3 * t + 3).join(' ')}\n`;

    const head = new TextEncoder().encode(header('binary_little_endian'));
    const body = new DataView(new ArrayBuffer(9 * 12 + 8 * 13));
    let o = 0;
    for (const x of g.positions) (body.setFloat32(o, x, true), (o += 4));
    for (let t = 0; t < 8; t++) {
      body.setUint8(o++, 3);
      for (let k = 0; k < 3; k++) (body.setInt32(o, g.triangles[3 * t + k], true), (o += 4));
    }
    const bin = new Uint8Array(head.length + body.byteLength);
    bin.set(head);
    bin.set(new Uint8Array(body.buffer), head.length);

    const a = parsePly(enc(ascii));
    const b = parsePly(bin.buffer);
    expect(Array.from(a.positions)).toEqual(g.positions);
    expect(Array.from(b.positions)).toEqual(g.positions);
    expect(Array.from(a.triangles)).toEqual(g.triangles);
    expect(Array.from(b.triangles)).toEqual(g.triangles);
  });

  it('rejects big-endian PLY and missing masks with an actionable message', () => {
    expect(() => parsePly(enc('ply\nformat binary_big_endian 1.0\nend_header\n'))).toThrow(/not supported/);
    expect(() => templateFromUserMesh('x', 'x.obj', enc('v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3'), { regions: {} })).toThrow(/lack the regions/);
    expect(() => templateFromUserMesh('x', 'x.stl', enc(''), masks)).toThrow(/must be .obj or .ply/);
  });
});

describe('a mesh the face cannot be drawn from is refused at import, naming the file', () => {
  const plyOf = (positions: string[], faces: number[][]) => enc(
    `ply\nformat ascii 1.0\nelement vertex ${positions.length}\nproperty float x\nproperty float y\nproperty float z\n` +
    `element face ${faces.length}\nproperty list uchar int vertex_indices\nend_header\n${positions.join('\n')}\n${faces.map((f) => `${f.length} ${f.join(' ')}`).join('\n')}\n`);
  const g = grid();
  const vertices = Array.from({ length: 9 }, (_, v) => g.positions.slice(3 * v, 3 * v + 3).join(' '));
  const faces = Array.from({ length: 8 }, (_, t) => g.triangles.slice(3 * t, 3 * t + 3));

  it('a coordinate that is not a number, no faces, or units it does not know', () => {
    expect(() => templateFromUserMesh('g', 'nan.ply', plyOf(['nan 0 0', ...vertices.slice(1)], faces), masks)).toThrow(/nan\.ply: vertex 0 has a coordinate that is not a number \(NaN\)/);
    expect(() => templateFromUserMesh('g', 'empty.ply', plyOf(vertices, []), masks)).toThrow(/empty\.ply: it has no triangles/);
    expect(() => templateFromUserMesh('g', 'g.ply', plyOf(vertices, faces), { ...masks, units: 'MM' as 'mm' })).toThrow(/g\.ply: units must be one of mm, cm, m, not "MM"/);
  });

  it('a triangle wound the other way from its neighbours (its boundary forms no loops)', () => {
    const flipped = faces.map((f, t) => (t === 0 ? [f[0], f[2], f[1]] : f));
    expect(() => templateFromUserMesh('g', 'flipped.ply', plyOf(vertices, flipped), masks)).toThrow(/flipped\.ply: its boundary does not form loops .* fix it in a mesh editor/);
    expect(templateFromUserMesh('g', 'g.ply', plyOf(vertices, faces), masks).vertexCount).toBe(9); // as it was: taken
  });
});
