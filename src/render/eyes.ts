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

/**
 * The eye's texture: the sphere's pole (top row) is the pupil's centre, rows go back over the ball by polar angle.
 * Pupil, a radially streaked iris darkening to its limbus, and the sclera, faintly pink towards the back.
 */
/** Polar angles (degrees from the pupil's centre) of the pupil's and the iris's edges: an 11.7 mm iris on a 12 mm ball. */
const PUPIL_EDGE = 11, IRIS_EDGE = 29.2;

export function eyeTexture(): THREE.Texture {
  const w = 256, h = 128;
  const canvas = typeof document !== 'undefined' ? Object.assign(document.createElement('canvas'), { width: w, height: h }) : new OffscreenCanvas(w, h);
  const ctx = canvas.getContext('2d') as CanvasRenderingContext2D;
  const image = ctx.createImageData(w, h);
  const deg = (row: number) => ((row + 0.5) / h) * 180; // polar angle from the pupil's centre
  for (let y = 0; y < h; y++) {
    const a = deg(y);
    for (let x = 0; x < w; x++) {
      const streak = 0.5 + 0.5 * Math.sin(x * 0.9) * Math.sin(x * 0.37 + 1.3);
      let c: number[];
      if (a < PUPIL_EDGE) c = [8, 6, 6];
      else if (a < IRIS_EDGE) {
        const t = (a - PUPIL_EDGE) / (IRIS_EDGE - PUPIL_EDGE);
        const base = [70 + 48 * t, 52 + 40 * t, 34 + 20 * t]; // brown, lighter outwards
        c = base.map((v) => v * (0.7 + 0.5 * streak) * (a > IRIS_EDGE - 3.5 ? 0.55 : 1)); // the limbus
      } else {
        const t = Math.min(1, (a - IRIS_EDGE) / 70);
        c = [236 - 8 * t, 232 - 28 * t, 226 - 34 * t];
      }
      const i = 4 * (y * w + x);
      image.data.set([c[0], c[1], c[2], 255], i);
    }
  }
  ctx.putImageData(image, 0, 0);
  const texture = new THREE.CanvasTexture(canvas as HTMLCanvasElement);
  texture.colorSpace = THREE.SRGBColorSpace;
  texture.anisotropy = 4;
  return texture;
}
