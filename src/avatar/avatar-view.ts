/**
 * Draws a user's glTF avatar (gltf-avatar.ts) with three.js and drives it from the engine's blend-shape output:
 * what <talking-face avatar="..."> shows instead of the template face. It implements the player's view
 * (src/player/player.ts): the player hands it each frame's ARKit weights, visemes and head rotation; the
 * template's vertices it is also handed are not the avatar's, so it ignores them.
 *
 * The caller owns the canvas. Nothing is allocated per frame.
 */
import * as THREE from 'three';
import { fitToCanvas, OnScreen } from '../render/canvas-size';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type { BlendshapeFrames } from './weights';
import { ARKIT_NAMES, VISEME_NAMES } from './names';
import { GltfAvatar } from './gltf-avatar';
import { Blinks } from './blinks';
import { pixelRatio, softwareWebGL } from '../render/software-gl';
import { fetchBody, StalledError } from '../model/fetch-body';

/** About a head's bounding radius in metres (glTF's unit). */
const HEAD_RADIUS = 0.15;
/** Seconds speech takes to blend in from the rest, and back out to it (setSpeaking), as the template face's (face-view.ts). */
const BLEND_IN = 0.12, BLEND_OUT = 0.4;

export class AvatarView {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera: THREE.PerspectiveCamera;
  readonly controls: OrbitControls;
  private readonly resizeObserver: ResizeObserver;
  private readonly onScreen: OnScreen;
  recording = false; // draw even while out of sight (a recording of the canvas needs its frames: player/record-video.ts)
  private needsRender = true;
  private frameHandle = 0;
  private readonly blinks = new Blinks(performance.now());
  private blink = 0;
  /** A visitor who asked for reduced motion gets no idle blinks (face-view.ts holds its life still likewise). */
  private readonly reducedMotion = globalThis.matchMedia?.('(prefers-reduced-motion: reduce)') ?? null;
  /** The frame last given (weights, visemes, head rotation); how much of it is shown against the rest is `speech`. */
  private readonly shown = { arkit: new Float32Array(ARKIT_NAMES.length), visemes: new Float32Array(VISEME_NAMES.length), head: new Float32Array(3) };
  private readonly scaled = { arkit: new Float32Array(ARKIT_NAMES.length), visemes: new Float32Array(VISEME_NAMES.length) };
  /** The ARKit weights of the model's face at rest (setRest; 0 until given): what the avatar shows before and after speech. */
  private readonly rest = new Float32Array(ARKIT_NAMES.length);
  /** The weight of the frame given against the rest (0: the rest alone), ramping to `target` (setSpeaking). */
  private speech = 0;
  private target = 0;
  private lastTime = -1;

  constructor(private readonly canvas: HTMLCanvasElement, readonly avatar: GltfAvatar) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: !softwareWebGL(), alpha: false }); // render/software-gl.ts
    this.renderer.setPixelRatio(pixelRatio());
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
    // Orbit and zoom only, and not into the head nor until it is a speck (a pinch on a phone has no other way back).
    [this.controls.enablePan, this.controls.minDistance, this.controls.maxDistance] = [false, 1.5 * sphere.radius, 10 * sphere.radius];
    this.controls.addEventListener('change', () => this.requestRender());
    this.controls.update();

    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(canvas);
    this.onScreen = new OnScreen(canvas, () => this.requestRender());
    this.resize();
    this.loop();
  }

  /** Fetch, parse and show the avatar at `url` (AvatarLoadError says what is wrong with it). */
  static async load(canvas: HTMLCanvasElement, url: string, headBone?: string | null): Promise<AvatarView> {
    const res = await fetchBody(url).catch((e: Error) => {
      const other = new URL(url, location.href).origin !== location.origin;
      const hint = other && !(e instanceof StalledError) ? ' (another origin: does it send CORS headers?)' : '';
      throw new Error(`could not fetch the avatar ${url}: ${e.message}${hint}`);
    });
    if (!res.ok) throw new Error(`could not fetch the avatar ${url}: HTTP ${res.status}`);
    return new AvatarView(canvas, await GltfAvatar.parse(res.bytes, url, headBone));
  }

  /** The speech weight now (0: the rest, 1: the frame given), as FaceView's. */
  get speechWeight(): number {
    return this.speech;
  }

  /** The template's vertices: not the avatar's mesh, so nothing to do (the weights drive it). */
  setVertices(): void {}

  /** The head pose: its rotation turns the head bone; the translation (mm of the template) is not applied. */
  setPose(rx: number, ry: number, rz: number): void {
    const h = this.shown.head; // kept for the fade to rest; set in place: nothing is allocated per frame
    h[0] = rx;
    h[1] = ry;
    h[2] = rz;
    if (this.speech >= 1) this.avatar.setHeadRotation(rx, ry, rz);
    else this.blend();
    this.requestRender();
  }

  /** Frame `frame` of the blend-shape output onto the avatar's morph targets. */
  setBlendshapes(b: BlendshapeFrames, frame: number): void {
    this.shown.arkit.set(b.arkit.subarray(frame * ARKIT_NAMES.length, (frame + 1) * ARKIT_NAMES.length));
    this.shown.visemes.set(b.visemes.subarray(frame * VISEME_NAMES.length, (frame + 1) * VISEME_NAMES.length));
    if (this.speech >= 1) this.avatar.setWeights(b.arkit, frame * ARKIT_NAMES.length, b.visemes, frame * VISEME_NAMES.length);
    else this.blend();
    this.requestRender();
  }

  /**
   * The weights of the model's face at rest (engine.restArkit(): what frames of silence get, e.g. mouthRollLower about
   * 0.16): shown while nothing is spoken, so that the avatar does not move when speech starts or ends in a pause.
   */
  setRest(arkit: Float32Array): void {
    this.rest.set(arkit);
    if (this.speech > 0) return; // speaking: the rest shows once speech ends
    this.blend(); // shown now (speech 0: the rest alone)
  }

  /**
   * Speech starts (true: blended in from the rest over BLEND_IN seconds, so the head does not jump at its first frame)
   * or stops (false: playback stopped or ended, the microphone closed, a pause live): the face goes back to rest and
   * the head to neutral over BLEND_OUT seconds, instead of holding the frame last shown (mid-word, when stopped).
   */
  setSpeaking(on: boolean): void {
    if (this.target === (on ? 1 : 0)) return;
    this.target = on ? 1 : 0;
    this.lastTime = -1;
    this.requestRender();
  }

  /** Back to the avatar's own neutral face, at once. */
  reset(): void {
    [this.speech, this.target] = [0, 0];
    this.avatar.reset();
    this.requestRender();
  }

  requestRender(): void {
    this.needsRender = true;
  }

  dispose(): void {
    cancelAnimationFrame(this.frameHandle);
    this.resizeObserver.disconnect();
    this.onScreen.disconnect();
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
    if (!this.onScreen.shown && !this.recording) return;
    if (this.controls.update()) this.needsRender = true;
    if (this.speech !== this.target) this.ramp(performance.now() / 1000);
    const blink = this.avatar.canBlink && !this.reducedMotion?.matches ? this.blinks.at(performance.now()) : 0;
    if (blink !== this.blink) {
      this.blink = blink;
      this.avatar.setIdleBlink(blink);
      this.needsRender = true;
    }
    if (!this.needsRender) return;
    this.needsRender = false;
    this.renderer.render(this.scene, this.camera);
  };

  /** One step of `speech` towards `target`. */
  private ramp(seconds: number): void {
    const dt = this.lastTime < 0 ? 0 : seconds - this.lastTime;
    this.lastTime = seconds;
    const up = this.target > this.speech;
    this.speech = up ? Math.min(1, this.speech + dt / BLEND_IN) : Math.max(0, this.speech - dt / BLEND_OUT);
    this.blend();
  }

  /** The frame's weights and head rotation weighed by `speech` against the rest's (visemes: against viseme_sil). */
  private blend(): void {
    const s = this.speech, { arkit, visemes } = this.scaled;
    for (let k = 0; k < arkit.length; k++) arkit[k] = s * this.shown.arkit[k] + (1 - s) * this.rest[k];
    for (let k = 0; k < visemes.length; k++) visemes[k] = s * this.shown.visemes[k];
    visemes[0] += 1 - s; // viseme_sil
    this.avatar.setWeights(arkit, 0, visemes, 0);
    const h = this.shown.head;
    this.avatar.setHeadRotation(s * h[0], s * h[1], s * h[2]);
    this.needsRender = true;
  }

  private resize(): void {
    fitToCanvas(this.canvas, this.renderer, this.camera);
    this.requestRender();
  }
}
