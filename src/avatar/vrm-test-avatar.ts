/**
 * The VRM test avatars (scripts/make-avatars.ts): the template's face on the full-body rig (full-body-rig.ts), its
 * morph targets named as VRoid Studio names them (Fcl_MTH_A ...), none of them an ARKit or viseme name, so only the
 * file's VRM extension says which moves the mouth: VRM 1.0's VRMC_vrm (expressions bound by node, weights 0-1, the
 * face towards +z) or VRM 0.x's VRM (blend-shape groups bound by mesh, weights 0-100, the face towards -z). Each
 * vowel is the viseme of that vowel (avatar-mesh.ts's visemeAsArkit); the face is two primitives, as VRoid's is
 * several; the humanoid maps VRM's bones to the rig's.
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';
import { ARKIT_INDEX, ARKIT_NAMES, type ArkitName, type VisemeName } from './names';
import { arkitBasis } from './basis';
import { avatarScene, visemeAsArkit, type MorphAsArkit } from './avatar-mesh';
import { fullBodyScene } from './full-body-rig';
import { editGlbJson } from './gltf-nodes';

const arkitMix = (weights: Partial<Record<ArkitName, number>>) => {
  const w = new Float32Array(ARKIT_NAMES.length);
  for (const [name, v] of Object.entries(weights)) w[ARKIT_INDEX[name as ArkitName]] = v;
  return w;
};

/** VRoid's morph targets, each with the VRM 1.0 preset it is bound to. */
const MORPHS: [name: string, preset: string, arkit: Float32Array][] = [
  ...([['A', 'aa', 'viseme_aa'], ['I', 'ih', 'viseme_I'], ['U', 'ou', 'viseme_U'], ['E', 'ee', 'viseme_E'], ['O', 'oh', 'viseme_O']] as const)
    .map(([v, preset, viseme]): [string, string, Float32Array] => [`Fcl_MTH_${v}`, preset, visemeAsArkit(viseme as VisemeName)]),
  ['Fcl_EYE_Close', 'blink', arkitMix({ eyeBlinkLeft: 1, eyeBlinkRight: 1 })],
  ['Fcl_EYE_Close_L', 'blinkLeft', arkitMix({ eyeBlinkLeft: 1 })],
  ['Fcl_EYE_Close_R', 'blinkRight', arkitMix({ eyeBlinkRight: 1 })],
  ['Fcl_ALL_Joy', 'happy', arkitMix({ mouthSmileLeft: 0.8, mouthSmileRight: 0.8, cheekSquintLeft: 0.5, cheekSquintRight: 0.5 })],
];
/** VRM 0.x's preset names for VRM 1.0's. */
const V0_NAMES: Record<string, string> = { aa: 'a', ih: 'i', ou: 'u', ee: 'e', oh: 'o', blink: 'blink', blinkLeft: 'blink_l', blinkRight: 'blink_r', happy: 'joy' };

/** VRM's humanoid bones and the rig's (full-body-rig.ts, Ready Player Me's names). */
const HUMANOID: Record<string, string> = {
  hips: 'Hips', spine: 'Spine', chest: 'Spine1', upperChest: 'Spine2', neck: 'Neck', head: 'Head', leftEye: 'LeftEye', rightEye: 'RightEye',
  ...Object.fromEntries((['Left', 'Right'] as const).flatMap((side) => {
    const s = side.toLowerCase();
    return [[`${s}Shoulder`, 'Shoulder'], [`${s}UpperArm`, 'Arm'], [`${s}LowerArm`, 'ForeArm'], [`${s}Hand`, 'Hand'],
      [`${s}UpperLeg`, 'UpLeg'], [`${s}LowerLeg`, 'Leg'], [`${s}Foot`, 'Foot'], [`${s}Toes`, 'ToeBase']].map(([vrm, rig]) => [vrm, side + rig]);
  })),
};

interface GlbJson {
  nodes: { name?: string; mesh?: number }[];
  extensionsUsed?: string[];
  extensions?: Record<string, unknown>;
}

/** A VRM test avatar as .vrm (.glb) bytes: VRM 1.0 (`'1'`) or 0.x (`'0'`). */
export async function buildVrmAvatarGlb(template: FaceTemplate, version: '0' | '1'): Promise<ArrayBuffer> {
  const morphs: MorphAsArkit[] = MORPHS.map(([name, , arkit]) => [name, arkit]);
  const { head, mesh } = avatarScene(template, arkitBasis(template), { morphs, name: 'Face' });
  // Two primitives sharing the morph targets, as VRoid's face has several (skin, mouth, eyes...): three.js loads the
  // node as a group of meshes, each of which an expression's bind moves.
  const triangles = mesh.geometry.index!.count, half = 3 * Math.floor(triangles / 6);
  mesh.geometry.addGroup(0, half, 0);
  mesh.geometry.addGroup(half, triangles - half, 1);
  const skin = mesh.material as THREE.MeshStandardMaterial;
  mesh.material = [skin, skin.clone()];
  const scene = fullBodyScene(head);
  if (version === '0') scene.getObjectByName('Armature')!.rotation.y = Math.PI; // VRM 0.x faces -z
  const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
  const glb = (await new GLTFExporter().parseAsync(scene, { binary: true })) as ArrayBuffer;
  scene.traverse((o) => {
    if (!(o as THREE.Mesh).isMesh) return;
    (o as THREE.Mesh).geometry.dispose();
    [(o as THREE.Mesh).material].flat().forEach((m) => m.dispose());
  });
  return editGlbJson<GlbJson>(glb, (json) => addVrm(json, version));
}

function addVrm(json: GlbJson, version: '0' | '1'): void {
  const node = (name: string) => {
    const i = json.nodes.findIndex((n) => n.name === name);
    if (i < 0) throw new Error(`VRM test avatar: no node ${name}`);
    return i;
  };
  const face = node('Face'), mesh = json.nodes[face].mesh!;
  json.extensionsUsed = [...(json.extensionsUsed ?? []), version === '1' ? 'VRMC_vrm' : 'VRM'];
  json.extensions ??= {};
  if (version === '1') {
    json.extensions.VRMC_vrm = {
      specVersion: '1.0',
      meta: { name: 'talking-face test avatar (VRM 1.0)', version: '1', authors: ['talking-face'], licenseUrl: 'https://vrm.dev/licenses/1.0/',
        avatarPermission: 'everyone', commercialUsage: 'corporation', allowRedistribution: true, modification: 'allowModificationRedistribution' },
      humanoid: { humanBones: Object.fromEntries(Object.entries(HUMANOID).map(([bone, name]) => [bone, { node: node(name) }])) },
      expressions: { preset: Object.fromEntries(MORPHS.map(([, preset], index) => [preset, {
        morphTargetBinds: [{ node: face, index, weight: 1 }], isBinary: false, overrideBlink: 'none', overrideLookAt: 'none', overrideMouth: 'none',
      }])) },
    };
    return;
  }
  json.extensions.VRM = {
    specVersion: '0.0',
    exporterVersion: 'talking-face make-avatars',
    meta: { title: 'talking-face test avatar (VRM 0.x)', version: '1', author: 'talking-face', allowedUserName: 'Everyone', licenseName: 'CC0' },
    humanoid: { humanBones: Object.entries(HUMANOID).map(([bone, name]) => ({ bone, node: node(name), useDefaultValues: true })) },
    blendShapeMaster: { blendShapeGroups: MORPHS.map(([name, preset], index) => ({
      name: name.replace('Fcl_', ''), presetName: V0_NAMES[preset], binds: [{ mesh, index, weight: 100 }], materialValues: [], isBinary: false,
    })) },
  };
}
