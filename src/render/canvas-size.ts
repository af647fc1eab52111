/** Size a renderer's drawing buffer and its camera's aspect to the canvas's displayed size (the face and avatar views). */
import type * as THREE from 'three';

export function fitToCanvas(canvas: HTMLCanvasElement, renderer: THREE.WebGLRenderer, camera: THREE.PerspectiveCamera): void {
  const w = Math.max(1, canvas.clientWidth);
  const h = Math.max(1, canvas.clientHeight);
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}
