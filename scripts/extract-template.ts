/**
 * Extract the MediaPipe canonical face (468 vertices, Apache-2.0) from the npm
 * package @mediapipe/face_mesh and write models/template/.
 *
 *   npx tsx scripts/extract-template.ts [--out models/template]
 *
 * The canonical mesh sits in face_mesh_solution_packed_assets.data as the
 * protobuf GeometryPipelineMetadata (field 1: canonical_mesh = Mesh3d with
 * vertex_buffer = 5 floats per vertex x y z u v, index_buffer = triangles).
 * The mesh closes the mouth and eyes with triangles; dropping every triangle
 * whose three vertices lie on the inner-lip contour or one eye contour opens
 * them so the lips can part.
 */
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';
import { encodeTemplate, templateFromMesh, type TemplateHeader } from '../src/template/face-template';
import { edgeCycles } from '../src/template/mesh-topology';
import { regionsFromContours } from '../src/template/regions';
import { formatJson } from './format-json';

const require = createRequire(import.meta.url);
const PACKAGE = '@mediapipe/face_mesh';
const ENTRY = 'geometry_pipeline_metadata_landmarks.binarypb';

type Connections = [number, number][];
interface FaceMeshModule {
  FACEMESH_LIPS: Connections;
  FACEMESH_LEFT_EYE: Connections;
  FACEMESH_RIGHT_EYE: Connections;
  FACEMESH_LEFT_EYEBROW: Connections;
  FACEMESH_RIGHT_EYEBROW: Connections;
  FACEMESH_FACE_OVAL: Connections;
}

export async function extractMediapipeTemplate(): Promise<{ header: TemplateHeader; binary: Uint8Array; notice: string }> {
  const pkgJson = require.resolve(`${PACKAGE}/package.json`);
  const pkgDir = dirname(pkgJson);
  const version: string = JSON.parse(readFileSync(pkgJson, 'utf8')).version;
  const mesh = readCanonicalMesh(pkgDir);
  const fm = require(join(pkgDir, 'face_mesh.js')) as FaceMeshModule;

  // The lip connections are two closed loops; the inner one encloses the smaller area.
  const lipLoops = edgeCycles(fm.FACEMESH_LIPS);
  if (lipLoops.length !== 2) throw new Error(`expected 2 lip contours in FACEMESH_LIPS, found ${lipLoops.length}`);
  const spanX = (loop: number[]) => Math.max(...loop.map((v) => mesh.positions[3 * v])) - Math.min(...loop.map((v) => mesh.positions[3 * v]));
  const [innerLips, outerLips] = spanX(lipLoops[0]) < spanX(lipLoops[1]) ? lipLoops : [lipLoops[1], lipLoops[0]];
  const leftEye = edgeCycles(fm.FACEMESH_LEFT_EYE)[0];
  const rightEye = edgeCycles(fm.FACEMESH_RIGHT_EYE)[0];
  const vertsOf = (c: Connections) => [...new Set(c.flat())];

  const closedSets = [innerLips, leftEye, rightEye].map((l) => new Set(l));
  const kept: number[] = [];
  for (let t = 0; t < mesh.triangles.length; t += 3) {
    const tri = [mesh.triangles[t], mesh.triangles[t + 1], mesh.triangles[t + 2]];
    if (closedSets.some((s) => tri.every((v) => s.has(v)))) continue;
    kept.push(...tri);
  }
  const regions = regionsFromContours(
    {
      innerLips,
      outerLips,
      leftEye,
      rightEye,
      brows: [...vertsOf(fm.FACEMESH_LEFT_EYEBROW), ...vertsOf(fm.FACEMESH_RIGHT_EYEBROW)],
      oval: vertsOf(fm.FACEMESH_FACE_OVAL),
    },
    mesh.positions,
  );
  const template = templateFromMesh(
    'mediapipe-canonical-468',
    'cm',
    mesh.positions,
    Uint32Array.from(kept),
    mesh.uvs,
    regions,
    {
      name: 'MediaPipe canonical face model',
      package: `${PACKAGE}@${version}`,
      file: `face_mesh_solution_packed_assets.data: ${ENTRY}`,
      license: 'Apache-2.0',
      regionsFrom: 'FACEMESH_LIPS, FACEMESH_LEFT_EYE, FACEMESH_RIGHT_EYE, FACEMESH_*_EYEBROW, FACEMESH_FACE_OVAL (face_mesh.js)',
      modification: `opened the mouth and eyes: dropped ${mesh.triangles.length / 3 - kept.length / 3} triangles whose vertices all lie on the inner-lip or an eye contour`,
    },
  );
  const { header, binary } = await encodeTemplate(template, 'template.bin');
  const notice = [
    'models/template/ holds a modified copy of the MediaPipe canonical face model.',
    '',
    `Source: npm package ${PACKAGE}@${version}, ${ENTRY}`,
    'inside face_mesh_solution_packed_assets.data, and the FACEMESH_* contour',
    'constants from face_mesh.js of the same package.',
    'Copyright 2020-2022 The MediaPipe Authors. Licensed under the Apache License,',
    'Version 2.0 (http://www.apache.org/licenses/LICENSE-2.0).',
    '',
    `Changes: ${template.source.modification}; added the 1-ring adjacency and`,
    'named vertex regions. Regenerate with: npx tsx scripts/extract-template.ts',
    '',
  ].join('\n');
  return { header, binary, notice };
}

/** Locate the packed asset via the loader's file table (offsets are never hard-coded) and decode the protobuf. */
function readCanonicalMesh(pkgDir: string): { positions: Float32Array; uvs: Float32Array; triangles: Uint32Array } {
  const loader = readFileSync(join(pkgDir, 'face_mesh_solution_packed_assets_loader.js'), 'utf8');
  const m = new RegExp(`"filename":\\s*"[^"]*${ENTRY}",\\s*"start":\\s*(\\d+),\\s*"end":\\s*(\\d+)`).exec(loader);
  if (!m) throw new Error(`${PACKAGE}: ${ENTRY} is not listed in face_mesh_solution_packed_assets_loader.js`);
  const data = readFileSync(join(pkgDir, 'face_mesh_solution_packed_assets.data'));
  const pb = new Uint8Array(data.buffer, data.byteOffset + Number(m[1]), Number(m[2]) - Number(m[1]));

  const meta = readFields(pb);
  const meshBytes = meta.get(1)?.[0];
  if (!(meshBytes instanceof Uint8Array)) throw new Error(`${ENTRY}: no canonical_mesh field`);
  const mesh = readFields(meshBytes);
  const vertexBuffer = collectPacked(mesh.get(3) ?? [], 'float');
  const indexBuffer = collectPacked(mesh.get(4) ?? [], 'varint');
  if (vertexBuffer.length % 5 !== 0) throw new Error(`${ENTRY}: vertex_buffer length ${vertexBuffer.length} is not a multiple of 5 (x y z u v)`);
  const n = vertexBuffer.length / 5;
  const positions = new Float32Array(n * 3);
  const uvs = new Float32Array(n * 2);
  for (let v = 0; v < n; v++) {
    positions.set(vertexBuffer.subarray(5 * v, 5 * v + 3), 3 * v);
    uvs.set(vertexBuffer.subarray(5 * v + 3, 5 * v + 5), 2 * v);
  }
  return { positions, uvs, triangles: Uint32Array.from(indexBuffer) };
}

type FieldValue = Uint8Array | number;

/** Minimal protobuf wire-format reader: field number -> values (varints as numbers, length-delimited as bytes, fixed32 as raw bytes). */
function readFields(buf: Uint8Array): Map<number, FieldValue[]> {
  const out = new Map<number, FieldValue[]>();
  let p = 0;
  const varint = () => {
    let result = 0;
    let shift = 0;
    for (;;) {
      const b = buf[p++];
      result += (b & 0x7f) * 2 ** shift;
      if (b < 0x80) return result;
      shift += 7;
    }
  };
  while (p < buf.length) {
    const key = varint();
    const field = Math.floor(key / 8);
    const wire = key & 7;
    let value: FieldValue;
    if (wire === 0) value = varint();
    else if (wire === 2) {
      const len = varint();
      value = buf.subarray(p, p + len);
      p += len;
    } else if (wire === 5) {
      value = buf.subarray(p, p + 4);
      p += 4;
    } else if (wire === 1) {
      value = buf.subarray(p, p + 8);
      p += 8;
    } else throw new Error(`unsupported protobuf wire type ${wire}`);
    (out.get(field) ?? out.set(field, []).get(field)!).push(value);
  }
  return out;
}

/** A repeated scalar field may arrive packed (one length-delimited blob) or unpacked (one value per entry). */
function collectPacked(values: FieldValue[], kind: 'float'): Float32Array;
function collectPacked(values: FieldValue[], kind: 'varint'): number[];
function collectPacked(values: FieldValue[], kind: 'float' | 'varint'): Float32Array | number[] {
  if (kind === 'float') {
    const chunks = values.map((v) => {
      if (typeof v === 'number') throw new Error('float field stored as varint');
      const copy = new Uint8Array(v);
      return new Float32Array(copy.buffer, 0, copy.length / 4);
    });
    const out = new Float32Array(chunks.reduce((s, c) => s + c.length, 0));
    let o = 0;
    for (const c of chunks) {
      out.set(c, o);
      o += c.length;
    }
    return out;
  }
  const out: number[] = [];
  for (const v of values) {
    if (typeof v === 'number') out.push(v);
    else {
      const fields = readFields(prefixVarints(v));
      for (const x of fields.get(1) ?? []) out.push(x as number);
    }
  }
  return out;
}

/** Re-tag a packed varint blob as a sequence of field-1 varints so readFields can decode it. */
function prefixVarints(blob: Uint8Array): Uint8Array {
  const out: number[] = [];
  let start = 0;
  for (let i = 0; i < blob.length; i++) {
    if (blob[i] < 0x80) {
      out.push(0x08, ...blob.subarray(start, i + 1));
      start = i + 1;
    }
  }
  return Uint8Array.from(out);
}

async function main(): Promise<void> {
  const argv = process.argv.slice(2);
  const outIdx = argv.indexOf('--out');
  const outDir = resolve(outIdx >= 0 ? argv[outIdx + 1] : 'models/template');
  const { header, binary, notice } = await extractMediapipeTemplate();
  mkdirSync(outDir, { recursive: true });
  writeFileSync(join(outDir, 'template.json'), formatJson(header));
  writeFileSync(join(outDir, 'template.bin'), binary);
  writeFileSync(join(outDir, 'NOTICE'), notice);
  console.log(`wrote ${outDir}: ${header.vertexCount} vertices, ${header.triangleCount} triangles, ${Object.keys(header.regions).length} regions`);
}

if (process.argv[1] && resolve(process.argv[1]) === resolve(new URL(import.meta.url).pathname)) {
  main().catch((e) => {
    console.error(`extract-template: ${(e as Error).message}`);
    process.exit(1);
  });
}
