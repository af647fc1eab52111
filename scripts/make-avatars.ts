/**
 * npm run make-avatars: the test avatars, made from the face template and the ARKit basis (src/avatar/), no
 * third-party asset: examples/avatars/arkit-face.glb (the 52 ARKit morph targets and a "Head" node),
 * examples/avatars/visemes-face.glb (only the 15 Oculus viseme targets, each a mix of the ARKit shapes) and
 * examples/avatars/arkit-full-body.glb (the ARKit face on a full-body skeleton with Ready Player Me's bone names,
 * which TalkingHead requires; src/avatar/full-body-rig.ts), and examples/avatars/vrm1-face.vrm and vrm0-face.vrm
 * (VRoid's morph-target names on the full-body rig, driven only through the file's VRM 1.0 or 0.x extension;
 * src/avatar/vrm-test-avatar.ts). A unit test checks that the committed files are exactly what this writes.
 */
import { readFileSync, realpathSync, writeFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { decodeTemplate } from '../src/template/face-template';
import { buildAvatarGlb } from '../src/avatar/avatar-mesh';
import { buildFullBodyAvatarGlb } from '../src/avatar/full-body-rig';
import { buildVrmAvatarGlb } from '../src/avatar/vrm-test-avatar';
import { installFileReader } from '../tests/unit/helpers/file-reader';

const ROOT = resolve(import.meta.dirname, '..');

export const AVATARS = {
  'arkit-face.glb': 'arkit', 'visemes-face.glb': 'visemes', 'arkit-full-body.glb': 'full-body', 'vrm1-face.vrm': 'vrm1', 'vrm0-face.vrm': 'vrm0',
} as const;

export async function makeAvatars(): Promise<Record<string, Uint8Array>> {
  installFileReader();
  const bin = readFileSync(resolve(ROOT, 'models/template/template.bin'));
  const template = await decodeTemplate(JSON.parse(readFileSync(resolve(ROOT, 'models/template/template.json'), 'utf8')),
    bin.buffer.slice(bin.byteOffset, bin.byteOffset + bin.byteLength) as ArrayBuffer);
  const out: Record<string, Uint8Array> = {};
  for (const [file, kind] of Object.entries(AVATARS)) {
    out[file] = new Uint8Array(await (kind === 'full-body' ? buildFullBodyAvatarGlb(template)
      : kind === 'vrm1' || kind === 'vrm0' ? buildVrmAvatarGlb(template, kind === 'vrm1' ? '1' : '0') : buildAvatarGlb(template, kind)));
  }
  return out;
}

if (process.argv[1] && realpathSync(process.argv[1]) === import.meta.filename) { // (run through a link too)
  for (const [file, bytes] of Object.entries(await makeAvatars())) {
    writeFileSync(resolve(ROOT, 'examples/avatars', file), bytes);
    console.log(`examples/avatars/${file}: ${(bytes.byteLength / 1024).toFixed(0)} kB`);
  }
}
