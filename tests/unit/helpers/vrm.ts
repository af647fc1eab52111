/** The VRM test avatars (examples/avatars/, npm run make-avatars) in unit tests: loaded plainly or by three-vrm, edited, read. */
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { expect } from 'vitest';
import * as THREE from 'three';
import { GLTFLoader, type GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { VRMLoaderPlugin, type VRM } from '@pixiv/three-vrm';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { editGlbJson } from '../../../src/avatar/gltf-nodes';
import { ARKIT_NAMES, VISEME_NAMES } from '../../../src/avatar/names';
import { ROOT } from './exported';

export const bytes = (name: string) => {
  const b = readFileSync(resolve(ROOT, 'examples/avatars', name));
  return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer;
};
export async function load(name: string | ArrayBuffer, threeVrm: boolean): Promise<GLTF> {
  const loader = new GLTFLoader();
  if (threeVrm) loader.register((parser) => new VRMLoaderPlugin(parser));
  return loader.parseAsync(typeof name === 'string' ? bytes(name) : name, '');
}
/** A test VRM with its glTF JSON changed by `edit` (the binary chunk kept). */
export const edited = (name: string, edit: (json: any) => void) => editGlbJson(bytes(name), edit); // eslint-disable-line @typescript-eslint/no-explicit-any
/** The face's influence of each named morph target, the same in each of its two primitives (meshes). */
export const morphs = (gltf: GLTF) => {
  const meshes: THREE.Mesh[] = [];
  gltf.scene.traverse((o) => { if ((o as THREE.Mesh).morphTargetDictionary?.Fcl_EYE_Close !== undefined) meshes.push(o as THREE.Mesh); });
  const [face, ...others] = meshes;
  expect(others.length).toBe(1);
  for (const other of others) expect(other.morphTargetInfluences).toEqual(face.morphTargetInfluences);
  return Object.fromEntries(Object.entries(face.morphTargetDictionary!).map(([n, i]) => [n, face.morphTargetInfluences![i]]));
};
export const oneHot = (n: number, k: number, v = 1) => Float32Array.from({ length: n }, (_, i) => (i === k ? v : 0));
export const arkitZero = new Float32Array(ARKIT_NAMES.length);

/** VRM 1.0's expressions in an edited file's JSON. */
export const expressionsOf = (json: { extensions: { VRMC_vrm: { expressions: { preset: Record<string, any>; custom?: Record<string, any> } } } }) => json.extensions.VRMC_vrm.expressions; // eslint-disable-line @typescript-eslint/no-explicit-any
export const renamed = (json: { meshes: { extras?: { targetNames?: string[] } }[] }, from: string, to: string) => {
  for (const m of json.meshes) if (m.extras?.targetNames) m.extras.targetNames = m.extras.targetNames.map((n) => (n === from ? to : n));
};
/** One frame through a plain-loaded and a three-vrm-loaded copy of `file`: each one's morph targets after it is shown. */
export async function bothWays(file: ArrayBuffer, arkit: Float32Array, visemes: Float32Array, idleBlink = 0) {
  const out = [];
  for (const threeVrm of [false, true]) {
    const gltf = await load(file.slice(0), threeVrm);
    const avatar = GltfAvatar.bind(gltf, 'edited.vrm');
    avatar.setWeights(arkit, 0, visemes, 0);
    avatar.setIdleBlink(idleBlink);
    (gltf.userData.vrm as VRM | undefined)?.update(0);
    out.push({ summary: avatar.summary, morphs: morphs(gltf) });
  }
  return out;
}
export const V = VISEME_NAMES.length, A = ARKIT_NAMES.length;

