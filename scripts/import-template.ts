/**
 * Convert your own face mesh (OBJ or PLY) and its masks file into the
 * template format the app and the training toolkit read.
 *
 *   npx tsx scripts/import-template.ts head.obj head-masks.json --id flame-5023 --out models/templates/flame-5023
 *
 * See docs/templates.md for the masks file and the region names.
 */
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { basename, join, resolve } from 'node:path';
import { encodeTemplate } from '../src/template/face-template';
import { templateFromUserMesh, type MasksFile } from '../src/template/mesh-import';
import { formatJson } from './format-json';

async function main(): Promise<void> {
  const args = process.argv.slice(2);
  const opt = (name: string) => {
    const i = args.indexOf(name);
    if (i < 0) return undefined;
    const v = args[i + 1];
    args.splice(i, 2);
    return v;
  };
  const id = opt('--id');
  const out = opt('--out');
  const [meshPath, masksPath] = args;
  if (!meshPath || !masksPath || !id || !out) {
    throw new Error('usage: import-template.ts MESH.obj|ply MASKS.json --id NAME --out DIR');
  }
  const bytes = readFileSync(meshPath);
  const masks = JSON.parse(readFileSync(masksPath, 'utf8')) as MasksFile;
  const template = templateFromUserMesh(id, basename(meshPath), bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), masks);
  const { header, binary } = await encodeTemplate(template, 'template.bin');
  mkdirSync(resolve(out), { recursive: true });
  writeFileSync(join(out, 'template.json'), formatJson(header));
  writeFileSync(join(out, 'template.bin'), binary);
  console.log(`wrote ${out}: ${template.vertexCount} vertices, ${header.triangleCount} triangles`);
}

main().catch((e) => {
  console.error(`import-template: ${(e as Error).message}`);
  process.exit(1);
});
