/**
 * The blend-shape output of a take in three formats (docs/avatar.md, "Export"):
 * - JSON: the 52 ARKit weights, the 15 visemes and the head rotation per frame, with the names;
 * - CSV in the column layout of Apple-iPhone recordings from Epic's Live Link Face app (what Unreal's and Unity's
 *   importers read): Timecode, BlendShapeCount, the 52 shapes in Live Link Face's own order, then the head's
 *   yaw, pitch and roll and both eyes' (the eyes are not predicted: 0);
 * - .glb: the template as an avatar whose morph targets are named after ARKit's shapes, animated by the weights
 *   (and the head by the head pose), which glTF viewers and engines play.
 */
import * as THREE from 'three';
import type { Animation } from '../engine/frames';
import type { FaceTemplate } from '../template/face-template';
import type { ArkitBasis } from './basis';
import { blendshapesOf } from './weights';
import { ARKIT_NAMES, LIVE_LINK_FACE_COLUMNS, VISEME_NAMES, arkitIndexOf } from './names';
import { avatarScene } from './avatar-mesh';

export const BLENDSHAPES_FORMAT = 'talking-face-blendshapes';

const round = (x: number) => Math.round(x * 1e5) / 1e5;
const rows = (values: Float32Array, width: number, frames: number) =>
  Array.from({ length: frames }, (_, f) => Array.from(values.subarray(f * width, (f + 1) * width), round));

/** JSON: names, fps, and per frame the 52 ARKit weights, the 15 visemes, and [yaw, pitch, roll] in radians. */
export function blendshapesJson(animation: Animation): string {
  const b = blendshapesOf(animation);
  const F = animation.frames;
  return JSON.stringify({
    format: BLENDSHAPES_FORMAT,
    version: 1,
    fps: animation.fps,
    frames: F,
    arkitNames: ARKIT_NAMES,
    visemeNames: VISEME_NAMES,
    headRotation: 'yaw, pitch, roll in radians; R = R_y(yaw) R_x(pitch) R_z(roll); +y up, the face towards +z',
    arkit: rows(b.arkit, ARKIT_NAMES.length, F),
    visemes: rows(b.visemes, VISEME_NAMES.length, F),
    head: rows(b.headRotation, 3, F),
  });
}

/** Live Link Face's timecode of frame f: HH:MM:SS:FF.fff, FF the frame within the second at `fps`, .fff a fraction of a frame. */
export function liveLinkTimecode(f: number, fps: number): string {
  const seconds = Math.floor(f / fps);
  const inSecond = f - seconds * fps;
  const frame = Math.floor(inSecond + 1e-9);
  const pad = (x: number, w = 2) => String(x).padStart(w, '0');
  return `${pad(Math.floor(seconds / 3600))}:${pad(Math.floor(seconds / 60) % 60)}:${pad(seconds % 60)}:${pad(frame)}.${pad(Math.round((inSecond - frame) * 1000) % 1000, 3)}`;
}

/** CSV in Live Link Face's layout, one row per frame at the animation's frame rate. */
export function liveLinkFaceCsv(animation: Animation): string {
  const b = blendshapesOf(animation);
  const A = ARKIT_NAMES.length;
  const order = LIVE_LINK_FACE_COLUMNS.slice(0, A).map((name) => arkitIndexOf(name));
  const lines = [['Timecode', 'BlendShapeCount', ...LIVE_LINK_FACE_COLUMNS].join(',')];
  const fixed = (x: number) => x.toFixed(6).replace(/\.?0+$/, '') || '0';
  for (let f = 0; f < animation.frames; f++) {
    const weights = order.map((k) => fixed(b.arkit[f * A + k]));
    const head = [0, 1, 2].map((k) => fixed(b.headRotation[f * 3 + k]));
    lines.push([liveLinkTimecode(f, animation.fps), LIVE_LINK_FACE_COLUMNS.length, ...weights, ...head, 0, 0, 0, 0, 0, 0].join(','));
  }
  return lines.join('\n') + '\n';
}

/** .glb: the template with ARKit-named morph targets, their weights animated per frame, the head bone turning. */
export async function blendshapesGlb(animation: Animation, template: FaceTemplate, basis: ArkitBasis): Promise<ArrayBuffer> {
  const b = blendshapesOf(animation);
  if (!template?.positions || !basis?.shapes) {
    throw new TypeError('blendshapesGlb(take, template, basis): give the engine\'s template and engine.avatarWeights.basis (docs/embedding.md)');
  }
  const { scene, mesh, head } = avatarScene(template, basis, { morphs: 'arkit', name: 'face' });
  const F = animation.frames;
  const times = Float32Array.from({ length: F }, (_, f) => f / animation.fps);
  const quats = poseQuaternions(animation);
  const clip = new THREE.AnimationClip('speech', Math.max(F - 1, 0) / animation.fps, [
    new THREE.NumberKeyframeTrack(`${mesh.name}.morphTargetInfluences`, times, b.arkit.slice(0, F * ARKIT_NAMES.length)),
    new THREE.QuaternionKeyframeTrack(`${head.name}.quaternion`, times, quats),
  ]);
  const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
  const bytes = (await new GLTFExporter().parseAsync(scene, { binary: true, animations: [clip] })) as ArrayBuffer;
  mesh.geometry.dispose();
  (mesh.material as THREE.Material).dispose();
  return bytes;
}

/** The head pose's rotation of each frame as a quaternion [x, y, z, w] (F x 4), from its axis-angle. */
export function poseQuaternions(animation: Animation): Float32Array {
  const F = animation.frames;
  const quats = new Float32Array(F * 4);
  const q = new THREE.Quaternion();
  const axis = new THREE.Vector3();
  for (let f = 0; f < F; f++) {
    const p = animation.pose.subarray(f * 6, f * 6 + 3);
    const angle = Math.hypot(p[0], p[1], p[2]);
    if (angle < 1e-9) q.identity();
    else q.setFromAxisAngle(axis.set(p[0] / angle, p[1] / angle, p[2] / angle), angle);
    q.toArray(quats, f * 4);
  }
  return quats;
}
