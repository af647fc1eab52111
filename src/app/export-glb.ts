/**
 * Export an animation as binary glTF (.glb) that standard viewers play, with the head pose as the
 * node's rotation and translation and the facial motion as morph targets, in one of two encodings:
 * - up to GLB_EXACT_FRAMES frames, exact: the neutral face as the mesh, one morph target per frame
 *   (that frame's I + O minus I) and a weights track that steps through them (one target on at a time);
 * - longer clips, compact: the mean face as the mesh and GLB_COMPONENTS morph targets, the strongest
 *   directions of the clip's motion (motion-basis.ts), with every frame's weights; the largest
 *   deviation from the exact frames is measured and reported. Eight is the number of simultaneous
 *   morph targets glTF asks every viewer to support, and the file grows by only 32 bytes a frame.
 * Also the raw per-frame vertices.
 */
import * as THREE from 'three';
import { GLTFExporter } from 'three/addons/exporters/GLTFExporter.js';
import type { Animation } from '../engine/engine';
import type { FaceTemplate } from '../template/face-template';
import { motionBasis } from './motion-basis';

/** Longest clip exported with one morph target per frame (its weights track is frames x frames). */
export const GLB_EXACT_FRAMES = 1800;
/** Morph targets in the compact encoding of longer clips. */
export const GLB_COMPONENTS = 8;

export interface GlbExport {
  bytes: ArrayBuffer;
  frames: number;
  encoding: 'per-frame' | 'components';
  morphTargets: number;
  /** Largest distance of any vertex from the exact animation, mm (0 for the per-frame encoding). */
  maxErrorMm: number;
}

export async function exportGlb(animation: Animation, template: FaceTemplate, unitsPerMm: number, name = 'talking-face'): Promise<GlbExport> {
  if (!animation.unposed) throw new Error('exportGlb: the animation has no unposed frames');
  const frames = animation.frames;
  if (frames < 1) throw new Error('exportGlb: the animation has no frames');
  const n = template.vertexCount;
  const dims = n * 3;
  const geometry = new THREE.BufferGeometry();
  const targets: THREE.BufferAttribute[] = [];
  let weights: Float32Array;
  let maxErrorMm = 0;
  const exact = frames <= GLB_EXACT_FRAMES;
  const D = new Float32Array(frames * dims); // per frame: I + O minus I
  for (let f = 0; f < frames; f++) for (let i = 0; i < dims; i++) D[f * dims + i] = animation.unposed[f * dims + i] - template.positions[i];
  if (exact) {
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(template.positions), 3));
    for (let f = 0; f < frames; f++) targets.push(new THREE.BufferAttribute(D.subarray(f * dims, (f + 1) * dims), 3));
    weights = new Float32Array(frames * frames);
    for (let f = 0; f < frames; f++) weights[f * frames + f] = 1;
  } else {
    const m = motionBasis(D, frames, dims, GLB_COMPONENTS);
    const base = new Float32Array(dims);
    for (let i = 0; i < dims; i++) base[i] = template.positions[i] + m.mean[i];
    geometry.setAttribute('position', new THREE.BufferAttribute(base, 3));
    for (let k = 0; k < m.components; k++) targets.push(new THREE.BufferAttribute(m.basis.subarray(k * dims, (k + 1) * dims), 3));
    weights = m.coefficients;
    maxErrorMm = m.maxError / unitsPerMm;
  }
  geometry.setIndex(new THREE.BufferAttribute(template.triangles, 1));
  geometry.morphAttributes.position = targets;
  geometry.morphTargetsRelative = true;
  geometry.computeVertexNormals();
  const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ color: 0xe0ac8e, roughness: 0.6, side: THREE.DoubleSide }));
  mesh.name = name;
  mesh.updateMorphTargets();
  const scene = new THREE.Scene();
  scene.add(mesh);

  const times = Float32Array.from({ length: frames }, (_, f) => f / animation.fps);
  const quats = new Float32Array(frames * 4);
  const moves = new Float32Array(frames * 3);
  const q = new THREE.Quaternion();
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
    new THREE.NumberKeyframeTrack(`${name}.morphTargetInfluences`, times, weights),
    new THREE.QuaternionKeyframeTrack(`${name}.quaternion`, times, quats),
    new THREE.VectorKeyframeTrack(`${name}.position`, times, moves),
  ]);
  const bytes = (await new GLTFExporter().parseAsync(scene, { binary: true, animations: [clip] })) as ArrayBuffer;
  geometry.dispose();
  (mesh.material as THREE.Material).dispose();
  return { bytes, frames, encoding: exact ? 'per-frame' : 'components', morphTargets: targets.length, maxErrorMm };
}

/** Re-load a .glb with three.js: how many morph targets, animation clips and their duration. */
export async function inspectGlb(bytes: ArrayBuffer): Promise<{ morphTargets: number; clips: number; duration: number; vertices: number }> {
  const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
  const gltf = await new GLTFLoader().parseAsync(bytes, '');
  let mesh: THREE.Mesh | null = null;
  gltf.scene.traverse((o) => {
    if (!mesh && (o as THREE.Mesh).isMesh) mesh = o as THREE.Mesh;
  });
  const m = mesh as THREE.Mesh | null;
  return {
    morphTargets: m?.geometry.morphAttributes.position?.length ?? 0,
    clips: gltf.animations.length,
    duration: gltf.animations[0]?.duration ?? 0,
    vertices: m?.geometry.getAttribute('position').count ?? 0,
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
