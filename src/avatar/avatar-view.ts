/**
 * Draws a user's glTF avatar (gltf-avatar.ts) with three.js and drives it from the engine's blend-shape output:
 * what <talking-face avatar="..."> shows instead of the template face. It implements the player's view
 * (src/player/player.ts): the player hands it each frame's ARKit weights, visemes and head rotation; the
 * template's vertices it is also handed are not the avatar's, so it ignores them.
 *
 * The caller owns the canvas. Nothing is allocated per frame.
 */
import * as THREE from 'three';
import { fitToCanvas } from '../render/canvas-size';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type { BlendshapeFrames } from './weights';
import { ARKIT_NAMES, VISEME_NAMES } from './names';
import { GltfAvatar } from './gltf-avatar';
import { Blinks } from './blinks';
import { softwareWebGL } from '../render/software-gl';

/** About a head's bounding radius in metres (glTF's unit). */
const HEAD_RADIUS = 0.15;

export class AvatarView {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera: THREE.PerspectiveCamera;
  readonly controls: OrbitControls;
  private readonly resizeObserver: ResizeObserver;
  private needsRender = true;
  private frameHandle = 0;
  private readonly blinks = new Blinks(performance.now());
  private blink = 0;

  constructor(private readonly canvas: HTMLCanvasElement, readonly avatar: GltfAvatar) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: !softwareWebGL(), alpha: false }); // render/software-gl.ts
    this.renderer.setPixelRatio(Math.min(globalThis.devicePixelRatio ?? 1, 2));
    this.scene.background = new THREE.Color(0x1d2230);
    this.scene.add(avatar.gltf.scene);
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
    this.controls.addEventListener('change', () => this.requestRender());
    this.controls.update();

    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(canvas);
    this.resize();
    this.loop();
  }

  /** Fetch, parse and show the avatar at `url` (AvatarLoadError says what is wrong with it). */
  static async load(canvas: HTMLCanvasElement, url: string, headBone?: string | null): Promise<AvatarView> {
    const res = await fetch(url).catch((e: Error) => {
      throw new Error(`could not fetch the avatar ${url}: ${e.message}`);
    });
    if (!res.ok) throw new Error(`could not fetch the avatar ${url}: HTTP ${res.status}`);
    return new AvatarView(canvas, await GltfAvatar.parse(await res.arrayBuffer(), url, headBone));
  }

  /** The template's vertices: not the avatar's mesh, so nothing to do (the weights drive it). */
  setVertices(): void {}

  /** The head pose: its rotation turns the head bone; the translation (mm of the template) is not applied. */
  setPose(rx: number, ry: number, rz: number): void {
    this.avatar.setHeadRotation(rx, ry, rz);
    this.requestRender();
  }

  /** Frame `frame` of the blend-shape output onto the avatar's morph targets. */
  setBlendshapes(b: BlendshapeFrames, frame: number): void {
    this.avatar.setWeights(b.arkit, frame * ARKIT_NAMES.length, b.visemes, frame * VISEME_NAMES.length);
    this.requestRender();
  }

  /** Back to the avatar's own neutral face. */
  reset(): void {
    this.avatar.reset();
    this.requestRender();
  }

  requestRender(): void {
    this.needsRender = true;
  }

  dispose(): void {
    cancelAnimationFrame(this.frameHandle);
    this.resizeObserver.disconnect();
    this.controls.dispose();
    this.scene.traverse((o) => {
      const mesh = o as THREE.Mesh;
      if (!mesh.isMesh) return;
      mesh.geometry.dispose();
      for (const m of Array.isArray(mesh.material) ? mesh.material : [mesh.material]) m.dispose();
    });
    this.renderer.dispose();
  }

  private loop = (): void => {
    this.frameHandle = requestAnimationFrame(this.loop);
    if (this.controls.update()) this.needsRender = true;
    const blink = this.avatar.canBlink ? this.blinks.at(performance.now()) : 0;
    if (blink !== this.blink) {
      this.blink = blink;
      this.avatar.setIdleBlink(blink);
      this.needsRender = true;
    }
    if (!this.needsRender) return;
    this.needsRender = false;
    this.renderer.render(this.scene, this.camera);
  };

  private resize(): void {
    fitToCanvas(this.canvas, this.renderer, this.camera);
    this.requestRender();
  }
}
