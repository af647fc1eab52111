/**
 * Draws a face template as a whole head (head.ts: the face the model animates inside a generated skull and neck,
 * eyes, teeth, tongue, a mouth) with three.js, and keeps it alive: between words it shows the model's rest face,
 * breathes, blinks and moves its eyes (idle-motion.ts); speech blends in and out of that rest without a pop.
 *
 * What is drawn each frame: shown = rest + s (frame - rest) + (1 - s + s o) b B, where `frame` is the last face given
 * to setVertices, `rest` the model's rest face (setRestFace; the frame itself until one is given), s the speech weight
 * (ramped towards 1 by setSpeaking(true), towards 0 by setSpeaking(false)), b the idle blink, B the blink field and
 * o how open the frame's lids are against the rest's, 0 to 1 (eyelids.ts). The head pose is scaled by s the same
 * way, so the head comes back to rest too.
 *
 * The caller owns the canvas. Nothing is allocated per frame.
 */
import * as THREE from 'three';
import { fitToCanvas, CanvasWatch } from './canvas-size';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type { FaceTemplate } from '../template/face-template';
import { Head } from './head';
import { blinkField, lidOpening, lidPairs } from './eyelids';
import { IdleMotion, type IdleState } from './idle-motion';
import { heat, lightScene } from './materials';
import { shareTongueProgram } from './mouth-interior';
import { pickFaceVertex, poseArrows } from './overlays';
import { NO_WEBGL, softwareWebGL, webglAvailable } from './software-gl';

export interface FaceViewOptions {
  /** Breathing, blinks and eye movements (default true). Off for a view that must show exactly what it is given. */
  life?: boolean;
  /** Seed of the idle motion's schedule (default 1). */
  seed?: number;
  /**
   * Hold the life still until setLifePaused(false) (default false). The demo starts so while the model loads:
   * without a GPU (SwiftShader, software) every idle frame is drawn on the CPU the model's sessions are created
   * on, and drawing them made the model ready 1.5 s later (npm run bench, first load).
   */
  lifePaused?: boolean;
  /** Multisampled edges (default: on, unless WebGL is software here: software-gl.ts says why). */
  antialias?: boolean;
}

/** Seconds for speech to blend in, and back out to the rest face. */
const BLEND_IN = 0.12, BLEND_OUT = 0.4;
const scratchAxis = new THREE.Vector3(), eyeTarget = new THREE.Vector3();
const scratchQ = new THREE.Quaternion();

export class FaceView {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera: THREE.PerspectiveCamera;
  readonly controls: OrbitControls;
  /** The whole head's parts (head.ts). */
  readonly model: Head;
  /** Everything that moves with the head pose T_p. */
  readonly head: THREE.Group;
  /** The last idle state drawn (null without life, and while it is held still: the eyes open and ahead, at rest). */
  idleState: IdleState | null = null;
  private readonly idle: IdleMotion | null;
  private lifePaused: boolean;
  private readonly reducedMotion = globalThis.matchMedia?.('(prefers-reduced-motion: reduce)') ?? null;
  private readonly blink: Float32Array;
  private readonly lids: Uint32Array; // lidPairs; the rest face's opening, what a frame's lids are measured against:
  private restOpening = 0;
  private readonly shown: Float32Array;
  private readonly frame: Float32Array;
  private rest: Float32Array | null = null;
  private hasFrame = false;
  private speech = 1;
  private speechTarget = 1;
  private tongue = 0;
  recording = false; // draw even while out of sight (a recording of the canvas needs its frames: player/record-video.ts)
  private readonly pose = new Float32Array(6);
  private readonly watch: CanvasWatch; // its size, the screen's pixel ratio, whether it is on screen, a context restored
  private needsRender = true;
  private frameHandle = 0;
  private lastTime = -1;
  private readonly faceRadius: number;
  private readonly frameSize: { height: number; width: number };
  private readonly environment: THREE.Texture;
  private readonly bodyHeight: number;
  private arrows: { template: THREE.ArrowHelper; current: THREE.ArrowHelper } | null = null;

  constructor(
    private readonly canvas: HTMLCanvasElement,
    readonly template: FaceTemplate,
    options: FaceViewOptions = {},
  ) {
    if (!webglAvailable()) throw new Error(NO_WEBGL); // plainly, not three.js's "Error creating WebGL context"
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: options.antialias ?? !softwareWebGL(), alpha: false });
    this.model = new Head(template);
    shareTongueProgram(this.model);
    this.head = this.model.group;
    this.scene.add(this.head, this.model.body);
    this.environment = lightScene(this.scene, this.renderer);
    this.shown = new Float32Array(template.positions);
    this.frame = new Float32Array(template.positions);
    this.blink = blinkField(template);
    this.lids = lidPairs(template);
    this.idle = options.life === false ? null : new IdleMotion(options.seed ?? 1);
    this.lifePaused = options.lifePaused ?? false;
    this.bodyHeight = this.model.body.scale.y;

    const m = this.model.measures;
    const H = m.top - m.chin;
    const crown = this.model.shell ? this.model.shell.egg.center[1] + this.model.shell.egg.up : m.top;
    const target = new THREE.Vector3(m.centerX, (crown + m.chin) / 2 - 0.02 * H, m.sideZ + 0.3 * m.halfWidth);
    // What the camera frames: the head from crown to chin with a margin, and a little more than its width.
    this.frameSize = { height: 1.06 * (crown - m.chin), width: 2.5 * m.halfWidth };
    const face = new THREE.BufferGeometry().setAttribute('position', new THREE.BufferAttribute(template.positions, 3));
    face.computeBoundingSphere();
    this.faceRadius = face.boundingSphere!.radius;
    this.camera = new THREE.PerspectiveCamera(30, 1, H / 40, H * 40);
    this.camera.position.set(target.x, target.y, target.z + 3.3 * H);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.target.copy(target);
    this.controls.enableDamping = true;
    // Orbit and zoom only, and not into the head nor until it is a speck (a pinch on a phone has no other way back).
    [this.controls.enablePan, this.controls.minDistance, this.controls.maxDistance] = [false, 1.2 * H, 8 * H];
    this.controls.addEventListener('change', () => this.requestRender());
    this.controls.update();

    this.watch = new CanvasWatch(canvas, () => this.resize(), () => this.requestRender());
    this.resize();
    this.compose();
    // The first frame is drawn at the next animation frame, not here: what the caller starts meanwhile (the model's
    // sessions, whose runtime downloads and compiles off the main thread) is on its way before the first draw, which
    // under a software GPU holds the main thread for half a second (its shaders are linked then).
    this.frameHandle = requestAnimationFrame(this.loop);
    this.drawn = new Promise((resolve) => (this.onDrawn = resolve));
  }

  /** Resolves when the first frame has been drawn. */
  readonly drawn: Promise<void>;
  private onDrawn: (() => void) | null = null;

  /**
   * Pause (true) or resume (false) the breathing, blinks and eye movements: paused, the face goes to its idle rest (eyes
   * open, looking ahead) and is drawn only when it changes.
   */
  setLifePaused(paused: boolean): void {
    this.lifePaused = paused;
  }

  /** Whether the life moves now: not paused, and the visitor has not asked for reduced motion (it is held still then). */
  private get alive(): boolean {
    return !this.lifePaused && !this.reducedMotion?.matches;
  }

  /** The face's vertices drawn now (template units, N x 3), read-only. */
  get shownVertices(): Float32Array {
    return this.shown;
  }

  /** The speech weight s now (0: the rest face, 1: the frame given). */
  get speechWeight(): number {
    return this.speech;
  }

  /** The face's vertices for this frame (N x 3, template units): I + O from the model, or any face. */
  setVertices(vertices: Float32Array): void {
    if (vertices.length !== this.frame.length) throw new Error(`setVertices: expected ${this.frame.length / 3} vertices, got ${vertices.length / 3}`);
    this.frame.set(vertices);
    this.hasFrame = true;
    this.compose();
  }

  /** The model's rest face (N x 3): what the face shows when no speech is, and what speech blends from. */
  setRestFace(rest: Float32Array): void {
    if (rest.length !== this.frame.length) throw new Error(`setRestFace: expected ${this.frame.length / 3} vertices, got ${rest.length / 3}`);
    this.rest = rest.slice();
    this.restOpening = lidOpening(this.rest, this.lids);
    if (!this.hasFrame) this.speech = this.speechTarget = 0;
    this.compose();
  }

  /** Blend speech in (the frames given are shown) or out (back to the rest face), over a fraction of a second. */
  setSpeaking(on: boolean): void {
    // The blend's clock starts now: with the life held still (paused, reduced motion) the loop has not updated it,
    // and a step as long as the stillness would make the blend one jump.
    if (this.speechTarget !== (on ? 1 : 0)) this.lastTime = -1;
    this.speechTarget = on ? 1 : 0;
    this.requestRender();
  }

  /** How raised the tongue is, 0..1 (Frames.tongue): drawn with the next setVertices (give it first). */
  setTongue(raise: number): void {
    this.tongue = raise;
  }

  /** Head pose y = R x + t: axis-angle (radians) and translation (template units), applied to the whole head. */
  setPose(rx: number, ry: number, rz: number, tx: number, ty: number, tz: number): void {
    this.pose.set([rx, ry, rz, tx, ty, tz]);
    this.applyPose();
  }

  requestRender(): void {
    this.needsRender = true;
  }

  /**
   * Paint a per-vertex scalar on the face (0 -> dark blue, `max` -> red, through cyan, green and yellow),
   * e.g. an error in mm or an attention weight; null restores the skin colours.
   */
  setColorMap(values: ArrayLike<number> | null, max = 1): void {
    if (!values) this.model.paint(null);
    else {
      if (values.length !== this.template.vertexCount) throw new Error(`setColorMap: expected ${this.template.vertexCount} values, got ${values.length}`);
      const c = new Float32Array(values.length * 3);
      for (let v = 0; v < values.length; v++) heat(Math.min(1, Math.max(0, values[v] / (max || 1))), c, 3 * v);
      this.model.paint(c);
    }
    this.requestRender();
  }

  /** The face vertex nearest the point under (clientX, clientY), or null if the face is not there. */
  pickVertex(clientX: number, clientY: number): number | null {
    return pickFaceVertex(this.canvas, this.camera, this.model.skin, this.template.vertexCount, clientX, clientY);
  }

  /**
   * The paper's Fig. 1 pose arrows: the nose-tip normal of the template (grey, fixed) and of the current
   * frame (orange, moves with the head pose).
   */
  showPoseArrows(on: boolean): void {
    if (on && !this.arrows) {
      this.arrows = poseArrows(this.template, this.model.skin, this.faceRadius * 0.9);
      if (!this.arrows) return;
      this.scene.add(this.arrows.template);
      this.head.add(this.arrows.current);
    } else if (!on && this.arrows) {
      this.scene.remove(this.arrows.template);
      this.head.remove(this.arrows.current);
      this.arrows = null;
    }
    this.requestRender();
  }

  /** Advance the life and speech blend to `seconds` and pose the head for it (the frame loop calls this). */
  update(seconds: number): void {
    const dt = this.lastTime < 0 ? 0 : Math.max(0, seconds - this.lastTime);
    this.lastTime = seconds;
    let changed = false;
    if (this.speech !== this.speechTarget && this.rest) {
      const step = dt / (this.speechTarget > this.speech ? BLEND_IN : BLEND_OUT);
      this.speech = this.speechTarget > this.speech ? Math.min(1, this.speech + step) : Math.max(0, this.speech - step);
      changed = true;
    } else if (!this.rest) this.speech = this.speechTarget;
    const before = this.idleState?.blink ?? 0;
    if (this.idle && this.alive) {
      this.idleState = this.idle.at(seconds);
      changed ||= this.idleState.blink > 0 || before > 0;
    } else if (this.idleState) [this.idleState, changed] = [null, true]; // held still: eyes open, ahead, at rest
    if (changed) this.compose();
    this.applyPose();
    this.head.updateMatrixWorld();
    eyeTarget.copy(this.camera.position);
    this.head.worldToLocal(eyeTarget);
    const s = this.idleState;
    this.model.eyes.lookAt(eyeTarget, s?.yaw ?? 0, s?.pitch ?? 0);
    this.model.body.scale.y = this.bodyHeight * (1 + 0.012 * (s?.breath ?? 0));
  }

  dispose(): void {
    cancelAnimationFrame(this.frameHandle);
    this.watch.disconnect();
    this.controls.dispose();
    this.model.dispose();
    this.environment.dispose();
    this.renderer.dispose();
    this.renderer.forceContextLoss(); // now, not at garbage collection: a page keeps 16 WebGL contexts at most
  }

  /** shown = rest + s (frame - rest) + (1 - s) b B, then everything that follows the face. */
  private compose(): void {
    const f = this.frame, out = this.shown;
    const rest = this.rest ?? f;
    const s = this.rest ? this.speech : 1;
    // The idle blink goes on during speech as far as the model's own lids are open (as an avatar's: gltf-avatar.ts).
    const open = this.rest && s > 0 ? Math.min(1, Math.max(0, lidOpening(f, this.lids) / (this.restOpening || 1))) : 1;
    const b = (this.idleState?.blink ?? 0) * (1 - s + s * open);
    for (let i = 0; i < out.length; i++) out[i] = rest[i] + s * (f[i] - rest[i]) + b * this.blink[i];
    this.model.setFace(out, this.tongue * s);
    this.requestRender();
  }

  /** The model's pose scaled by the speech weight, and breathing on top: the chest lifts the head a little. */
  private applyPose(): void {
    const s = this.rest ? this.speech : 1;
    const [rx, ry, rz, tx, ty, tz] = this.pose;
    const angle = Math.hypot(rx, ry, rz) * s;
    if (angle < 1e-9) this.head.quaternion.identity();
    else this.head.quaternion.setFromAxisAngle(scratchAxis.set(rx, ry, rz).normalize(), angle);
    const breath = this.idleState?.breath ?? 0;
    const H = this.model.measures.top - this.model.measures.chin;
    this.head.quaternion.multiply(scratchQ.setFromAxisAngle(scratchAxis.set(1, 0, 0), -0.004 * breath));
    this.head.position.set(tx * s, ty * s + 0.0035 * H * breath, tz * s);
    this.requestRender();
  }

  private loop = (): void => {
    this.frameHandle = requestAnimationFrame(this.loop);
    if (!this.watch.shown && !this.recording) return; // (its life and camera catch up when it is shown again)
    // Damping keeps moving the camera for a few frames after the pointer stops.
    if (this.controls.update()) this.needsRender = true;
    if ((this.idle && this.alive) || this.idleState || this.speech !== this.speechTarget) this.update(performance.now() / 1000);
    if (!this.needsRender) return;
    this.needsRender = false;
    this.renderer.render(this.scene, this.camera);
    if (this.onDrawn) {
      this.onDrawn();
      this.onDrawn = null;
    }
  };

  /** Fit the head in the canvas (a new size resets the zoom, not the direction the camera looks from). */
  private resize(): void {
    fitToCanvas(this.canvas, this.renderer, this.camera);
    const tan = Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2));
    const distance = Math.max(this.frameSize.height / (2 * tan), this.frameSize.width / (2 * tan * this.camera.aspect));
    const t = this.controls.target;
    this.camera.position.sub(t).setLength(THREE.MathUtils.clamp(distance, this.controls.minDistance, this.controls.maxDistance)).add(t);
    this.controls.update();
    this.requestRender();
  }
}
