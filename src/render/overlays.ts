/**
 * What the demo draws over the head or asks of it: the vertex under the pointer, and the paper's Fig. 1 pose arrows.
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';

/** The face vertex nearest the point under (clientX, clientY) on `skin` (the face's first `faceVertices`), or null. */
export function pickFaceVertex(canvas: HTMLCanvasElement, camera: THREE.Camera, skin: THREE.Mesh, faceVertices: number, clientX: number, clientY: number): number | null {
  const r = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((clientX - r.left) / r.width) * 2 - 1, -((clientY - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, camera);
  skin.geometry.computeBoundingSphere();
  skin.geometry.computeBoundingBox();
  const hit = ray.intersectObject(skin, false)[0];
  if (!hit?.face) return null;
  const local = skin.worldToLocal(hit.point.clone());
  const pos = skin.geometry.getAttribute('position') as THREE.BufferAttribute;
  let best: number | null = null, bestD = Infinity;
  for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
    if (v >= faceVertices) continue; // the shell or the mouth: not the model's face
    const d = local.distanceToSquared(new THREE.Vector3().fromBufferAttribute(pos, v));
    if (d < bestD) [best, bestD] = [v, d];
  }
  return best;
}

/**
 * The paper's Fig. 1 pose arrows: the nose-tip normal of the template (grey; the caller keeps it fixed in the scene)
 * and of the current frame (orange; the caller puts it on the posed head). Null if the template names no nose tip.
 */
export function poseArrows(template: FaceTemplate, skin: THREE.Mesh, length: number): { template: THREE.ArrowHelper; current: THREE.ArrowHelper } | null {
  const tip = template.regions.nose_tip?.[0];
  if (tip === undefined) return null;
  const origin = new THREE.Vector3().fromArray(template.positions, 3 * tip);
  const normal = new THREE.Vector3().fromBufferAttribute(skin.geometry.getAttribute('normal') as THREE.BufferAttribute, tip).normalize();
  const fixed = new THREE.ArrowHelper(normal, origin, length, 0xb0b6c4, length * 0.15, length * 0.07);
  const current = new THREE.ArrowHelper(normal, origin, length, 0xff8a3d, length * 0.15, length * 0.07);
  fixed.name = 'pose_arrow_template';
  current.name = 'pose_arrow_current';
  return { template: fixed, current };
}
