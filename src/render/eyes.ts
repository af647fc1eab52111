/**
 * Eyeballs in the sockets behind the lids: a sclera with iris, limbus and pupil painted on it (a texture drawn in
 * code), under a clear coat that catches the lights as the cornea does (materials.ts), and gaze: each eye turns about its centre towards
 * a target in the head's frame. The lids are the face's own vertices, so the model's blinks (and the idle blinks,
 * eyelids.ts) close them over the eyes.
 *
 * Sizes come from each lid opening, so any template gets fitting eyes.
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';
import { eyeMaterial } from './materials';

/** Largest turn of the eyes from straight ahead (radians): people turn the head beyond about this. */
const MAX_TURN = 0.45;
const scratch = new THREE.Vector3();

export class Eyes {
  readonly left: THREE.Group;
  readonly right: THREE.Group;
  /** Eye centres in the head's frame (template units). */
  readonly centers: THREE.Vector3[];
  /** The balls' radii (template units). */
  readonly radii: number[] = [];

  constructor(template: FaceTemplate) {
    const material = eyeMaterial();
    const groups: THREE.Group[] = [];
    this.centers = [];
    for (const side of ['left', 'right'] as const) {
      const r = template.regions;
      const loop = [...r[`eye_${side}_upper`], ...r[`eye_${side}_lower`]];
      const box = new THREE.Box3();
      for (const v of loop) box.expandByPoint(scratch.fromArray(template.positions, 3 * v));
      const size = box.getSize(new THREE.Vector3());
      const center = box.getCenter(new THREE.Vector3());
      const radius = size.x * 0.62;
      const eye = new THREE.Group();
      eye.name = `eye_${side}`;
      eye.rotation.order = 'YXZ';
      const ballGeometry = new THREE.SphereGeometry(radius, 40, 24);
      ballGeometry.rotateX(Math.PI / 2); // the texture's pole (the iris) looks along +z
      const ball = new THREE.Mesh(ballGeometry, material);
      ball.name = `eyeball_${side}`;
      eye.add(ball);
      // The front of the ball sits just behind the deepest lid vertex, so lids close in front of it.
      eye.position.set(center.x, center.y - size.y * 0.08, box.max.z - radius * 1.02 - size.z * 0.12);
      this.centers.push(eye.position.clone());
      this.radii.push(radius);
      groups.push(eye);
    }
    [this.left, this.right] = groups;
  }

  /** Turn both eyes towards `target` (head frame) offset by (yaw, pitch) radians; turns are clamped. */
  lookAt(target: THREE.Vector3, yaw: number, pitch: number): void {
    for (const eye of [this.left, this.right]) {
      scratch.subVectors(target, eye.position);
      const y = Math.atan2(scratch.x, scratch.z) + yaw;
      const p = Math.atan2(scratch.y, Math.hypot(scratch.x, scratch.z)) + pitch;
      eye.rotation.y = Math.max(-MAX_TURN, Math.min(MAX_TURN, y));
      eye.rotation.x = -Math.max(-MAX_TURN, Math.min(MAX_TURN, p));
    }
  }
}
