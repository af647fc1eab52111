/**
 * Export an animation as binary glTF (.glb) that standard viewers play, life-size (in metres): the whole head (render/head.ts: face,
 * skull and neck, eyes, teeth, tongue, the mouth's inside), with the head pose as the head node's rotation and
 * translation, the lower jaw's rotation (estimated from the face, render/jaw.ts), the tongue's raise and the eyes'
 * gaze as tracks, and the motion of the face (with the shell and mouth that follow it) as morph targets, in one of
 * two encodings:
 * - up to GLB_EXACT_FRAMES frames (10 s), exact: the neutral face as the mesh, one morph target per frame
 *   (that frame's I + O minus I) and a weights track that steps through them (one target on at a time); a viewer
 *   declares a uniform per target (three.js), and many GPUs allow about a thousand, so longer clips are not sent so;
 * - longer clips, compact: the mean face as the mesh and the GLB_COMPONENTS strongest directions of the clip's
 *   motion (motion-basis.ts), each as two morph targets, its positive and its negative side, with every frame's
 *   weights, all within 0..1 (importers such as Blender's keep a shape key's weight there); the largest deviation
 *   from the exact frames is measured and reported. At most eight targets are weighted at once, the number glTF
 *   asks every viewer to support, and the file grows by only 64 bytes a frame.
 * Also the raw per-frame vertices.
 */
import * as THREE from 'three';
import { GLTFExporter } from 'three/addons/exporters/GLTFExporter.js';
import type { Animation } from '../engine/engine';
import type { FaceTemplate } from '../template/face-template';
import { motionBasis } from './motion-basis';
import { slicer, type Slicing } from '../engine/frames';
import { Head } from '../render/head';
import { IdleMotion } from '../render/idle-motion';

/** Longest clip exported with one morph target per frame (its weights track is frames x frames). */
export const GLB_EXACT_FRAMES = 300;
/** Directions of motion in the compact encoding of longer clips (two morph targets each). */
export const GLB_COMPONENTS = 8;
/** Share of a long clip's export spent posing the head frame by frame (the rest finds its components; measured). */
const POSING_SHARE = 0.05;

export interface GlbExport {
  bytes: ArrayBuffer;
  frames: number;
  encoding: 'per-frame' | 'components';
  morphTargets: number;
  /** Largest distance of any vertex from the exact animation, mm (0 for the per-frame encoding). */
  maxErrorMm: number;
}

export async function exportGlb(animation: Animation, template: FaceTemplate, unitsPerMm: number, name = 'talking-face',
  work: Slicing = {}): Promise<GlbExport> {
  if (!animation.unposed) throw new Error('exportGlb: the animation has no unposed frames');
  const frames = animation.frames;
  if (frames < 1) throw new Error('exportGlb: the animation has no frames');
  // The whole head (render/head.ts): face + shell + mouth cavity in one buffer, posed frame by frame like the view.
  const head = new Head(template);
  const base = head.vertices.slice();
  const dims = base.length;
  const n3 = template.vertexCount * 3;
  const D = new Float32Array(frames * dims); // per frame: the joined buffer minus its template pose
  const jaw = new Float32Array(frames * 4);
  const tongue = new Float32Array(frames);
  const q = new THREE.Quaternion();
  const exact = frames <= GLB_EXACT_FRAMES;
  const posingShare = exact ? 1 : POSING_SHARE;
  // Seconds of the page's thread for a long take: in slices, with progress, stopped by the signal.
  const posing = slicer(frames, { signal: work.signal, onProgress: (d) => work.onProgress?.(posingShare * d) });
  for (let f = 0; f < frames; f++) {
    head.setFace(animation.unposed.subarray(f * n3, (f + 1) * n3), animation.tongue[f] ?? 0);
    const v = head.vertices;
    for (let i = 0; i < dims; i++) D[f * dims + i] = v[i] - base[i];
    head.jaw.quaternion.toArray(jaw, f * 4);
    tongue[f] = animation.tongue[f] ?? 0;
    await posing();
  }
  const geometry = head.skin.geometry;
  const targets: THREE.BufferAttribute[] = [];
  let weights: Float32Array;
  let maxErrorMm = 0;
  if (exact) {
    geometry.setAttribute('position', new THREE.BufferAttribute(base, 3));
    for (let f = 0; f < frames; f++) targets.push(named(D.subarray(f * dims, (f + 1) * dims), `frame_${f}`));
    weights = new Float32Array(frames * frames);
    for (let f = 0; f < frames; f++) weights[f * frames + f] = 1;
  } else {
    const m = await motionBasis(D, frames, dims, GLB_COMPONENTS, {
      signal: work.signal, onProgress: (d) => work.onProgress?.(posingShare + (1 - posingShare) * d),
    });
    const mean = new Float32Array(dims);
    for (let i = 0; i < dims; i++) mean[i] = base[i] + m.mean[i];
    geometry.setAttribute('position', new THREE.BufferAttribute(mean, 3));
    const K = m.components;
    weights = new Float32Array(frames * 2 * K);
    for (let k = 0; k < K; k++) {
      let most = 0, least = 0; // the side's largest coefficient is its target's full weight
      for (let f = 0; f < frames; f++) [most, least] = [Math.max(most, m.coefficients[f * K + k]), Math.min(least, m.coefficients[f * K + k])];
      const direction = m.basis.subarray(k * dims, (k + 1) * dims);
      targets.push(named(direction.map((v) => v * most), `motion_${k + 1}_plus`), named(direction.map((v) => v * least), `motion_${k + 1}_minus`));
      for (let f = 0; f < frames; f++) {
        const c = m.coefficients[f * K + k];
        weights[f * 2 * K + 2 * k] = c > 0 ? c / most : 0;
        weights[f * 2 * K + 2 * k + 1] = c < 0 ? c / least : 0;
      }
    }
    maxErrorMm = m.maxError / unitsPerMm;
  }
  geometry.morphAttributes.position = targets;
  geometry.morphTargetsRelative = true;
  geometry.computeVertexNormals();
  head.skin.updateMorphTargets();
  head.group.name = name;
  // glTF's unit is the metre: the head (in the template's units, centimetres for the MediaPipe face) under a root
  // that scales it, so that other tools show it life-size (its pose and motion stay in the head's own units inside).
  const root = new THREE.Group();
  root.name = `${name}_root`;
  root.scale.setScalar(1 / (unitsPerMm * 1000));
  root.add(head.group, head.body);
  const scene = new THREE.Scene();
  scene.add(root);

  const times = Float32Array.from({ length: frames }, (_, f) => f / animation.fps);
  const quats = new Float32Array(frames * 4);
  const moves = new Float32Array(frames * 3);
  const axis = new THREE.Vector3();
  for (let f = 0; f < frames; f++) {
    const p = animation.pose.subarray(f * 6, f * 6 + 6);
    const angle = Math.hypot(p[0], p[1], p[2]);
    if (angle < 1e-9) q.identity();
    else q.setFromAxisAngle(axis.set(p[0] / angle, p[1] / angle, p[2] / angle), angle);
    q.toArray(quats, f * 4);
    moves.set([p[3] * unitsPerMm, p[4] * unitsPerMm, p[5] * unitsPerMm], f * 3);
  }
  const clip = new THREE.AnimationClip('speech', Math.max(frames - 1, 0) / animation.fps, [
    new THREE.NumberKeyframeTrack('face.morphTargetInfluences', times, weights),
    new THREE.QuaternionKeyframeTrack(`${name}.quaternion`, times, quats),
    new THREE.VectorKeyframeTrack(`${name}.position`, times, moves),
    new THREE.QuaternionKeyframeTrack('jaw_lower.quaternion', times, jaw),
    new THREE.NumberKeyframeTrack('tongue.morphTargetInfluences', times, tongue),
    ...gazeTracks(head, times),
  ]);
  const bytes = (await new GLTFExporter().parseAsync(scene, { binary: true, animations: [clip] })) as ArrayBuffer;
  head.dispose();
  return { bytes, frames, encoding: exact ? 'per-frame' : 'components', morphTargets: targets.length, maxErrorMm };
}

/** The eyes' gaze per frame: on the viewer straight ahead, with the idle schedule's saccades and glances (idle-motion.ts). */
function gazeTracks(head: Head, times: Float32Array): THREE.KeyframeTrack[] {
  const idle = new IdleMotion(1);
  const ahead = new THREE.Vector3();
  const far = head.measures.top - head.measures.chin; // a viewer in front, far compared with the eyes' spacing
  const tracks: THREE.KeyframeTrack[] = [];
  const per = [new Float32Array(times.length * 4), new Float32Array(times.length * 4)];
  times.forEach((t, f) => {
    const s = idle.at(t);
    const eyes = head.eyes;
    ahead.set(eyes.centers[0].x / 2 + eyes.centers[1].x / 2, eyes.centers[0].y, eyes.centers[0].z + 10 * far);
    eyes.lookAt(ahead, s.yaw, s.pitch);
    eyes.left.quaternion.toArray(per[0], f * 4);
    eyes.right.quaternion.toArray(per[1], f * 4);
  });
  tracks.push(new THREE.QuaternionKeyframeTrack('eye_left.quaternion', times, per[0]), new THREE.QuaternionKeyframeTrack('eye_right.quaternion', times, per[1]));
  return tracks;
}

/** A morph target with its name (other tools show it: Blender's shape keys, three.js's morphTargetDictionary). */
function named(values: Float32Array, name: string): THREE.BufferAttribute {
  const a = new THREE.BufferAttribute(values, 3);
  a.name = name;
  return a;
}

/**
 * Re-load a .glb with three.js: the face mesh's morph targets and vertices, the animation clips, their duration,
 * the names of the head's parts, and which of them the clip animates.
 */
export async function inspectGlb(bytes: ArrayBuffer): Promise<{ morphTargets: number; targetNames: string[]; weightRange: [number, number];
  clips: number; duration: number; vertices: number; parts: string[]; animated: string[]; heightM: number }> {
  const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
  const gltf = await new GLTFLoader().parseAsync(bytes, '');
  let face: THREE.Mesh | null = null;
  const parts: string[] = [];
  gltf.scene.traverse((o) => {
    if (o.name) parts.push(o.name);
    if (!face && (o as THREE.Mesh).isMesh && (o as THREE.Mesh).geometry.morphAttributes.position?.length) face = o as THREE.Mesh;
  });
  const m = face as THREE.Mesh | null;
  const faceWeights = (gltf.animations[0]?.tracks ?? []).filter((t) => {
    const node = gltf.scene.getObjectByName(t.name.split('.')[0]);
    return t.name.endsWith('.morphTargetInfluences') && m && (node === m || node?.parent === m.parent);
  });
  const weightRange: [number, number] = [Infinity, -Infinity];
  for (const t of faceWeights) for (const w of t.values) [weightRange[0], weightRange[1]] = [Math.min(weightRange[0], w), Math.max(weightRange[1], w)];
  return {
    morphTargets: m?.geometry.morphAttributes.position?.length ?? 0,
    targetNames: Object.keys(m?.morphTargetDictionary ?? {}),
    /** The face's morph-target weights, least and most, over the clip. */
    weightRange,
    clips: gltf.animations.length,
    duration: gltf.animations[0]?.duration ?? 0,
    vertices: m?.geometry.getAttribute('position').count ?? 0,
    parts,
    /** The scene's height in glTF's unit, the metre (the head and shoulders). */
    heightM: new THREE.Box3().setFromObject(gltf.scene).getSize(new THREE.Vector3()).y,
    // The face's two primitives (skin, mouth) load as child meshes of the 'face' node, each with its morph track.
    animated: [...new Set((gltf.animations[0]?.tracks ?? []).map((t) => {
      const node = gltf.scene.getObjectByName(t.name.split('.')[0]);
      return node?.parent?.name === 'face' ? 'face' : t.name.split('.')[0];
    }))],
  };
}

/** The posed vertices, float32 little-endian, frames x N x 3, in the template's units. */
export function rawFrames(animation: Animation): Blob {
  return new Blob([animation.vertices.slice().buffer], { type: 'application/octet-stream' });
}

export function download(blob: Blob, filename: string): void {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = filename;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
}
