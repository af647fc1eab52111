/**
 * A take as a VRM Animation (.vrma, the VRMC_vrm_animation extension of glTF), which @pixiv/three-vrm-animation and
 * other VRM tools play on any VRM avatar: the head's rotation per frame, and the mouth's five vowel expressions (aa ih
 * ou ee oh) made from the visemes as a VRM avatar shows them live (vrm.ts). A VRM Animation animates a humanoid: its
 * bones here are hips, spine, chest, neck and head, at rest in a T-pose (no rotation), the hips 1 m up; only the
 * head turns. Each expression is a node whose translation's x is the expression's weight (the format's way).
 * No blinks: the model does not predict them (a page's player adds idle blinks; blinks.ts).
 */
import * as THREE from 'three';
import type { Animation } from '../engine/frames';
import { blendshapesOf } from './weights';
import { VISEME_NAMES } from './names';
import { VRM_VOWELS, vowelsOf } from './vrm';
import { editGlbJson } from './gltf-nodes';
import { poseQuaternions } from './export';

/** The humanoid's bones: name, VRM's name, offset from the parent (m). */
const BONES: [name: string, humanBone: string, at: [number, number, number]][] = [
  ['Hips', 'hips', [0, 1, 0]],
  ['Spine', 'spine', [0, 0.1, 0]],
  ['Chest', 'chest', [0, 0.15, 0]],
  ['Neck', 'neck', [0, 0.3, 0]],
  ['Head', 'head', [0, 0.1, 0]],
];

/** .vrma bytes: the take's head rotation and vowel expressions at its frame rate. */
export async function vrmAnimation(animation: Animation): Promise<ArrayBuffer> {
  const b = blendshapesOf(animation);
  const F = animation.frames, V = VISEME_NAMES.length;
  const scene = new THREE.Scene();
  let parent: THREE.Object3D = scene;
  for (const [name, , at] of BONES) {
    const bone = new THREE.Object3D();
    bone.name = name;
    bone.position.set(...at);
    parent.add(bone);
    parent = bone;
  }
  for (const vowel of VRM_VOWELS) {
    const node = new THREE.Object3D();
    node.name = `Expression_${vowel}`;
    scene.add(node);
  }
  const times = Float32Array.from({ length: F }, (_, f) => f / animation.fps);
  const weights = VRM_VOWELS.map(() => new Float32Array(F * 3));
  const vowels = new Float32Array(VRM_VOWELS.length);
  for (let f = 0; f < F; f++) {
    vowelsOf(b.visemes, f * V, vowels);
    for (let k = 0; k < VRM_VOWELS.length; k++) weights[k][f * 3] = vowels[k];
  }
  const clip = new THREE.AnimationClip('speech', Math.max(F - 1, 0) / animation.fps, [
    new THREE.QuaternionKeyframeTrack('Head.quaternion', times, poseQuaternions(animation)),
    ...VRM_VOWELS.map((vowel, k) => new THREE.VectorKeyframeTrack(`Expression_${vowel}.position`, times, weights[k])),
  ]);
  const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
  const glb = (await new GLTFExporter().parseAsync(scene, { binary: true, animations: [clip] })) as ArrayBuffer;
  return editGlbJson<{ nodes: { name?: string }[]; extensionsUsed?: string[]; extensions?: Record<string, unknown> }>(glb, (json) => {
    const node = (name: string) => json.nodes.findIndex((n) => n.name === name);
    json.extensionsUsed = [...(json.extensionsUsed ?? []), 'VRMC_vrm_animation'];
    json.extensions = {
      ...json.extensions,
      VRMC_vrm_animation: {
        specVersion: '1.0',
        humanoid: { humanBones: Object.fromEntries(BONES.map(([name, humanBone]) => [humanBone, { node: node(name) }])) },
        expressions: { preset: Object.fromEntries(VRM_VOWELS.map((vowel) => [vowel, { node: node(`Expression_${vowel}`) }])) },
      },
    };
  });
}
