/**
 * VRM avatars (VRoid Studio's, VRoid Hub's, UniVRM's: VRM 1.0 and 0.x): their mouth has five expressions, the
 * vowels aa ih ou ee oh, bound to morph targets of any name by the file's VRM extension; their blinks are
 * expressions too, and the humanoid names the head bone. Read here from a glTF loaded by a plain GLTFLoader (the
 * extension's JSON, its node and mesh indices mapped to three.js objects), or taken from @pixiv/three-vrm's VRM where
 * the page loaded it with VRMLoaderPlugin (`gltf.userData.vrm`): its expression manager and its normalized head bone,
 * which vrm.update() copies to the model. No import of three-vrm: it is the page's.
 */
import type * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { VISEME_NAMES } from './names';

/** VRM's mouth presets, in the order of VISEME_VOWELS's columns. */
export const VRM_VOWELS = ['aa', 'ih', 'ou', 'ee', 'oh'] as const;
export type VrmVowel = (typeof VRM_VOWELS)[number];

/**
 * Each of the 15 visemes (VISEME_NAMES order) as VRM's five vowels (VRM_VOWELS order): the non-negative mix of the
 * aa, I, U, E and O visemes' shapes (made from the ARKit basis, avatar-mesh.ts's visemeAsArkit) closest to the
 * viseme's own shape on the template's face, rounded to 0.01; tests/unit/avatar/vrm.test.ts recomputes it. Except
 * PP: its lips are closed, and every vowel parts them, so it is none (the least-squares mix, aa 0.09, follows its
 * jaw).
 */
export const VISEME_VOWELS: readonly (readonly [number, number, number, number, number])[] = [
  //  aa    ih    ou    ee    oh
  [0, 0, 0, 0, 0], // sil
  [0, 0, 0, 0, 0], // PP
  [0.08, 0, 0, 0.12, 0], // FF
  [0.2, 0.13, 0, 0, 0.03], // TH
  [0.26, 0, 0, 0, 0.01], // DD
  [0.31, 0, 0, 0, 0.01], // kk
  [0, 0.06, 0.67, 0, 0], // CH
  [0, 0.31, 0, 0, 0], // SS
  [0.26, 0, 0, 0, 0.01], // nn
  [0, 0.04, 0.33, 0, 0.22], // RR
  [1, 0, 0, 0, 0], // aa
  [0, 0, 0, 1, 0], // E
  [0, 1, 0, 0, 0], // I
  [0, 0, 0, 0, 1], // O
  [0, 0, 1, 0, 0], // U
];

/** The five vowels' weights (into `out`, VRM_VOWELS order) for one frame of visemes (15, from index `at`). */
export function vowelsOf(visemes: ArrayLike<number>, at: number, out: Float32Array): Float32Array {
  out.fill(0);
  for (let v = 0; v < VISEME_NAMES.length; v++) {
    const w = visemes[at + v];
    if (!w) continue;
    const row = VISEME_VOWELS[v];
    for (let k = 0; k < 5; k++) out[k] += w * row[k];
  }
  for (let k = 0; k < 5; k++) out[k] = Math.min(1, out[k]);
  return out;
}

/** One morph target an expression moves: influences[at] += the expression's weight x `weight`. */
export interface VrmBind {
  influences: number[];
  at: number;
  weight: number;
}

/** What the element needs of @pixiv/three-vrm's VRM (gltf.userData.vrm), typed here so as not to import it. */
export interface ThreeVrmLike {
  meta?: { metaVersion?: string };
  expressionManager?: { setValue(name: string, weight: number): void; getExpression(name: string): unknown };
  humanoid?: { getNormalizedBoneNode(name: string): THREE.Object3D | null | undefined };
}

/** A VRM read from its extension: the expressions' binds by preset name (VRM 1.0's names), the head bone, the version. */
export interface VrmFile {
  version: '0' | '1';
  expressions: Map<string, VrmBind[]>;
  head: THREE.Object3D | null;
}

/** VRM 0.x preset names as VRM 1.0 spells them (three-vrm's map; only those driven here). */
const V0_PRESETS: Record<string, string> = { a: 'aa', i: 'ih', u: 'ou', e: 'ee', o: 'oh', blink: 'blink', blink_l: 'blinkLeft', blink_r: 'blinkRight' };

interface GltfJson {
  nodes?: { mesh?: number }[];
  extensions?: {
    VRMC_vrm?: {
      humanoid?: { humanBones?: Record<string, { node?: number }> };
      expressions?: { preset?: Record<string, { morphTargetBinds?: { node?: number; index?: number; weight?: number }[] } | undefined> };
    };
    VRM?: {
      humanoid?: { humanBones?: { bone?: string; node?: number }[] };
      blendShapeMaster?: { blendShapeGroups?: { presetName?: string; binds?: { mesh?: number; index?: number; weight?: number }[] }[] };
    };
  };
}

interface Association { nodes?: number; meshes?: number }
interface Parser { json?: GltfJson; associations?: Map<unknown, Association> }

/** three-vrm's VRM where the page loaded the file with VRMLoaderPlugin (one with an expression manager), else null. */
export function threeVrmOf(gltf: GLTF): ThreeVrmLike | null {
  const vrm = (gltf.userData as { vrm?: ThreeVrmLike } | undefined)?.vrm;
  return vrm?.expressionManager ? vrm : null;
}

/**
 * The VRM extension of a glTF loaded by GLTFLoader (VRMC_vrm, else VRM 0.x's VRM), its indices mapped to the
 * scene's objects through the loader's associations; null when the file has neither, or the loader's parser is gone.
 */
export function readVrm(gltf: GLTF): VrmFile | null {
  const parser = (gltf as unknown as { parser?: Parser }).parser;
  const json = parser?.json, ext = json?.extensions;
  if (!json || !parser.associations || !(ext?.VRMC_vrm || ext?.VRM)) return null;
  const nodes = new Map<number, THREE.Object3D>();
  const meshes = new Map<number, THREE.Mesh[]>();
  gltf.scene.traverse((o) => {
    const a = parser.associations!.get(o);
    if (a?.nodes !== undefined) nodes.set(a.nodes, o);
    const mesh = o as THREE.Mesh;
    if (a?.meshes !== undefined && mesh.morphTargetInfluences) meshes.set(a.meshes, [...(meshes.get(a.meshes) ?? []), mesh]);
  });
  // A node's primitives: the node itself where its mesh has one primitive, else its children of that mesh.
  const primitivesOf = (node: number): THREE.Mesh[] => {
    const object = nodes.get(node), mesh = json.nodes?.[node]?.mesh;
    if (!object || mesh === undefined) return [];
    const own = meshes.get(mesh) ?? [];
    return own.filter((m) => m === object || m.parent === object);
  };
  const expressions = new Map<string, VrmBind[]>();
  const bind = (name: string, primitives: THREE.Mesh[], index: number | undefined, weight: number) => {
    if (index === undefined) return;
    for (const m of primitives) {
      if (index < m.morphTargetInfluences!.length) expressions.set(name, [...(expressions.get(name) ?? []), { influences: m.morphTargetInfluences!, at: index, weight }]);
    }
  };
  if (ext.VRMC_vrm) {
    for (const [name, expression] of Object.entries(ext.VRMC_vrm.expressions?.preset ?? {})) {
      for (const b of expression?.morphTargetBinds ?? []) if (b.node !== undefined) bind(name, primitivesOf(b.node), b.index, b.weight ?? 1);
    }
    const head = ext.VRMC_vrm.humanoid?.humanBones?.head?.node;
    return { version: '1', expressions, head: head === undefined ? null : nodes.get(head) ?? null };
  }
  const v0 = ext.VRM!;
  for (const group of v0.blendShapeMaster?.blendShapeGroups ?? []) {
    const name = V0_PRESETS[group.presetName ?? ''];
    if (!name) continue;
    for (const b of group.binds ?? []) {
      if (b.mesh === undefined) continue;
      // Every node using the mesh (three.js gives each its own objects), as three-vrm binds them.
      const users = (json.nodes ?? []).flatMap((n, i) => (n.mesh === b.mesh ? primitivesOf(i) : []));
      bind(name, users, b.index, (b.weight ?? 100) / 100); // VRM 0.x weighs binds 0-100
    }
  }
  const head = v0.humanoid?.humanBones?.find((b) => b.bone === 'head')?.node;
  return { version: '0', expressions, head: head === undefined ? null : nodes.get(head) ?? null };
}
