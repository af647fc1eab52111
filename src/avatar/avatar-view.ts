/**
 * Draws a user's glTF avatar (gltf-avatar.ts) with three.js and drives it from the engine's blend-shape output:
 * what <talking-face avatar="..."> shows instead of the template face. It implements the player's view
 * (src/player/player.ts): the player hands it each frame's ARKit weights, visemes and head rotation; the
 * template's vertices it is also handed are not the avatar's, so it ignores them.
 *
 * The caller owns the canvas. Nothing is allocated per frame.
 */
import * as THREE from 'three';
import { fitToCanvas, CanvasWatch } from '../render/canvas-size';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type { BlendshapeFrames } from './weights';
import { GltfAvatar, type AvatarBindOptions } from './gltf-avatar';
import { AvatarDriver } from './avatar-driver';
import { NO_WEBGL, softwareWebGL, webglAvailable } from '../render/software-gl';
import { fetchBody, StalledError } from '../model/fetch-body';

/** About a head's bounding radius in metres (glTF's unit). */
const HEAD_RADIUS = 0.15;

export class AvatarView {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera: THREE.PerspectiveCamera;
  readonly controls: OrbitControls;
  private readonly watch: CanvasWatch; // its size, the screen's pixel ratio, whether it is on screen, a context restored
  recording = false; // draw even while out of sight (a recording of the canvas needs its frames: player/record-video.ts)
  private needsRender = true;
  private frameHandle = 0;
  /** The blend from the rest to speech and the idle blinks: everything but the drawing. */
  readonly driver: AvatarDriver;
  /** A visitor who asked for reduced motion gets no idle blinks (face-view.ts holds its life still likewise). */
  private readonly reducedMotion = globalThis.matchMedia?.('(prefers-reduced-motion: reduce)') ?? null;

  constructor(private readonly canvas: HTMLCanvasElement, readonly avatar: GltfAvatar) {
    this.driver = new AvatarDriver(avatar, performance.now());
    if (!webglAvailable()) throw new Error(NO_WEBGL); // plainly, not three.js's "Error creating WebGL context"
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: !softwareWebGL(), alpha: false }); // render/software-gl.ts
    this.scene.background = new THREE.Color(0x1d2230);
    this.scene.add(avatar.gltf.scene);
    if (avatar.facing === '-z') avatar.gltf.scene.rotation.y += Math.PI; // its face towards the camera (it turns in its own axes)
    this.scene.add(new THREE.HemisphereLight(0xfff4ea, 0x39303a, 1.1));
    const key = new THREE.DirectionalLight(0xffffff, 2.0);
    key.position.set(0.6, 0.8, 1.5);
    this.scene.add(key);

    // Frame the face: the meshes the output drives (a full-body avatar's head mesh), seen from the front (+z).
    const box = new THREE.Box3();
    avatar.gltf.scene.updateMatrixWorld(true);
    avatar.gltf.scene.traverse((o) => {
      if ((o as THREE.Mesh).morphTargetInfluences?.length) box.expandByObject(o, true);
    });
    if (box.isEmpty()) box.setFromObject(avatar.gltf.scene);
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    if (avatar.head && sphere.radius > HEAD_RADIUS * 3) {
      // One mesh for the whole body: frame the head (glTF is in metres), just above its bone.
      avatar.head.getWorldPosition(sphere.center).y += HEAD_RADIUS / 2;
      sphere.radius = HEAD_RADIUS;
    }
    this.camera = new THREE.PerspectiveCamera(30, 1, sphere.radius / 20, sphere.radius * 40);
    this.camera.position.set(sphere.center.x, sphere.center.y, sphere.center.z + sphere.radius * 3.6);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.target.copy(sphere.center);
    this.controls.enableDamping = true;
    // Orbit and zoom only, and not into the head nor until it is a speck (a pinch on a phone has no other way back).
    [this.controls.enablePan, this.controls.minDistance, this.controls.maxDistance] = [false, 1.5 * sphere.radius, 10 * sphere.radius];
    this.controls.addEventListener('change', () => this.requestRender());
    this.controls.update();

    this.watch = new CanvasWatch(canvas, () => this.resize(), () => this.requestRender());
    this.resize();
    this.loop();
  }

  /** Fetch, parse and show the avatar at `url` (AvatarLoadError says what is wrong with it); `signal` stops the download. */
  static async load(canvas: HTMLCanvasElement, url: string, headBone?: string | null, options: AvatarBindOptions = {}, signal?: AbortSignal): Promise<AvatarView> {
    const res = await fetchBody(url, { signal }).catch((e: Error) => {
      if (signal?.aborted) throw e;
      const other = new URL(url, location.href).origin !== location.origin;
      const hint = other && !(e instanceof StalledError) ? ' (another origin: does it send CORS headers?)' : '';
      throw new Error(`could not fetch the avatar ${url}: ${e.message}${hint}`);
    });
    if (!res.ok) throw new Error(`could not fetch the avatar ${url}: HTTP ${res.status}`);
    return new AvatarView(canvas, await GltfAvatar.parse(res.bytes, url, headBone, options));
  }

  /** The speech weight now (0: the rest, 1: the frame given), as FaceView's. */
  get speechWeight(): number {
    return this.driver.speechWeight;
  }

  /** The template's vertices: not the avatar's mesh, so nothing to do (the weights drive it). */
  setVertices(): void {}

  /** The head pose: its rotation turns the head bone; the translation (mm of the template) is not applied. */
  setPose(rx: number, ry: number, rz: number): void {
    this.driver.setPose(rx, ry, rz);
    this.requestRender();
  }

  /** Frame `frame` of the blend-shape output onto the avatar's morph targets. */
  setBlendshapes(b: BlendshapeFrames, frame: number): void {
    this.driver.setBlendshapes(b, frame);
    this.requestRender();
  }

  /** The weights of the model's face at rest (engine.restArkit()), shown while nothing is spoken (AvatarDriver.setRest). */
  setRest(arkit: Float32Array): void {
    this.driver.setRest(arkit);
    this.requestRender();
  }

  /** Speech starts (blended in from the rest) or stops (back to rest): AvatarDriver.setSpeaking. */
  setSpeaking(on: boolean): void {
    this.driver.setSpeaking(on);
    this.requestRender();
  }

  /** Back to the avatar's own neutral face, at once. */
  reset(): void {
    this.driver.reset();
    this.requestRender();
  }

  requestRender(): void {
    this.needsRender = true;
  }

  dispose(): void {
    cancelAnimationFrame(this.frameHandle);
    this.watch.disconnect();
    this.controls.dispose();
    this.scene.traverse((o) => {
      const mesh = o as THREE.Mesh;
      if (!mesh.isMesh) return;
      mesh.geometry.dispose();
      for (const m of Array.isArray(mesh.material) ? mesh.material : [mesh.material]) m.dispose();
    });
    this.renderer.dispose();
    this.renderer.forceContextLoss(); // now, not at garbage collection: a page keeps 16 WebGL contexts at most
  }

  private loop = (): void => {
    this.frameHandle = requestAnimationFrame(this.loop);
    if (!this.watch.shown && !this.recording) return;
    if (this.controls.update()) this.needsRender = true;
    this.driver.blinking = !this.reducedMotion?.matches;
    if (this.driver.update(performance.now())) this.needsRender = true;
    if (!this.needsRender) return;
    this.needsRender = false;
    this.renderer.render(this.scene, this.camera);
  };

  private resize(): void {
    fitToCanvas(this.canvas, this.renderer, this.camera);
    this.requestRender();
  }
}
