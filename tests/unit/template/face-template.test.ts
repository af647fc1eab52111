import { describe, expect, it, beforeAll } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { decodeTemplate, encodeTemplate, REQUIRED_REGIONS, TemplateFormatError, type FaceTemplate, type TemplateHeader } from '../../../src/template/face-template';
import { boundaryLoops, buildAdjacency, edgeCycles, neighbours } from '../../../src/template/mesh-topology';
import { extractMediapipeTemplate } from '../../../scripts/extract-template';
import { formatJson } from '../../../scripts/format-json';

const DIR = resolve(import.meta.dirname, '../../../models/template');
const headerText = readFileSync(resolve(DIR, 'template.json'), 'utf8');
const binaryBytes = readFileSync(resolve(DIR, 'template.bin'));
const asArrayBuffer = (b: Buffer) => b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer;

let t: FaceTemplate;
beforeAll(async () => {
  t = await decodeTemplate(JSON.parse(headerText), asArrayBuffer(binaryBytes));
});

describe('the shipped MediaPipe template', () => {
  it('has 468 vertices and the opened triangle list', () => {
    expect(t.vertexCount).toBe(468);
    expect(t.positions.length).toBe(468 * 3);
    expect(t.triangles.length / 3).toBe(852);
    expect(t.uvs?.length).toBe(468 * 2);
  });

  it('has a symmetric 1-ring adjacency with no self loops, equal to the one the triangles imply', () => {
    const { offsets, indices } = t.adjacency;
    for (let v = 0; v < t.vertexCount; v++) {
      const nb = neighbours(t.adjacency, v);
      expect(nb.length).toBeGreaterThan(0);
      for (const w of nb) {
        expect(w).not.toBe(v);
        expect(Array.from(neighbours(t.adjacency, w))).toContain(v);
      }
    }
    const rebuilt = buildAdjacency(t.vertexCount, t.triangles);
    expect(Array.from(offsets)).toEqual(Array.from(rebuilt.offsets));
    expect(Array.from(indices)).toEqual(Array.from(rebuilt.indices));
  });

  it('is open at the mouth and both eyes: four boundary loops matching the contour regions', () => {
    const loops = boundaryLoops(t.triangles).map((l) => new Set(l));
    expect(loops).toHaveLength(4);
    const sameSet = (a: Set<number>, b: Iterable<number>) => {
      const bs = new Set(b);
      return a.size === bs.size && [...a].every((v) => bs.has(v));
    };
    const r = t.regions;
    const expected = [
      r.face_boundary,
      [...r.lips_inner_upper, ...r.lips_inner_lower],
      [...r.eye_left_upper, ...r.eye_left_lower],
      [...r.eye_right_upper, ...r.eye_right_lower],
    ];
    for (const want of expected) expect(loops.some((l) => sameSet(l, want))).toBe(true);
  });

  it('has every required region non-empty and in range, with upper above lower', () => {
    for (const name of REQUIRED_REGIONS) {
      const idx = t.regions[name];
      expect(idx.length, name).toBeGreaterThan(0);
      for (const v of idx) expect(v).toBeLessThan(t.vertexCount);
    }
    const meanY = (idx: Uint32Array) => Array.from(idx).reduce((s, v) => s + t.positions[3 * v + 1], 0) / idx.length;
    expect(meanY(t.regions.lips_inner_upper)).toBeGreaterThan(meanY(t.regions.lips_inner_lower));
    expect(meanY(t.regions.eye_left_upper)).toBeGreaterThan(meanY(t.regions.eye_left_lower));
    expect(meanY(t.regions.brows)).toBeGreaterThan(meanY(t.regions.eye_left_upper));
    expect(meanY(t.regions.jaw)).toBeLessThan(meanY(t.regions.lips_inner_lower));
    // Subject's left eye is on the +x side (MediaPipe names eyes from the subject's view).
    const meanX = (idx: Uint32Array) => Array.from(idx).reduce((s, v) => s + t.positions[3 * v], 0) / idx.length;
    expect(meanX(t.regions.eye_left_upper)).toBeGreaterThan(0);
    expect(meanX(t.regions.eye_right_upper)).toBeLessThan(0);
  });

  it('is in centimetres, Y up, facing +Z', () => {
    expect(t.units).toBe('cm');
    const ys = Array.from({ length: t.vertexCount }, (_, v) => t.positions[3 * v + 1]);
    const height = Math.max(...ys) - Math.min(...ys);
    expect(height).toBeGreaterThan(12); // a face is 15-20 cm from chin to hairline
    expect(height).toBeLessThan(25);
    const nose = t.regions.nose_tip[0];
    expect(t.positions[3 * nose + 2]).toBeGreaterThan(t.positions[3 * t.regions.face_boundary[0] + 2]);
  });

  it('is exactly what the extraction script writes', async () => {
    const { header, binary } = await extractMediapipeTemplate();
    expect(Buffer.from(binary).equals(binaryBytes)).toBe(true);
    expect(formatJson(header)).toBe(headerText);
  });
});

describe('template decoding rejects broken files with a clear error', () => {
  it('a corrupt binary', async () => {
    const bad = Buffer.from(binaryBytes);
    bad[100] ^= 0xff;
    await expect(decodeTemplate(JSON.parse(headerText), asArrayBuffer(bad))).rejects.toThrow(/corrupt/);
  });

  it('a missing required region', async () => {
    const h = JSON.parse(headerText) as TemplateHeader;
    delete h.regions.jaw;
    await expect(decodeTemplate(h, asArrayBuffer(binaryBytes))).rejects.toThrow(/lacks the regions jaw/);
  });

  it('an unknown format version, and something that is not a template', async () => {
    const h = JSON.parse(headerText) as TemplateHeader;
    h.version = 99;
    await expect(decodeTemplate(h, asArrayBuffer(binaryBytes))).rejects.toThrow(TemplateFormatError);
    await expect(decodeTemplate({ hello: 1 }, asArrayBuffer(binaryBytes))).rejects.toThrow(/not a face template/);
  });

  it('1-rings the attention cannot read: decreasing offsets, a vertex in its own ring, out of order, one-sided', async () => {
    const broken = async (edit: (offsets: Uint32Array, indices: Uint32Array) => void) => {
      const adjacency = { offsets: t.adjacency.offsets.slice(), indices: t.adjacency.indices.slice() };
      edit(adjacency.offsets, adjacency.indices);
      const { header, binary } = await encodeTemplate({ ...t, adjacency }, 'template.bin');
      return decodeTemplate(JSON.parse(JSON.stringify(header)), binary.buffer as ArrayBuffer);
    };
    const o = t.adjacency.offsets, n = t.vertexCount;
    await expect(broken((off) => { off[2] = off[1] - 1; })).rejects.toThrow(/adjacencyOffsets decrease at vertex 1/);
    await expect(broken((_, idx) => { idx[o[0]] = 0; })).rejects.toThrow(/1-ring of vertex 0 lists itself/);
    await expect(broken((_, idx) => { [idx[o[0]], idx[o[0] + 1]] = [idx[o[0] + 1], idx[o[0]]]; })).rejects.toThrow(/vertex 0 is not in ascending order/);
    await expect(broken((_, idx) => { idx[o[1] - 1] = n - 1; })).rejects.toThrow(new RegExp(`vertex 0 lists ${n - 1}, whose ring lacks 0`));
  });

  it('round-trips through encode/decode', async () => {
    const { header, binary } = await encodeTemplate(t, 'template.bin');
    const again = await decodeTemplate(JSON.parse(JSON.stringify(header)), binary.buffer as ArrayBuffer);
    expect(Array.from(again.positions)).toEqual(Array.from(t.positions));
    expect(Array.from(again.regions.jaw)).toEqual(Array.from(t.regions.jaw));
  });
});

describe('edgeCycles', () => {
  it('walks a closed loop round, and an open chain from one end whatever order its edges come in', () => {
    expect(edgeCycles([[0, 1], [1, 2], [2, 0]])).toEqual([[0, 1, 2]]);
    expect(edgeCycles([[2, 3], [1, 2]])).toEqual([[3, 2, 1]]); // (from its middle it came out as [2, 3] and [1])
    expect(edgeCycles([[5, 6], [7, 8], [6, 7]]).map((c) => c.length)).toEqual([4]);
  });
});
