/**
 * Draws a face template (and later, posed frames y_i = T_p,i (I + O_i)) with three.js:
 * a shaded skin surface, two eyeballs behind the lid openings and a dark
 * inner-mouth backing so parted lips never show the void behind the mask.
 *
 * The caller owns the canvas. `setVertices` updates the position attribute in
 * place; nothing is allocated per frame.
 */
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { lipMask, type FaceTemplate } from '../template/face-template';

const SKIN_COLOR = 0xe0ac8e;
const EYE_COLOR = 0xf4f1ec;
const IRIS_COLOR = 0x3b2a1e;
const MOUTH_COLOR = 0x2a0a0c;
const LIP_COLOR = 0xb8676a;
const scratchOffset = new THREE.Vector3();
const scratchSpherical = new THREE.Spherical();
const scratchAxis = new THREE.Vector3();

export class FaceView {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera: THREE.PerspectiveCamera;
  readonly controls: OrbitControls;
  /** Everything that moves with the head pose T_p. */
  readonly head = new THREE.Group();
  private readonly face: THREE.Mesh<THREE.BufferGeometry, THREE.MeshStandardMaterial>;
  private readonly positions: THREE.BufferAttribute;
  private readonly resizeObserver: ResizeObserver;
  private needsRender = true;
  private frameHandle = 0;
  private readonly skin: Float32Array;
  private arrows: { template: THREE.ArrowHelper; current: THREE.ArrowHelper } | null = null;

  constructor(
    private readonly canvas: HTMLCanvasElement,
    readonly template: FaceTemplate,
  ) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, alpha: false });
    this.renderer.setPixelRatio(Math.min(globalThis.devicePixelRatio ?? 1, 2));
    this.scene.background = new THREE.Color(0x1d2230);

    const geometry = new THREE.BufferGeometry();
    this.positions = new THREE.BufferAttribute(new Float32Array(template.positions), 3);
    this.positions.setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute('position', this.positions);
    if (template.uvs) geometry.setAttribute('uv', new THREE.BufferAttribute(template.uvs, 2));
    geometry.setIndex(new THREE.BufferAttribute(template.triangles, 1));
    this.skin = skinColors(template);
    geometry.setAttribute('color', new THREE.BufferAttribute(this.skin.slice(), 3));
    geometry.computeVertexNormals();
    geometry.computeBoundingSphere();
    this.face = new THREE.Mesh(
      geometry,
      new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.62, metalness: 0, side: THREE.DoubleSide }),
    );
    this.face.name = 'face';
    this.head.add(this.face);
    this.addEyes();
    this.addMouthBacking();
    this.scene.add(this.head);

    this.scene.add(new THREE.HemisphereLight(0xfff4ea, 0x39303a, 1.1));
    const key = new THREE.DirectionalLight(0xffffff, 2.0);
    key.position.set(0.6, 0.8, 1.5);
    this.scene.add(key);
    const rim = new THREE.DirectionalLight(0x9ab4ff, 0.6);
    rim.position.set(-1, 0.4, -0.8);
    this.scene.add(rim);

    const sphere = geometry.boundingSphere!;
    this.camera = new THREE.PerspectiveCamera(30, 1, sphere.radius / 20, sphere.radius * 40);
    this.camera.position.set(sphere.center.x, sphere.center.y, sphere.center.z + sphere.radius * 3.6);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.target.copy(sphere.center);
    this.controls.enableDamping = true;
    this.controls.addEventListener('change', () => this.requestRender());
    this.controls.update();

    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(canvas);
    this.resize();
    this.loop();
  }

  /** Replace the face's vertices (N x 3, template units) in place. */
  /** The vertices drawn now (template units), read-only. */
  get shownVertices(): Float32Array {
    return this.positions.array as Float32Array;
  }

  setVertices(vertices: Float32Array): void {
    if (vertices.length !== this.positions.array.length) {
      throw new Error(`setVertices: expected ${this.positions.array.length / 3} vertices, got ${vertices.length / 3}`);
    }
    (this.positions.array as Float32Array).set(vertices);
    this.positions.needsUpdate = true;
    this.face.geometry.computeVertexNormals();
    this.requestRender();
  }

  /** Head pose y = R x + t: axis-angle (radians) and translation (template units), applied to face, eyes and mouth. */
  setPose(rx: number, ry: number, rz: number, tx: number, ty: number, tz: number): void {
    const angle = Math.hypot(rx, ry, rz);
    if (angle < 1e-9) this.head.quaternion.identity();
    else this.head.quaternion.setFromAxisAngle(scratchAxis.set(rx / angle, ry / angle, rz / angle), angle);
    this.head.position.set(tx, ty, tz);
    this.requestRender();
  }

  requestRender(): void {
    this.needsRender = true;
  }

  /** Turn the camera around the face (radians: left-right, up-down), as a drag would: the keyboard's orbit. */
  orbit(azimuth: number, polar: number): void {
    const offset = scratchOffset.copy(this.camera.position).sub(this.controls.target);
    scratchSpherical.setFromVector3(offset);
    scratchSpherical.theta += azimuth;
    scratchSpherical.phi = Math.min(Math.PI - 0.05, Math.max(0.05, scratchSpherical.phi + polar));
    this.camera.position.copy(this.controls.target).add(offset.setFromSpherical(scratchSpherical));
    this.camera.lookAt(this.controls.target);
    this.controls.update();
    this.requestRender();
  }

  /** Move the camera towards the face (factor < 1) or away from it (> 1), as the scroll wheel would. */
  zoom(factor: number): void {
    const offset = scratchOffset.copy(this.camera.position).sub(this.controls.target);
    const distance = Math.min(this.controls.maxDistance, Math.max(this.controls.minDistance, offset.length() * factor));
    this.camera.position.copy(this.controls.target).add(offset.setLength(distance));
    this.controls.update();
    this.requestRender();
  }

  /**
   * Paint a per-vertex scalar on the face (0 -> dark blue, `max` -> red, through cyan, green and yellow),
   * e.g. an error in mm or an attention weight; null restores the skin colours.
   */
  setColorMap(values: ArrayLike<number> | null, max = 1): void {
    const color = this.face.geometry.getAttribute('color') as THREE.BufferAttribute;
    const c = color.array as Float32Array;
    if (!values) c.set(this.skin);
    else {
      if (values.length !== this.template.vertexCount) throw new Error(`setColorMap: expected ${this.template.vertexCount} values, got ${values.length}`);
      for (let v = 0; v < values.length; v++) heat(Math.min(1, Math.max(0, values[v] / (max || 1))), c, 3 * v);
    }
    color.needsUpdate = true;
    this.requestRender();
  }

  /** The vertex nearest the point under (clientX, clientY) on the face, or null if the face is not there. */
  pickVertex(clientX: number, clientY: number): number | null {
    const r = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - r.left) / r.width) * 2 - 1, -((clientY - r.top) / r.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    this.face.geometry.computeBoundingSphere();
    const hit = ray.intersectObject(this.face, false)[0];
    if (!hit?.face) return null;
    const local = this.face.worldToLocal(hit.point.clone());
    let best = hit.face.a, bestD = Infinity;
    for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
      const d = local.distanceToSquared(new THREE.Vector3().fromBufferAttribute(this.positions, v));
      if (d < bestD) [best, bestD] = [v, d];
    }
    return best;
  }

  /**
   * The paper's Fig. 1 pose arrows: the nose-tip normal of the template (grey, fixed) and of the current
   * frame (orange, moves with the head pose).
   */
  showPoseArrows(on: boolean): void {
    if (on && !this.arrows) {
      const tip = this.template.regions.nose_tip?.[0];
      if (tip === undefined) return;
      const geometry = this.face.geometry;
      const origin = new THREE.Vector3().fromBufferAttribute(this.positions, tip);
      const normal = new THREE.Vector3().fromBufferAttribute(geometry.getAttribute('normal') as THREE.BufferAttribute, tip).normalize();
      const length = geometry.boundingSphere!.radius * 0.9;
      const template = new THREE.ArrowHelper(normal, origin, length, 0xb0b6c4, length * 0.15, length * 0.07);
      const current = new THREE.ArrowHelper(normal, origin, length, 0xff8a3d, length * 0.15, length * 0.07);
      template.name = 'pose_arrow_template';
      current.name = 'pose_arrow_current';
      this.scene.add(template);
      this.head.add(current);
      this.arrows = { template, current };
    } else if (!on && this.arrows) {
      this.scene.remove(this.arrows.template);
      this.head.remove(this.arrows.current);
      this.arrows = null;
    }
    this.requestRender();
  }

  dispose(): void {
    cancelAnimationFrame(this.frameHandle);
    this.resizeObserver.disconnect();
    this.controls.dispose();
    this.scene.traverse((o) => {
      if (o instanceof THREE.Mesh) {
        o.geometry.dispose();
        (o.material as THREE.Material).dispose();
      }
    });
    this.renderer.dispose();
  }

  private loop = (): void => {
    this.frameHandle = requestAnimationFrame(this.loop);
    // Damping keeps moving the camera for a few frames after the pointer stops.
    if (this.controls.update()) this.needsRender = true;
    if (!this.needsRender) return;
    this.needsRender = false;
    this.renderer.render(this.scene, this.camera);
  };

  private resize(): void {
    const w = Math.max(1, this.canvas.clientWidth);
    const h = Math.max(1, this.canvas.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  /** An eyeball behind each lid opening, sized from the opening so any template gets fitting eyes. */
  private addEyes(): void {
    const r = this.template.regions;
    for (const side of ['left', 'right'] as const) {
      const loop = [...r[`eye_${side}_upper`], ...r[`eye_${side}_lower`]];
      const { center, size, maxZ } = this.bounds(loop);
      const radius = size.x * 0.62;
      const eye = new THREE.Group();
      eye.name = `eye_${side}`;
      const ball = new THREE.Mesh(new THREE.SphereGeometry(radius, 32, 16), new THREE.MeshStandardMaterial({ color: EYE_COLOR, roughness: 0.25 }));
      const iris = new THREE.Mesh(
        new THREE.CircleGeometry(radius * 0.34, 32),
        new THREE.MeshStandardMaterial({ color: IRIS_COLOR, roughness: 0.3 }),
      );
      iris.position.z = radius * 1.001;
      eye.add(ball, iris);
      // The front of the ball sits just behind the deepest lid vertex.
      eye.position.set(center.x, center.y, maxZ - radius - size.z * 0.15);
      this.head.add(eye);
    }
  }

  /** A dark ellipsoid behind the inner lips: what an open mouth shows instead of the mask's empty back. */
  private addMouthBacking(): void {
    const r = this.template.regions;
    const { center, size } = this.bounds([...r.lips_inner_upper, ...r.lips_inner_lower]);
    const outer = this.bounds(Array.from(r.lips_outer));
    const mouth = new THREE.Mesh(new THREE.SphereGeometry(1, 32, 16), new THREE.MeshStandardMaterial({ color: MOUTH_COLOR, roughness: 0.9 }));
    mouth.name = 'mouth_backing';
    const halfWidth = size.x * 0.5;
    mouth.scale.set(halfWidth * 0.95, outer.size.y * 0.9, halfWidth * 0.8);
    mouth.position.set(center.x, center.y - outer.size.y * 0.15, outer.minZ - halfWidth * 0.35);
    this.head.add(mouth);
  }

  private bounds(indices: ArrayLike<number>): { center: THREE.Vector3; size: THREE.Vector3; maxZ: number; minZ: number } {
    const box = new THREE.Box3();
    const p = new THREE.Vector3();
    const pos = this.template.positions;
    for (let i = 0; i < indices.length; i++) box.expandByPoint(p.fromArray(pos, 3 * indices[i]));
    return { center: box.getCenter(new THREE.Vector3()), size: box.getSize(new THREE.Vector3()), maxZ: box.max.z, minZ: box.min.z };
  }
}

/**
 * Per-vertex colours: skin, with the lips tinted. The lip surface is found by
 * flooding the 1-ring graph from the inner-lip contour outward and stopping at
 * the outer-lip contour, so it works for any template with those regions.
 */
/** A blue -> cyan -> green -> yellow -> red ramp at t in [0, 1], written to out[at..at+3). */
function heat(t: number, out: Float32Array, at: number): void {
  const stops = [[0.12, 0.16, 0.45], [0.1, 0.65, 0.85], [0.25, 0.8, 0.3], [0.95, 0.85, 0.2], [0.85, 0.15, 0.12]];
  const x = t * (stops.length - 1);
  const k = Math.min(stops.length - 2, Math.floor(x));
  const f = x - k;
  for (let i = 0; i < 3; i++) out[at + i] = stops[k][i] * (1 - f) + stops[k + 1][i] * f;
}

function skinColors(t: FaceTemplate): Float32Array {
  const skin = new THREE.Color(SKIN_COLOR);
  const lip = new THREE.Color(LIP_COLOR);
  const colors = new Float32Array(t.vertexCount * 3);
  for (let v = 0; v < t.vertexCount; v++) skin.toArray(colors, 3 * v);
  const isLip = lipMask(t);
  for (let v = 0; v < t.vertexCount; v++) if (isLip[v]) lip.toArray(colors, 3 * v);
  return colors;
}
