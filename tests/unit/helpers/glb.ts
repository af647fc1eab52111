/**
 * glTF binary files read and written in tests: the project's test avatars taken apart and put back, e.g. with every
 * buffer view meshopt-compressed (what gltfpack and gltf-transform's optimize write), with meshoptimizer's own encoder.
 */
import { readFileSync } from 'node:fs';
import { MeshoptEncoder } from 'meshoptimizer';

export interface Json {
  extensionsUsed?: string[];
  extensionsRequired?: string[];
  buffers: { byteLength: number; extensions?: object }[];
  bufferViews: { buffer: number; byteOffset?: number; byteLength: number; byteStride?: number; extensions?: object }[];
  accessors: { bufferView?: number; componentType: number }[];
}

export function readGlb(path: string): { json: Json; bin: Uint8Array } {
  const b = readFileSync(path);
  const jsonLength = b.readUInt32LE(12);
  const json = JSON.parse(b.subarray(20, 20 + jsonLength).toString()) as Json;
  const binAt = 20 + jsonLength;
  return { json, bin: new Uint8Array(b.subarray(binAt + 8, binAt + 8 + b.readUInt32LE(binAt))) };
}

export function writeGlb(json: object, bin: Uint8Array): ArrayBuffer {
  const pad = (n: number) => (n + 3) & ~3;
  const text = new TextEncoder().encode(JSON.stringify(json));
  const jsonBytes = new Uint8Array(pad(text.length)).fill(0x20);
  jsonBytes.set(text);
  const binBytes = new Uint8Array(pad(bin.length));
  binBytes.set(bin);
  const out = new Uint8Array(12 + 8 + jsonBytes.length + 8 + binBytes.length);
  const v = new DataView(out.buffer);
  v.setUint32(0, 0x46546c67, true); // glTF
  v.setUint32(4, 2, true);
  v.setUint32(8, out.length, true);
  v.setUint32(12, jsonBytes.length, true);
  v.setUint32(16, 0x4e4f534a, true); // JSON
  out.set(jsonBytes, 20);
  v.setUint32(20 + jsonBytes.length, binBytes.length, true);
  v.setUint32(24 + jsonBytes.length, 0x004e4942, true); // BIN
  out.set(binBytes, 28 + jsonBytes.length);
  return out.buffer;
}

/** The avatar with every buffer view meshopt-compressed (EXT_meshopt_compression), its data only in compressed form. */
export async function meshopt(path: string): Promise<ArrayBuffer> {
  await MeshoptEncoder.ready;
  const { json, bin } = readGlb(path);
  const indexViews = new Set(json.accessors.filter((_, i) => isIndex(json, i)).map((a) => a.bufferView));
  const chunks: Uint8Array[] = [];
  let at = 0;
  json.bufferViews = json.bufferViews.map((view, i) => {
    const data = bin.subarray(view.byteOffset ?? 0, (view.byteOffset ?? 0) + view.byteLength);
    const stride = indexViews.has(i) ? (json.accessors.find((a) => a.bufferView === i)!.componentType === 5125 ? 4 : 2) : view.byteStride ?? 4;
    const count = view.byteLength / stride;
    const mode = indexViews.has(i) ? 'INDICES' : 'ATTRIBUTES';
    const encoded = mode === 'INDICES' ? MeshoptEncoder.encodeIndexSequence(data, count, stride) : MeshoptEncoder.encodeVertexBuffer(data, count, stride);
    const extension = { buffer: 0, byteOffset: at, byteLength: encoded.length, byteStride: stride, count, mode };
    chunks.push(encoded);
    at += (encoded.length + 3) & ~3;
    return { ...view, buffer: 1, extensions: { EXT_meshopt_compression: extension } };
  });
  const packed = new Uint8Array(at);
  let o = 0;
  for (const c of chunks) { packed.set(c, o); o += (c.length + 3) & ~3; }
  json.buffers = [{ byteLength: packed.length }, { byteLength: json.buffers[0].byteLength, extensions: { EXT_meshopt_compression: { fallback: true } } }];
  json.extensionsUsed = [...(json.extensionsUsed ?? []), 'EXT_meshopt_compression'];
  json.extensionsRequired = [...(json.extensionsRequired ?? []), 'EXT_meshopt_compression'];
  return writeGlb(json, packed);
}

function isIndex(json: Json & { meshes?: { primitives: { indices?: number }[] }[] }, accessor: number): boolean {
  return (json.meshes ?? []).some((m) => m.primitives.some((p) => p.indices === accessor));
}
