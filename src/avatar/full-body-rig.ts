/**
 * The face avatar (avatar-mesh.ts) on a full-body skeleton with Ready Player Me's bone names (Mixamo's, without the
 * "mixamorig" prefix), for avatar classes that will not load a face alone. TalkingHead (@met4citizen/talkinghead)
 * is one: its showAvatar() looks up a root object "Armature" and every bone its poses and gestures turn (Hips,
 * Spine, Spine1, Spine2, Neck, Head, both shoulders, arms, forearms, hands, the fifteen finger bones of each hand,
 * up-legs, legs, feet and toe bases) and throws "Avatar object <name> not found" for the first one missing; it then
 * reads LeftEye / RightEye for the avatar's height and gaze, and stands the avatar so that its lowest geometry
 * touches the floor. docs/embedding.md, "Driving a TalkingHead avatar".
 *
 * No third-party asset and no skinning: each bone carries a rigid segment (a cylinder to its child), so the
 * mannequin follows any pose a class gives the bones. As in Mixamo's rig, a bone's child lies along its local +y
 * and the character faces +z with its left at +x; the rest pose is a T-pose. Lengths are an adult's, in metres,
 * with the hips 1 m up (TalkingHead's poses put them there).
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';
import { avatarScene } from './avatar-mesh';
import { arkitBasis } from './basis';

const BODY = 0x8a94a6;

interface BoneSpec {
  name: string;
  parent: string;
  /** Offset from the parent bone, in the parent's frame (m). */
  at: [number, number, number];
  /** Rest rotation (Euler XYZ, rad); identity when absent. */
  turn?: [number, number, number];
  /** The rigid segment towards the bone's child along +y: length, half-width (x), half-depth (z). */
  segment?: [number, number, number];
}

/** A finger of one hand: its first bone's offset in the hand's frame, its three segments' lengths. */
const FINGERS: [name: string, at: [number, number, number], lengths: [number, number, number]][] = [
  ['Thumb', [0.02, 0.03, 0.025], [0.035, 0.03, 0.025]],
  ['Index', [0.025, 0.09, 0.01], [0.04, 0.025, 0.02]],
  ['Middle', [0.005, 0.095, 0.01], [0.045, 0.028, 0.022]],
  ['Ring', [-0.015, 0.09, 0.008], [0.04, 0.026, 0.02]],
  ['Pinky', [-0.032, 0.08, 0.005], [0.032, 0.02, 0.018]],
];

/** The bones, parents first. The face's Head node (avatar-mesh.ts) takes the place of "Head". */
function skeleton(): BoneSpec[] {
  const bones: BoneSpec[] = [
    { name: 'Hips', parent: 'Armature', at: [0, 1, 0], segment: [0.1, 0.14, 0.1] },
    { name: 'Spine', parent: 'Hips', at: [0, 0.1, 0], segment: [0.12, 0.14, 0.1] },
    { name: 'Spine1', parent: 'Spine', at: [0, 0.12, 0], segment: [0.13, 0.15, 0.1] },
    { name: 'Spine2', parent: 'Spine1', at: [0, 0.13, 0], segment: [0.16, 0.17, 0.11] },
    { name: 'Neck', parent: 'Spine2', at: [0, 0.16, 0], segment: [0.09, 0.045, 0.045] },
    // The face's pivot (the template's origin) lies in front of the neck's axis, between the ears.
    { name: 'Head', parent: 'Neck', at: [0, 0.09, 0.035] },
  ];
  for (const [side, s] of [['Left', 1], ['Right', -1]] as const) {
    const limb = (name: string, parent: string, at: [number, number, number], turn?: [number, number, number], segment?: [number, number, number]) =>
      bones.push({ name: side + name, parent: parent === 'Spine2' || parent === 'Hips' ? parent : side + parent, at: [s * at[0], at[1], at[2]], turn, segment });
    limb('Shoulder', 'Spine2', [0.06, 0.1, 0], [0, 0, -s * Math.PI / 2], [0.11, 0.045, 0.045]);
    limb('Arm', 'Shoulder', [0, 0.11, 0], undefined, [0.27, 0.045, 0.045]);
    limb('ForeArm', 'Arm', [0, 0.27, 0], undefined, [0.25, 0.037, 0.037]);
    limb('Hand', 'ForeArm', [0, 0.25, 0], undefined, [0.09, 0.04, 0.015]);
    for (const [finger, at, lengths] of FINGERS) {
      lengths.forEach((length, k) => {
        const name = `Hand${finger}${k + 1}`;
        const parent = k === 0 ? 'Hand' : `Hand${finger}${k}`;
        limb(name, parent, k === 0 ? at : [0, lengths[k - 1], 0], undefined, [length, 0.009, 0.009]);
      });
    }
    limb('UpLeg', 'Hips', [0.09, -0.06, 0], [0, 0, Math.PI], [0.43, 0.07, 0.07]);
    limb('Leg', 'UpLeg', [0, 0.43, 0], undefined, [0.42, 0.055, 0.055]);
    limb('Foot', 'Leg', [0, 0.42, 0], [1.1, 0, 0], [0.14, 0.045, 0.035]);
    limb('ToeBase', 'Foot', [0, 0.14, 0], undefined, [0.06, 0.045, 0.03]);
  }
  return bones;
}

/**
 * The full-body scene: Armature > Hips > ... > Neck > the face's Head node, LeftEye / RightEye under the head at the
 * eyeballs' centres (the eyeballs hung from them), every bone with its segment.
 */
export function fullBodyScene(head: THREE.Object3D): THREE.Scene {
  const armature = new THREE.Object3D();
  armature.name = 'Armature';
  const byName = new Map<string, THREE.Object3D>([['Armature', armature]]);
  const unit = new THREE.CylinderGeometry(1, 1, 1, 10).translate(0, 0.5, 0);
  const material = new THREE.MeshStandardMaterial({ color: BODY, roughness: 0.7 });
  for (const b of skeleton()) {
    const bone = b.name === 'Head' ? head : new THREE.Bone();
    bone.name = b.name;
    bone.position.set(...b.at);
    if (b.turn) bone.rotation.set(...b.turn);
    const parent = byName.get(b.parent);
    if (!parent) throw new Error(`full-body rig: bone ${b.name} comes before its parent ${b.parent}`);
    parent.add(bone);
    byName.set(b.name, bone);
    if (b.segment) {
      const segment = new THREE.Mesh(unit, material);
      segment.name = `${b.name}_segment`;
      segment.scale.set(b.segment[1], b.segment[0], b.segment[2]);
      bone.add(segment);
    }
  }
  for (const [side, eyeName] of [['Left', 'eye_left'], ['Right', 'eye_right']] as const) {
    const eyeball = head.getObjectByName(eyeName);
    if (!eyeball) throw new Error(`full-body rig: the face has no ${eyeName}`);
    const eye = new THREE.Bone();
    eye.name = `${side}Eye`;
    eye.position.copy(eyeball.position);
    head.add(eye);
    eye.add(eyeball);
    eyeball.position.set(0, 0, 0);
  }
  const scene = new THREE.Scene();
  scene.add(armature);
  return scene;
}

/** The test avatar for TalkingHead as .glb bytes: the ARKit face (52 morph targets) on the full-body rig. */
export async function buildFullBodyAvatarGlb(template: FaceTemplate): Promise<ArrayBuffer> {
  const { head } = avatarScene(template, arkitBasis(template), { morphs: 'arkit', name: 'face_arkit' });
  const scene = fullBodyScene(head);
  const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
  const bytes = (await new GLTFExporter().parseAsync(scene, { binary: true })) as ArrayBuffer;
  scene.traverse((o) => {
    if (!(o as THREE.Mesh).isMesh) return;
    (o as THREE.Mesh).geometry.dispose();
    ((o as THREE.Mesh).material as THREE.Material).dispose();
  });
  return bytes;
}
