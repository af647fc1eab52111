/**
 * VRM avatars (VRoid Studio's, VRoid Hub's, UniVRM's: VRM 1.0 and 0.x): their mouth has five expressions, the
 * vowels aa ih ou ee oh, bound to morph targets of any name by the file's VRM extension; their blinks are
 * expressions too, and the humanoid names the head bone. Read here from a glTF loaded by a plain GLTFLoader (the
 * extension's JSON, its node and mesh indices mapped to three.js objects), or taken from @pixiv/three-vrm's VRM where
 * the page loaded it with VRMLoaderPlugin (`gltf.userData.vrm`): its expression manager and its normalized head bone,
 * which vrm.update() copies to the model. No import of three-vrm: it is the page's. Either way the expressions
 * follow three-vrm's rules (VRMExpressionManager.update): a binary one is on above 0.5 (and off where an override
 * scales it below 1), and one that overrides the mouth or the blinks blocks them at any weight ('block') or scales
 * them down by its weight ('blend').
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

type Override = 'none' | 'block' | 'blend';

/** An expression as the file defines it (VRM 1.0's names; a VRM 0.x group's preset name mapped, else its own name). */
export interface VrmExpression {
  binds: VrmBind[];
  isBinary: boolean;
  overrideMouth: Override;
  overrideBlink: Override;
}

/** A VRM read from its extension: its expressions by name, the head bone, the version. */
export interface VrmFile {
  version: '0' | '1';
  expressions: Map<string, VrmExpression>;
  head: THREE.Object3D | null;
  /** Expressions with a bind to a node, mesh or morph target the file does not have (left out, as three-vrm does). */
  unbound: string[];
}

/**
 * The model's own eyeBlink weights count from this up for a VRM's blink expressions (stretched: 1 stays 1): they are
 * small and steady (the model does not predict blinks), and three-vrm blocks the mouth at any weight of a blink
 * expression that overrides it.
 */
export const VRM_BLINK_FLOOR = 0.1;

/** What the avatar needs of three-vrm's VRM (gltf.userData.vrm), typed here so as not to import it. */
export interface ThreeVrmLike {
  meta?: { metaVersion?: string };
  expressionManager?: ExpressionManagerLike & {
    expressions: { expressionName: string; binds?: readonly { primitives?: readonly THREE.Mesh[]; index?: number }[] }[];
  };
  humanoid?: {
    getNormalizedBoneNode(name: string): THREE.Object3D | null | undefined;
    /** The model's own (raw) bones by humanoid name. */
    humanBones?: Record<string, { node?: THREE.Object3D } | undefined>;
    /** Whether vrm.update() copies the normalized bones' pose to the model's own (three-vrm's default: true). */
    autoUpdateHumanBones?: boolean;
  };
}

/** Expressions set by name: three-vrm's VRMExpressionManager (applied by vrm.update()), or VrmExpressions. */
export interface ExpressionManagerLike {
  setValue(name: string, weight: number): void;
}

const MOUTH = new Set<string>(VRM_VOWELS), BLINKS = new Set(['blink', 'blinkLeft', 'blinkRight']);

/**
 * A VRM's expressions applied to its morph targets where three-vrm is not there to (a plain GLTFLoader's glTF):
 * setValue() as three-vrm's expression manager takes it, update() as its update() applies the weights.
 */
export class VrmExpressions implements ExpressionManagerLike {
  private readonly entries: (VrmExpression & { weight: number; part: 'mouth' | 'blink' | null })[];
  private readonly byName = new Map<string, VrmExpression & { weight: number }>();

  constructor(file: VrmFile) {
    this.entries = [...file.expressions].map(([name, e]) => {
      const entry = { ...e, weight: 0, part: MOUTH.has(name) ? 'mouth' as const : BLINKS.has(name) ? 'blink' as const : null };
      this.byName.set(name, entry);
      return entry;
    });
  }

  setValue(name: string, weight: number): void {
    const entry = this.byName.get(name);
    if (entry) entry.weight = Math.min(1, Math.max(0, weight));
  }

  /** Every morph target an expression binds to 0, then each expression's weight (binary, overridden) added. */
  update(): void {
    let mouth = 1, blink = 1;
    for (const e of this.entries) {
      mouth -= overrideAmount(e.overrideMouth, outputWeight(e));
      blink -= overrideAmount(e.overrideBlink, outputWeight(e));
    }
    mouth = Math.max(0, mouth);
    blink = Math.max(0, blink);
    for (const e of this.entries) for (const b of e.binds) b.influences[b.at] = 0;
    for (const e of this.entries) {
      let w = outputWeight(e) * (e.part === 'mouth' ? mouth : e.part === 'blink' ? blink : 1);
      if (e.isBinary && w < 1) w = 0; // (a binary one scaled down by an override is off)
      if (w) for (const b of e.binds) b.influences[b.at] += w * b.weight;
    }
  }
}

const outputWeight = (e: { isBinary: boolean; weight: number }) => (e.isBinary ? (e.weight > 0.5 ? 1 : 0) : e.weight);
const overrideAmount = (o: Override, weight: number) => (o === 'block' ? (weight > 0 ? 1 : 0) : o === 'blend' ? weight : 0);
const override = (o: unknown): Override => (o === 'block' || o === 'blend' ? o : 'none');

/** VRM 1.0's preset expressions. */
const V1_PRESETS = new Set([...VRM_VOWELS, 'happy', 'angry', 'sad', 'relaxed', 'surprised', 'blink', 'blinkLeft', 'blinkRight',
  'lookUp', 'lookDown', 'lookLeft', 'lookRight', 'neutral']);

/** VRM 0.x preset names as VRM 1.0 spells them (three-vrm's map). */
const V0_PRESETS: Record<string, string> = {
  a: 'aa', i: 'ih', u: 'ou', e: 'ee', o: 'oh', blink: 'blink', blink_l: 'blinkLeft', blink_r: 'blinkRight', joy: 'happy', angry: 'angry',
  sorrow: 'sad', fun: 'relaxed', lookup: 'lookUp', lookdown: 'lookDown', lookleft: 'lookLeft', lookright: 'lookRight', neutral: 'neutral',
};

interface SchemaExpression {
  morphTargetBinds?: { node?: number; index?: number; weight?: number }[];
  isBinary?: boolean;
  overrideMouth?: string;
  overrideBlink?: string;
}

interface GltfJson {
  nodes?: { mesh?: number }[];
  extensions?: {
    VRMC_vrm?: {
      humanoid?: { humanBones?: Record<string, { node?: number }> };
      expressions?: { preset?: Record<string, SchemaExpression | undefined>; custom?: Record<string, SchemaExpression | undefined> };
    };
    VRM?: {
      humanoid?: { humanBones?: { bone?: string; node?: number }[] };
      blendShapeMaster?: { blendShapeGroups?: { name?: string; presetName?: string; isBinary?: boolean; binds?: { mesh?: number; index?: number; weight?: number }[] }[] };
    };
  };
}

interface Association { nodes?: number; meshes?: number }
interface Parser { json?: GltfJson; associations?: Map<unknown, Association> }

/** three-vrm's VRM where the page loaded the file with VRMLoaderPlugin, else null. */
export function threeVrmOf(gltf: GLTF): ThreeVrmLike | null {
  const vrm = (gltf.userData as { vrm?: ThreeVrmLike } | undefined)?.vrm;
  return vrm?.expressionManager || vrm?.humanoid ? vrm : null;
}

/**
 * The VRM extension of a glTF loaded by GLTFLoader (VRMC_vrm, else VRM 0.x's VRM), its indices mapped to the
 * scene's objects through the loader's associations; null when the file has neither, or the loader's parser is gone.
 * A bind to a node, mesh or morph target the file does not have is left out, as three-vrm leaves it.
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
  // A node's primitives: the node itself where its mesh has one primitive, else its children of that mesh (not a
  // child node that uses the same mesh).
  const nodeObjects = new Set(nodes.values());
  const primitivesOf = (node: number): THREE.Mesh[] => {
    const object = nodes.get(node), mesh = json.nodes?.[node]?.mesh;
    if (!object || mesh === undefined) return [];
    return (meshes.get(mesh) ?? []).filter((m) => m === object || (m.parent === object && !nodeObjects.has(m)));
  };
  const expressions = new Map<string, VrmExpression>();
  const add = (name: string, isBinary?: boolean, mouth?: string, blink?: string): VrmBind[] => {
    const e = { binds: [], isBinary: !!isBinary, overrideMouth: override(mouth), overrideBlink: override(blink) };
    expressions.set(name, e);
    return e.binds;
  };
  const unbound = new Set<string>();
  const bind = (name: string, binds: VrmBind[], primitives: THREE.Mesh[], index: number | undefined, weight: number) => {
    const ok = primitives.length > 0 && Number.isInteger(index) && index! >= 0 && primitives.every((m) => index! < m.morphTargetInfluences!.length);
    if (!ok) unbound.add(name);
    else for (const m of primitives) binds.push({ influences: m.morphTargetInfluences!, at: index!, weight });
  };
  if (ext.VRMC_vrm) {
    const { preset = {}, custom = {} } = ext.VRMC_vrm.expressions ?? {};
    // As three-vrm: a preset of another name, and a custom expression named as a preset, are left out.
    const named = [...Object.entries(preset).filter(([n]) => V1_PRESETS.has(n)), ...Object.entries(custom).filter(([n]) => !V1_PRESETS.has(n))];
    for (const [name, e] of named) {
      if (!e) continue;
      const binds = add(name, e.isBinary, e.overrideMouth, e.overrideBlink);
      for (const b of e.morphTargetBinds ?? []) bind(name, binds, b.node === undefined ? [] : primitivesOf(b.node), b.index, b.weight ?? 1);
    }
    const head = ext.VRMC_vrm.humanoid?.humanBones?.head?.node;
    return { version: '1', expressions, head: head === undefined ? null : nodes.get(head) ?? null, unbound: [...unbound] };
  }
  const v0 = ext.VRM!;
  for (const group of v0.blendShapeMaster?.blendShapeGroups ?? []) {
    const name = V0_PRESETS[group.presetName ?? ''] ?? group.name;
    if (!name || expressions.has(name)) continue; // (three-vrm keeps a preset's first group too)
    const binds = add(name, group.isBinary);
    for (const b of group.binds ?? []) {
      // Every node using the mesh (three.js gives each its own objects), as three-vrm binds them.
      const users = b.mesh === undefined ? [] : (json.nodes ?? []).flatMap((n, i) => (n.mesh === b.mesh ? primitivesOf(i) : []));
      bind(name, binds, users, b.index, (b.weight ?? 100) / 100); // VRM 0.x weighs binds 0-100
    }
  }
  const head = v0.humanoid?.humanBones?.find((b) => b.bone === 'head')?.node;
  return { version: '0', expressions, head: head === undefined ? null : nodes.get(head) ?? null, unbound: [...unbound] };
}
