/**
 * Read a user's own face mesh (OBJ, or PLY in ascii / binary little-endian)
 * plus a masks file of named vertex regions, into a FaceTemplate. A FLAME
 * head from VOCASET (5023 vertices) goes through here unchanged.
 *
 * Masks file: JSON `{ "units": "mm", "regions": { "lips_inner_upper": [..], ... } }`
 * with the names in REQUIRED_REGIONS (docs/templates.md).
 */
import { REQUIRED_REGIONS, TemplateFormatError, templateFromMesh, type FaceTemplate } from './face-template';

export interface RawMesh {
  positions: Float32Array;
  triangles: Uint32Array;
  uvs: Float32Array | null;
}

export function parseObj(text: string): RawMesh {
  const pos: number[] = [];
  const tex: number[] = [];
  const tris: number[] = [];
  // OBJ keeps UVs per face corner; a template needs one UV per vertex, taken from the first corner that names it.
  const uvOfVertex = new Map<number, number>();
  const lines = text.split(/\r?\n/);
  lines.forEach((line, lineNo) => {
    const parts = line.trim().split(/\s+/);
    if (parts[0] === 'v') pos.push(+parts[1], +parts[2], +parts[3]);
    else if (parts[0] === 'vt') tex.push(+parts[1], +parts[2]);
    else if (parts[0] === 'f') {
      const corners = parts.slice(1).map((c) => {
        const [vi, ti] = c.split('/');
        const v = resolveIndex(+vi, pos.length / 3, lineNo);
        if (ti) {
          const t = resolveIndex(+ti, tex.length / 2, lineNo);
          if (!uvOfVertex.has(v)) uvOfVertex.set(v, t);
        }
        return v;
      });
      if (corners.length < 3) throw new TemplateFormatError(`OBJ line ${lineNo + 1}: a face needs at least 3 vertices`);
      for (let k = 1; k + 1 < corners.length; k++) tris.push(corners[0], corners[k], corners[k + 1]);
    }
  });
  const positions = Float32Array.from(pos);
  if (positions.length === 0 || tris.length === 0) throw new TemplateFormatError('OBJ file has no vertices or no faces');
  for (const x of positions) if (!Number.isFinite(x)) throw new TemplateFormatError('OBJ file has a vertex coordinate that is not a number');
  let uvs: Float32Array | null = null;
  if (uvOfVertex.size === positions.length / 3) {
    uvs = new Float32Array((positions.length / 3) * 2);
    for (const [v, t] of uvOfVertex) uvs.set([tex[2 * t], tex[2 * t + 1]], 2 * v);
  }
  return { positions, triangles: Uint32Array.from(tris), uvs };
}

function resolveIndex(i: number, count: number, lineNo: number): number {
  const idx = i < 0 ? count + i : i - 1;
  if (!Number.isInteger(idx) || idx < 0 || idx >= count) {
    throw new TemplateFormatError(`OBJ line ${lineNo + 1}: index ${i} refers to no vertex`);
  }
  return idx;
}

const PLY_TYPES: Record<string, { size: number; read: (d: DataView, o: number) => number }> = {
  char: { size: 1, read: (d, o) => d.getInt8(o) },
  int8: { size: 1, read: (d, o) => d.getInt8(o) },
  uchar: { size: 1, read: (d, o) => d.getUint8(o) },
  uint8: { size: 1, read: (d, o) => d.getUint8(o) },
  short: { size: 2, read: (d, o) => d.getInt16(o, true) },
  int16: { size: 2, read: (d, o) => d.getInt16(o, true) },
  ushort: { size: 2, read: (d, o) => d.getUint16(o, true) },
  uint16: { size: 2, read: (d, o) => d.getUint16(o, true) },
  int: { size: 4, read: (d, o) => d.getInt32(o, true) },
  int32: { size: 4, read: (d, o) => d.getInt32(o, true) },
  uint: { size: 4, read: (d, o) => d.getUint32(o, true) },
  uint32: { size: 4, read: (d, o) => d.getUint32(o, true) },
  float: { size: 4, read: (d, o) => d.getFloat32(o, true) },
  float32: { size: 4, read: (d, o) => d.getFloat32(o, true) },
  double: { size: 8, read: (d, o) => d.getFloat64(o, true) },
  float64: { size: 8, read: (d, o) => d.getFloat64(o, true) },
};

interface PlyProperty {
  name: string;
  type: string;
  countType?: string;
}
interface PlyElement {
  name: string;
  count: number;
  props: PlyProperty[];
}

export function parsePly(data: ArrayBuffer): RawMesh {
  const bytes = new Uint8Array(data);
  const headerEnd = findHeaderEnd(bytes);
  const headerLines = new TextDecoder().decode(bytes.subarray(0, headerEnd)).split(/\r?\n/);
  if (headerLines[0] !== 'ply') throw new TemplateFormatError('not a PLY file (first line is not "ply")');
  let format = '';
  const elements: PlyElement[] = [];
  for (const line of headerLines.slice(1)) {
    const p = line.trim().split(/\s+/);
    if (p[0] === 'format') format = p[1];
    else if (p[0] === 'element') elements.push({ name: p[1], count: Number(p[2]), props: [] });
    else if (p[0] === 'property') {
      const el = elements[elements.length - 1];
      if (!el) throw new TemplateFormatError('PLY header: property before any element');
      el.props.push(p[1] === 'list' ? { name: p[4], type: p[3], countType: p[2] } : { name: p[2], type: p[1] });
    }
  }
  if (format !== 'ascii' && format !== 'binary_little_endian') {
    throw new TemplateFormatError(`PLY format "${format}" is not supported (use ascii or binary_little_endian)`);
  }
  const rows = readPlyRows(format === 'ascii' ? asciiReader(bytes.subarray(headerEnd)) : binaryReader(data, headerEnd), elements);
  const vertex = rows.get('vertex');
  const face = rows.get('face');
  if (!vertex || !face) throw new TemplateFormatError('PLY file needs "vertex" and "face" elements');
  const positions = new Float32Array(vertex.length * 3);
  const hasUv = vertex.length > 0 && ('s' in vertex[0] || 'u' in vertex[0]);
  const uvs = hasUv ? new Float32Array(vertex.length * 2) : null;
  vertex.forEach((r, i) => {
    positions.set([r.x as number, r.y as number, r.z as number], 3 * i);
    if (uvs) uvs.set([(r.s ?? r.u) as number, (r.t ?? r.v) as number], 2 * i);
  });
  const tris: number[] = [];
  for (const r of face) {
    const idx = (r.vertex_indices ?? r.vertex_index) as number[] | undefined;
    if (!idx) throw new TemplateFormatError('PLY face element has no vertex_indices list');
    for (let k = 1; k + 1 < idx.length; k++) tris.push(idx[0], idx[k], idx[k + 1]);
  }
  return { positions, triangles: Uint32Array.from(tris), uvs };
}

function findHeaderEnd(bytes: Uint8Array): number {
  const marker = new TextEncoder().encode('end_header');
  outer: for (let i = 0; i + marker.length <= Math.min(bytes.length, 1 << 16); i++) {
    for (let k = 0; k < marker.length; k++) if (bytes[i + k] !== marker[k]) continue outer;
    let end = i + marker.length;
    if (bytes[end] === 0x0d) end++;
    if (bytes[end] === 0x0a) end++;
    return end;
  }
  throw new TemplateFormatError('PLY header has no end_header line');
}

type PlyRow = Record<string, number | number[]>;

/** The next scalar of a PLY body, read as `type` (binary) or as the next number token (ascii). */
type PlyScalarReader = (type: string) => number;

function asciiReader(body: Uint8Array): PlyScalarReader {
  const tokens = new TextDecoder().decode(body).split(/\s+/).filter(Boolean).map(Number);
  let p = 0;
  return () => {
    if (p >= tokens.length) throw new TemplateFormatError('PLY file ends before all elements were read');
    return tokens[p++];
  };
}

function binaryReader(data: ArrayBuffer, start: number): PlyScalarReader {
  const d = new DataView(data);
  let o = start;
  return (type) => {
    const t = PLY_TYPES[type];
    if (!t) throw new TemplateFormatError(`PLY property type "${type}" is not supported`);
    if (o + t.size > d.byteLength) throw new TemplateFormatError('PLY file ends before all elements were read');
    const v = t.read(d, o);
    o += t.size;
    return v;
  };
}

/** Every element's rows, each property (scalar or list) read in header order by `read`. */
function readPlyRows(read: PlyScalarReader, elements: PlyElement[]): Map<string, PlyRow[]> {
  const out = new Map<string, PlyRow[]>();
  for (const el of elements) {
    const rows: PlyRow[] = [];
    for (let i = 0; i < el.count; i++) {
      const row: PlyRow = {};
      for (const prop of el.props) {
        if (prop.countType) {
          const n = read(prop.countType);
          const list: number[] = [];
          for (let k = 0; k < n; k++) list.push(read(prop.type));
          row[prop.name] = list;
        } else row[prop.name] = read(prop.type);
      }
      rows.push(row);
    }
    out.set(el.name, rows);
  }
  return out;
}

export interface MasksFile {
  units?: FaceTemplate['units'];
  regions: Record<string, number[]>;
}

/** A user's mesh file (by name, to pick the parser) plus its masks file -> template. */
export function templateFromUserMesh(id: string, fileName: string, contents: ArrayBuffer, masks: MasksFile): FaceTemplate {
  const lower = fileName.toLowerCase();
  let mesh: RawMesh;
  if (lower.endsWith('.obj')) mesh = parseObj(new TextDecoder().decode(contents));
  else if (lower.endsWith('.ply')) mesh = parsePly(contents);
  else throw new TemplateFormatError(`${fileName}: a template mesh must be .obj or .ply`);
  const missing = REQUIRED_REGIONS.filter((r) => !masks.regions?.[r]?.length);
  if (missing.length) throw new TemplateFormatError(`masks for ${fileName} lack the regions ${missing.join(', ')} (see docs/templates.md)`);
  return templateFromMesh(id, masks.units ?? 'mm', mesh.positions, mesh.triangles, mesh.uvs, masks.regions, { file: fileName });
}
