/**
 * The face template: a neutral mesh I (N x 3, Eq. 2 of the paper) with its
 * triangles, UVs, 1-ring adjacency and named vertex regions.
 *
 * On disk a template is two files that TypeScript and Python both read:
 *   template.json  header: ids, units, axes, region index lists, and where each
 *                  array sits inside the binary file;
 *   template.bin   little-endian arrays (float32 positions and UVs, uint32
 *                  triangles and the CSR adjacency).
 * Nothing here assumes a vertex count: a FLAME head (5023 vertices) converted
 * with `scripts/import-template.ts` loads through the same code.
 */
import { boundaryLoops, buildAdjacency, type Adjacency } from './mesh-topology';
import { checkedStallSeconds, fetchBody } from '../model/fetch-body';

export const TEMPLATE_FORMAT = 'talking-face-template';

/** Millimetres per template unit (the model works in mm). */
export const MM_PER_UNIT: Record<'cm' | 'mm' | 'm', number> = { mm: 1, cm: 10, m: 1000 };
export const TEMPLATE_FORMAT_VERSION = 1;

/** Region names every template must provide (the rig, the metrics and the viewer use them). */
export const REQUIRED_REGIONS = [
  'lips_inner_upper',
  'lips_inner_lower',
  'lips_outer',
  'eye_left_upper',
  'eye_left_lower',
  'eye_right_upper',
  'eye_right_lower',
  'brows',
  'upper_face',
  'face_boundary',
  'jaw',
] as const;
export type RegionName = (typeof REQUIRED_REGIONS)[number];
export type Regions = Record<RegionName, Uint32Array> & Record<string, Uint32Array>;

export interface FaceTemplate {
  id: string;
  /** Length unit of `positions` (the MediaPipe face is in centimetres). */
  units: 'cm' | 'mm' | 'm';
  vertexCount: number;
  /** (N, 3) xyz, Y up, +Z toward the viewer, face centred near the origin. */
  positions: Float32Array;
  /** (N, 2) texture coordinates, or null when the source has none. */
  uvs: Float32Array | null;
  /** (T, 3) vertex indices, counter-clockwise seen from the front. */
  triangles: Uint32Array;
  /** 1-ring neighbours (no self loops) in CSR form. */
  adjacency: Adjacency;
  regions: Regions;
  /** Free-form provenance (source package, licence). */
  source: Record<string, string>;
}

type Dtype = 'float32' | 'uint32';
interface BufferView {
  dtype: Dtype;
  byteOffset: number;
  shape: number[];
}

export interface TemplateHeader {
  format: typeof TEMPLATE_FORMAT;
  version: number;
  id: string;
  units: FaceTemplate['units'];
  axes: { up: '+y'; front: '+z'; right: '+x' };
  vertexCount: number;
  triangleCount: number;
  binary: string;
  binarySha256: string;
  buffers: Record<'positions' | 'triangles' | 'adjacencyOffsets' | 'adjacencyIndices', BufferView> & {
    uvs?: BufferView;
  };
  regions: Record<string, number[]>;
  source: Record<string, string>;
}

export class TemplateFormatError extends Error {
  override name = 'TemplateFormatError';
}

/** Serialise a template to the header + binary pair (the binary's hash goes in the header). */
export async function encodeTemplate(
  t: FaceTemplate,
  binaryName: string,
): Promise<{ header: TemplateHeader; binary: Uint8Array }> {
  const parts: { name: string; data: Float32Array | Uint32Array; shape: number[] }[] = [
    { name: 'positions', data: t.positions, shape: [t.vertexCount, 3] },
    { name: 'triangles', data: t.triangles, shape: [t.triangles.length / 3, 3] },
    { name: 'adjacencyOffsets', data: t.adjacency.offsets, shape: [t.vertexCount + 1] },
    { name: 'adjacencyIndices', data: t.adjacency.indices, shape: [t.adjacency.indices.length] },
  ];
  if (t.uvs) parts.push({ name: 'uvs', data: t.uvs, shape: [t.vertexCount, 2] });

  const total = parts.reduce((s, p) => s + p.data.byteLength, 0);
  const binary = new Uint8Array(total);
  const buffers: Record<string, BufferView> = {};
  let offset = 0;
  for (const p of parts) {
    binary.set(new Uint8Array(p.data.buffer, p.data.byteOffset, p.data.byteLength), offset);
    buffers[p.name] = {
      dtype: p.data instanceof Float32Array ? 'float32' : 'uint32',
      byteOffset: offset,
      shape: p.shape,
    };
    offset += p.data.byteLength;
  }
  const regions: Record<string, number[]> = {};
  for (const [name, idx] of Object.entries(t.regions)) regions[name] = Array.from(idx);

  const header: TemplateHeader = {
    format: TEMPLATE_FORMAT,
    version: TEMPLATE_FORMAT_VERSION,
    id: t.id,
    units: t.units,
    axes: { up: '+y', front: '+z', right: '+x' },
    vertexCount: t.vertexCount,
    triangleCount: t.triangles.length / 3,
    binary: binaryName,
    binarySha256: await sha256Hex(binary),
    buffers: buffers as TemplateHeader['buffers'],
    regions,
    source: t.source,
  };
  return { header, binary };
}

/** Parse a header + binary pair, checking every count and index so a broken file fails here, not in a shader. */
export async function decodeTemplate(header: unknown, binary: ArrayBuffer): Promise<FaceTemplate> {
  const h = header as TemplateHeader;
  if (!h || h.format !== TEMPLATE_FORMAT) {
    throw new TemplateFormatError(`not a face template: expected "format": "${TEMPLATE_FORMAT}"`);
  }
  if (h.version !== TEMPLATE_FORMAT_VERSION) {
    throw new TemplateFormatError(`template format version ${h.version} is not supported (this build reads ${TEMPLATE_FORMAT_VERSION})`);
  }
  const digest = await sha256Hex(new Uint8Array(binary));
  if (digest !== h.binarySha256) {
    throw new TemplateFormatError(`template binary ${h.binary} is corrupt or does not belong to template "${h.id}" (sha256 mismatch)`);
  }
  const view = <T extends Float32Array | Uint32Array>(name: string, ctor: { new (b: ArrayBuffer, o: number, n: number): T }, required = true): T | null => {
    const b = (h.buffers as Record<string, BufferView | undefined>)[name];
    if (!b) {
      if (required) throw new TemplateFormatError(`template "${h.id}" has no "${name}" buffer`);
      return null;
    }
    const count = b.shape.reduce((a, c) => a * c, 1);
    if (b.byteOffset % 4 !== 0 || b.byteOffset + count * 4 > binary.byteLength) {
      throw new TemplateFormatError(`template buffer "${name}" lies outside ${h.binary}`);
    }
    return new ctor(binary.slice(b.byteOffset, b.byteOffset + count * 4), 0, count);
  };
  const positions = view('positions', Float32Array)!;
  const triangles = view('triangles', Uint32Array)!;
  const offsets = view('adjacencyOffsets', Uint32Array)!;
  const indices = view('adjacencyIndices', Uint32Array)!;
  const uvs = view('uvs', Float32Array, false);
  const n = h.vertexCount;
  if (positions.length !== n * 3 || offsets.length !== n + 1 || offsets[n] !== indices.length) {
    throw new TemplateFormatError(`template "${h.id}": buffer sizes do not match vertexCount ${n}`);
  }
  checkIndices(triangles, n, 'triangles');
  checkMesh(`template "${h.id}"`, h.units, positions, triangles);
  checkIndices(indices, n, 'adjacencyIndices');
  checkAdjacency(`template "${h.id}"`, offsets, indices);
  const regions = {} as Regions;
  for (const [name, list] of Object.entries(h.regions)) {
    const idx = Uint32Array.from(list);
    checkIndices(idx, n, `region ${name}`);
    regions[name] = idx;
  }
  const missing = REQUIRED_REGIONS.filter((r) => !regions[r] || regions[r].length === 0);
  if (missing.length) {
    throw new TemplateFormatError(`template "${h.id}" lacks the regions ${missing.join(', ')} (see docs/templates.md)`);
  }
  return {
    id: h.id,
    units: h.units,
    vertexCount: n,
    positions,
    uvs,
    triangles,
    adjacency: { offsets, indices },
    regions,
    source: h.source ?? {},
  };
}

/**
 * Fetch a template by the URL of its header; the binary is resolved next to it. A download that brings nothing for
 * `stallSeconds` (default STALL_SECONDS) fails, naming it.
 */
export async function loadTemplate(headerUrl: string | URL, fetchFn: typeof fetch = fetch, stallSeconds?: number): Promise<FaceTemplate> {
  if (stallSeconds !== undefined) checkedStallSeconds(stallSeconds); // (a RangeError as it is, not as a failed download)
  const get = async (url: string | URL, what: string) => {
    const body = await fetchBody(url, { fetch: fetchFn, stallSeconds }).catch((e: Error) => {
      throw new TemplateFormatError(`could not fetch the face template's ${url}: ${e.message}`);
    });
    if (!body.ok) throw new TemplateFormatError(`could not load ${what} ${url}: HTTP ${body.status}`);
    return body.bytes;
  };
  let header: TemplateHeader;
  const text = new TextDecoder().decode(await get(headerUrl, 'the face template'));
  try {
    header = JSON.parse(text);
  } catch (e) {
    throw new TemplateFormatError(`face template ${headerUrl} is not valid JSON: ${(e as Error).message}`);
  }
  const binUrl = new URL(header.binary, new URL(String(headerUrl), globalThis.location?.href ?? 'file:///'));
  return decodeTemplate(header, await get(binUrl, 'the template binary'));
}

/** Build a template from a bare mesh plus region index lists (a user's OBJ/PLY and masks file). */
export function templateFromMesh(
  id: string,
  units: FaceTemplate['units'],
  positions: Float32Array,
  triangles: Uint32Array,
  uvs: Float32Array | null,
  regions: Record<string, ArrayLike<number>>,
  source: Record<string, string> = {},
): FaceTemplate {
  const n = positions.length / 3;
  checkIndices(triangles, n, 'triangles');
  checkMesh(source.file ?? `template "${id}"`, units, positions, triangles);
  const r = {} as Regions;
  for (const [name, list] of Object.entries(regions)) {
    const idx = Uint32Array.from(list);
    checkIndices(idx, n, `region ${name}`);
    r[name] = idx;
  }
  return { id, units, vertexCount: n, positions, uvs, triangles, adjacency: buildAdjacency(n, triangles), regions: r, source };
}

/**
 * What the face's renderer needs of a mesh, said before it is drawn (else the head could not be built): known units,
 * finite coordinates, triangles, and edges on the mesh's boundary (the eyes' and mouth's openings, the outline) that
 * form loops: a triangle wound the other way from its neighbours, or two openings meeting at one vertex, do not.
 */
function checkMesh(what: string, units: unknown, positions: Float32Array, triangles: Uint32Array): void {
  if (!Object.hasOwn(MM_PER_UNIT, units as string)) throw new TemplateFormatError(`${what}: units must be one of ${Object.keys(MM_PER_UNIT).join(', ')}, not ${JSON.stringify(units)}`);
  const bad = positions.findIndex((x) => !Number.isFinite(x));
  if (bad >= 0) throw new TemplateFormatError(`${what}: vertex ${Math.floor(bad / 3)} has a coordinate that is not a number (${positions[bad]})`);
  if (triangles.length === 0 || triangles.length % 3) throw new TemplateFormatError(`${what}: it has ${triangles.length ? 'a broken triangle list' : 'no triangles'}`);
  try {
    boundaryLoops(triangles);
  } catch (e) {
    throw new TemplateFormatError(`${what}: its boundary does not form loops (${(e as Error).message}); a triangle wound the other way from its neighbours, or two openings meeting at one vertex, does this: fix it in a mesh editor`);
  }
}

function checkIndices(a: Uint32Array, n: number, what: string): void {
  for (let i = 0; i < a.length; i++) {
    if (a[i] >= n) throw new TemplateFormatError(`${what}: index ${a[i]} is out of range for ${n} vertices`);
  }
}

/**
 * The 1-rings in CSR form as the attention reads them: offsets from 0, never decreasing (a list read backwards made
 * the three decoders disagree, and the shader loop run for ever), each list ascending without the vertex itself, and
 * symmetric (u in v's ring when v is in u's).
 */
function checkAdjacency(what: string, offsets: Uint32Array, indices: Uint32Array): void {
  const n = offsets.length - 1;
  if (offsets[0] !== 0) throw new TemplateFormatError(`${what}: adjacencyOffsets must start at 0, not ${offsets[0]}`);
  const has = (v: number, u: number): boolean => {
    let lo = offsets[v], hi = offsets[v + 1] - 1;
    while (lo <= hi) {
      const mid = (lo + hi) >> 1;
      if (indices[mid] === u) return true;
      if (indices[mid] < u) lo = mid + 1;
      else hi = mid - 1;
    }
    return false;
  };
  for (let v = 0; v < n; v++) {
    if (offsets[v + 1] < offsets[v]) throw new TemplateFormatError(`${what}: adjacencyOffsets decrease at vertex ${v}`);
    for (let k = offsets[v]; k < offsets[v + 1]; k++) {
      const u = indices[k];
      const why = u === v ? 'lists itself' : k > offsets[v] && u <= indices[k - 1] ? 'is not in ascending order' : !has(u, v) ? `lists ${u}, whose ring lacks ${v}` : '';
      if (why) throw new TemplateFormatError(`${what}: the 1-ring of vertex ${v} ${why} (adjacencyIndices: symmetric, no self loops, ascending)`);
    }
  }
}

async function sha256Hex(bytes: Uint8Array): Promise<string> {
  const digest = await crypto.subtle.digest('SHA-256', bytes as Uint8Array<ArrayBuffer>);
  return Array.from(new Uint8Array(digest), (b) => b.toString(16).padStart(2, '0')).join('');
}

/**
 * The lip surface as a per-vertex mask: flood the 1-ring graph from the inner-lip contours out to the
 * outer-lip contour (the same region as training's metrics.lip_region, used for E_vl).
 */
export function lipMask(t: FaceTemplate): Uint8Array {
  const mask = new Uint8Array(t.vertexCount);
  const outer = new Set(t.regions.lips_outer);
  const queue = [...t.regions.lips_inner_upper, ...t.regions.lips_inner_lower];
  for (const v of queue) mask[v] = 1;
  while (queue.length) {
    const v = queue.pop()!;
    if (outer.has(v)) continue;
    for (let k = t.adjacency.offsets[v]; k < t.adjacency.offsets[v + 1]; k++) {
      const w = t.adjacency.indices[k];
      if (!mask[w]) {
        mask[w] = 1;
        queue.push(w);
      }
    }
  }
  return mask;
}
