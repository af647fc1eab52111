/**
 * The camera by keyboard, for every view (the demo's face, the element's face or avatar): arrow keys orbit and + / -
 * zoom, as a drag and the scroll wheel do with OrbitControls. Nothing is allocated per key press.
 */
import * as THREE from 'three';
import type { OrbitControls } from 'three/addons/controls/OrbitControls.js';

/** Radians per arrow key press, and the zoom factor per + press. */
export const ORBIT_STEP = Math.PI / 24;
export const ZOOM_STEP = 0.85;

/** What a canvas's label says of these keys. */
export const CAMERA_KEYS_TEXT = 'Arrow keys orbit, plus and minus zoom (or drag and scroll)';

const ORBIT: Record<string, [number, number]> = {
  ArrowLeft: [ORBIT_STEP, 0], ArrowRight: [-ORBIT_STEP, 0], ArrowUp: [0, ORBIT_STEP], ArrowDown: [0, -ORBIT_STEP],
};
const ZOOM: Record<string, number> = { '+': ZOOM_STEP, '=': ZOOM_STEP, '-': 1 / ZOOM_STEP, _: 1 / ZOOM_STEP };

const offset = new THREE.Vector3();
const spherical = new THREE.Spherical();

/** A view whose camera the keys move. */
export interface Orbitable {
  readonly camera: THREE.Camera;
  readonly controls: OrbitControls;
  requestRender(): void;
}

/** Turn the camera around its target (radians: left-right, up-down), as a drag would. */
export function orbitCamera(v: Orbitable, azimuth: number, polar: number): void {
  offset.copy(v.camera.position).sub(v.controls.target);
  spherical.setFromVector3(offset);
  spherical.theta += azimuth;
  spherical.phi = Math.min(Math.PI - 0.05, Math.max(0.05, spherical.phi + polar));
  v.camera.position.copy(v.controls.target).add(offset.setFromSpherical(spherical));
  v.camera.lookAt(v.controls.target);
  v.controls.update();
  v.requestRender();
}

/** Move the camera towards its target (factor < 1) or away (> 1), within the controls' distances, as scrolling would. */
export function zoomCamera(v: Orbitable, factor: number): void {
  offset.copy(v.camera.position).sub(v.controls.target);
  const distance = Math.min(v.controls.maxDistance, Math.max(v.controls.minDistance, offset.length() * factor));
  v.camera.position.copy(v.controls.target).add(offset.setLength(distance));
  v.controls.update();
  v.requestRender();
}

/** Apply a camera key to `view`: true (and the key's default prevented) if `ev` was one. */
export function cameraKey(ev: KeyboardEvent, view: Orbitable | null): boolean {
  if (ev.ctrlKey || ev.metaKey || ev.altKey || !view) return false;
  if (ev.key in ORBIT) orbitCamera(view, ...ORBIT[ev.key]);
  else if (ev.key in ZOOM) zoomCamera(view, ZOOM[ev.key]);
  else return false;
  ev.preventDefault();
  return true;
}
