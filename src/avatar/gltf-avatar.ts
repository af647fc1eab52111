/**
 * A user's glTF avatar bound to this project's output (face-binding.ts finds what drives it): its morph targets found
 * by ARKit name or by Oculus viseme name (names.ts: case-insensitive, exporter prefixes stripped, `_L` / `_R` spelled
 * out), or, for a VRM, its five vowel expressions and its blinks (vrm.ts); and a head bone to turn with the predicted
 * head pose. No renderer here (avatar-view.ts draws it), so it loads in Node too.
 */
import * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { ARKIT_INDEX, ARKIT_NAMES } from './names';
import { VRM_VOWELS, vowelsOf } from './vrm';
import { bindFace, type AvatarScheme, type ExpressionDrive, type Target } from './face-binding';
import { AvatarLoadError, bufferOf, folderOf, parentInScene } from './gltf-nodes';

export { AvatarLoadError, type AvatarScheme };

export interface AvatarSummary {
  /**
   * Which output drives the face: ARKit weights when the avatar has an ARKit target that opens the mouth (jawOpen,
   * mouthLowerDown…, mouthUpperUp…), else the visemes when it has viseme targets (with eyeBlinkLeft / eyeBlinkRight,
   * if it has them, still driven as blinks), else,
   * for a VRM, its vowel expressions (aa ih ou ee oh, made from the visemes: vrm.ts) and its blink expressions. A
   * VRM is ARKit's only where its jawOpen is reached, the visemes' only where its viseme_aa is (face-binding.ts).
   */
  scheme: AvatarScheme;
  /**
   * What drives it: ARKit names (out of 52, with a VRM's expressions named after them), viseme names (out of 15), or a
   * VRM's vowel expressions (out of 5); then a VRM's blink expressions where they are its blinks (blinkLeft and
   * blinkRight, or blink).
   */
  matched: string[];
  /** The bone turned with the head pose (a VRM loaded with three-vrm: its normalized head, where three-vrm copies it), or null. */
  headBone: string | null;
}

/** How a glTF avatar is bound: which way its face looks (glTF's convention, +z, unless said otherwise). */
export interface AvatarBindOptions {
  /**
   * '+z' (glTF's convention) or '-z' (VRM 0.x models, and others made facing away from a glTF camera). Default: '-z'
   * for a VRM 0.x file, else '+z'.
   */
  facing?: '+z' | '-z';
}

export class GltfAvatar {
  private readonly rest = new THREE.Quaternion();
  /** setHeadRotation's `onTop`: the rotation it turned (the page's animation of the bone). */
  private readonly onTopBase = new THREE.Quaternion();
  /** The head bone's rotation as setHeadRotation last wrote it, and how (null: not since binding or reset). */
  private readonly written = new THREE.Quaternion();
  private wroteOnTop: boolean | null = null;

  /** The model's own eyeBlinkLeft / eyeBlinkRight of the frame shown, and the idle blink on top of them. */
  private readonly modelBlink = [0, 0];
  private idleBlink = 0;
  /** A VRM's vowels this frame (scheme 'vrm'). */
  private readonly vowels = new Float32Array(VRM_VOWELS.length);
  private readonly blinkTargets: Target[];
  private readonly expressions: ExpressionDrive | null;

  private constructor(
    readonly gltf: GLTF,
    readonly scheme: AvatarScheme,
    private readonly targets: Target[],
    readonly matched: string[],
    readonly head: THREE.Object3D | null,
    readonly facing: '+z' | '-z',
    /** eyeBlinkLeft / eyeBlinkRight targets (channel 0 / 1), whatever drives the rest of the face. */
    blinkTargets: Target[],
    /** Expressions set by name: three-vrm's manager (vrm.update() applies them), or the file's read here. */
    expressions: ExpressionDrive | null,
  ) {
    this.blinkTargets = blinkTargets;
    this.expressions = expressions;
    if (head) this.rest.copy(head.quaternion);
  }

  /**
   * Parse a .glb (or .gltf JSON) and bind it: `data` is the file's bytes (an ArrayBuffer, or a view of them such as
   * a Uint8Array or Node's Buffer). `source` names the file in messages; `headBone` is the `avatar-head-bone`
   * attribute (default: a bone named Head or head); `options.facing` which way the face looks. Throws AvatarLoadError
   * with what is wrong.
   */
  static async parse(data: ArrayBuffer | ArrayBufferView, source: string, headBone?: string | null, options: AvatarBindOptions = {}): Promise<GltfAvatar> {
    const bytes = bufferOf(data, source);
    const start = new Uint8Array(bytes, 0, Math.min(64, bytes.byteLength));
    const magic = String.fromCharCode(...start.subarray(0, 4));
    const firstChar = new TextDecoder().decode(start).trimStart()[0]; // (a UTF-8 byte-order mark is dropped)
    if (magic !== 'glTF' && firstChar !== '{') {
      throw new AvatarLoadError(firstChar === '<'
        ? `${source} is not a glTF file but an HTML page, as hosts send for a missing file: is the URL right?`
        : `${source} is not a glTF file (a .glb or .vrm starts with "glTF"; this one starts with ${JSON.stringify(magic)}): export the avatar as glTF binary (.glb, or .vrm)`);
    }
    const declared = magic === 'glTF' && bytes.byteLength >= 12 ? new DataView(bytes).getUint32(8, true) : 0;
    if (declared > bytes.byteLength) {
      throw new AvatarLoadError(`${source} is cut short: its header says ${declared} bytes, ${bytes.byteLength} came (an interrupted download or upload?)`);
    }
    const used = extensionsOf(bytes, magic === 'glTF');
    const refused = undecoded(used, source);
    if (refused) throw new AvatarLoadError(refused);
    const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
    const loader = new GLTFLoader();
    if (used.used.some((e) => MESHOPT.includes(e))) loader.setMeshoptDecoder((await import('three/addons/libs/meshopt_decoder.module.js')).MeshoptDecoder);
    let gltf: GLTF;
    try {
      gltf = await loader.parseAsync(bytes, folderOf(source));
    } catch (e) {
      throw new AvatarLoadError(`${source} could not be read as glTF: ${(e as Error).message}`);
    }
    return GltfAvatar.bind(gltf, source, headBone, options);
  }

  /**
   * Bind a loaded glTF (what GLTFLoader gives: `gltf`, not `gltf.scene`): find its targets and its head bone (the
   * one named `headBone`, else Head or head, else a bone whose name ends in head). `source` names it in messages.
   */
  static bind(gltf: GLTF, source: string, headBone?: string | null, options: AvatarBindOptions = {}): GltfAvatar {
    if ((gltf as unknown as THREE.Object3D)?.isObject3D) {
      throw new TypeError(`GltfAvatar.bind(${source}): give what GLTFLoader gave (gltf), not its scene: GltfAvatar.bind(gltf, ...)`);
    }
    if ((gltf as unknown as { humanoid?: unknown })?.humanoid && !(gltf as { parser?: unknown }).parser) {
      throw new TypeError(`GltfAvatar.bind(${source}): give what GLTFLoader gave (gltf), not gltf.userData.vrm: GltfAvatar.bind(gltf, ...)`);
    }
    if (!gltf?.scene) throw new AvatarLoadError(`${source} has no scene: export the avatar with its scene`);
    const face = bindFace(gltf, source, headBone);
    const facing = options.facing ?? (face.vrmVersion === '0' ? '-z' : '+z');
    if (facing !== '+z' && facing !== '-z') throw new TypeError(`GltfAvatar.bind(${source}): facing is '+z' or '-z', not ${JSON.stringify(facing)}`);
    return new GltfAvatar(gltf, face.scheme, face.targets, face.matched, face.head, facing, face.blinkTargets, face.expressions);
  }

  get summary(): AvatarSummary {
    return { scheme: this.scheme, matched: this.matched, headBone: this.head?.name ?? null };
  }

  /** Whether the avatar can blink (it has eyeBlinkLeft / eyeBlinkRight targets, or blink expressions). */
  get canBlink(): boolean {
    return this.blinkTargets.length > 0 || !!this.expressions?.blinks.length;
  }

  /**
   * Set the face from one frame of output: ARKit weights (52) and visemes (15), each from its index `at` (a VRM's
   * vowels are made from the visemes). Expressions of three-vrm's are set, and vrm.update() applies them.
   */
  setWeights(arkit: ArrayLike<number>, arkitAt: number, visemes: ArrayLike<number>, visemesAt: number): void {
    if (this.scheme === 'vrm') this.writeFace(vowelsOf(visemes, visemesAt, this.vowels), 0);
    else if (this.scheme === 'arkit') this.writeFace(arkit, arkitAt);
    else this.writeFace(visemes, visemesAt);
    this.modelBlink[0] = arkit[arkitAt + ARKIT_INDEX.eyeBlinkLeft];
    this.modelBlink[1] = arkit[arkitAt + ARKIT_INDEX.eyeBlinkRight];
    this.applyBlink();
  }

  /** An idle blink's lid closure (blinks.ts) on top of the model's own eyeBlink weights. */
  setIdleBlink(amount: number): void {
    this.idleBlink = amount;
    this.applyBlink();
  }

  /**
   * Every driven morph target (and expression) back to 0 and the head to its rest pose: after turns on top of the
   * page's animation, the animation's rotation they turned (the page's, where it has set the bone since).
   */
  reset(): void {
    this.writeFace(ZEROS, 0);
    this.modelBlink.fill(0);
    this.applyBlink();
    const q = this.head?.quaternion; // (not turned since binding or the last reset: left as the page has it)
    if (q && this.wroteOnTop === false) q.copy(this.rest);
    else if (q && this.wroteOnTop && q.equals(this.written)) q.copy(this.onTopBase);
    this.wroteOnTop = null;
  }

  /** Each target (and expression) to its channel's value, from index `at` of `values`. */
  private writeFace(values: ArrayLike<number>, at: number): void {
    for (let i = 0; i < this.targets.length; i++) {
      const t = this.targets[i];
      t.influences[t.at] = values[at + t.channel] * t.weight;
    }
    const e = this.expressions;
    if (e) for (let i = 0; i < e.face.length; i++) e.manager.setValue(e.face[i][0], values[at + e.face[i][1]]);
  }

  /**
   * A blink channel's closure: 0 left, 1 right, 2 both (a VRM's one blink expression), the idle blink on top. The
   * model's own weight counts from `floor` up (a VRM's blink expressions: VRM_BLINK_FLOOR, vrm.ts), stretched to 1.
   */
  private blinkOf(channel: number, floor = 0): number {
    const model = channel === 2 ? Math.max(this.modelBlink[0], this.modelBlink[1]) : this.modelBlink[channel];
    return Math.max(Math.max(0, model - floor) / (1 - floor), this.idleBlink);
  }

  /** The blinks set, then (a VRM read here) its expressions applied to its morph targets. */
  private applyBlink(): void {
    for (let i = 0; i < this.blinkTargets.length; i++) {
      const t = this.blinkTargets[i];
      t.influences[t.at] = this.blinkOf(t.channel) * t.weight;
    }
    const e = this.expressions;
    if (!e) return;
    for (let i = 0; i < e.blinks.length; i++) e.manager.setValue(e.blinks[i][0], this.blinkOf(e.blinks[i][1], e.blinks[i][2]));
    e.own?.update();
  }

  /**
   * Turn the head bone by an axis-angle rotation (radians) given in the avatar's own axes (glTF's: +y up, the face
   * towards +z, as the template's), about the bone's own pivot, on top of the bone's rest rotation. The axes are
   * gltf.scene's, wherever the page has put or turned it: the rotation is carried into the bone's parent frame
   * through the parent's rotation relative to gltf.scene, read at each call, so an avatar placed, turned or
   * re-parented before or after binding nods about its own x axis.
   *
   * An avatar bound `facing: '-z'` turns as if it faced +z (a nod is still a nod).
   *
   * `onTop`: on top of the bone's rotation as the page's own animation (an AnimationMixer) last set it, not its rest:
   * call it after the animation's update. Where nothing has set the bone since the last call (no clip on it, a clip
   * stopped or ended, two calls in one frame), the turn goes on top of the same rotation as then, so turns never add up
   * (after a call without `onTop`, on top of the rest).
   */
  setHeadRotation(rx: number, ry: number, rz: number, onTop = false): void {
    if (!this.head) return;
    const flip = this.facing === '-z' ? -1 : 1; // the avatar's axes turned half round y: x and z change sign
    rx *= flip;
    rz *= flip;
    const angle = Math.hypot(rx, ry, rz);
    if (angle < 1e-9) scratch.identity();
    else scratch.setFromAxisAngle(axis.set(rx / angle, ry / angle, rz / angle), angle);
    const parent = parentInScene(this.head, this.gltf.scene);
    scratch.premultiply(inverse.copy(parent).invert()).multiply(parent); // parent^-1 * delta * parent
    const q = this.head.quaternion;
    if (onTop) {
      const untouched = this.wroteOnTop !== null && q.equals(this.written); // nothing has set the bone since
      if (!untouched) this.onTopBase.copy(q); // the animation's rotation now
      else if (!this.wroteOnTop) this.onTopBase.copy(this.rest); // the last turn was on top of the rest
    }
    q.multiplyQuaternions(scratch, onTop ? this.onTopBase : this.rest);
    this.written.copy(q);
    this.wroteOnTop = onTop;
  }
}

const ZEROS = new Float32Array(ARKIT_NAMES.length);
const scratch = new THREE.Quaternion();
const inverse = new THREE.Quaternion();
const axis = new THREE.Vector3();

/** Meshopt compression (gltfpack, gltf-transform optimize): decoded (its decoder is WebAssembly inside the script). */
const MESHOPT = ['EXT_meshopt_compression', 'KHR_meshopt_compression'];

/** The extensions a glTF's JSON says it uses and requires (none where it cannot be read: GLTFLoader then says why). */
function extensionsOf(bytes: ArrayBuffer, binary: boolean): { used: string[]; required: string[] } {
  try {
    const view = new DataView(bytes);
    const text = binary ? new Uint8Array(bytes, 20, view.getUint32(12, true)) : new Uint8Array(bytes);
    const json = JSON.parse(new TextDecoder().decode(text)) as { extensionsUsed?: unknown; extensionsRequired?: unknown };
    const names = (list: unknown): string[] => (Array.isArray(list) ? list.filter((e): e is string => typeof e === 'string') : []);
    return { used: names(json.extensionsUsed), required: names(json.extensionsRequired) };
  } catch {
    return { used: [], required: [] }; // not readable here: GLTFLoader's own message says what is wrong
  }
}

/**
 * Why a glTF cannot be read here, or null: Draco meshes (GLTFLoader cannot read them at all without a DRACOLoader,
 * whose decoder would be fetched from elsewhere) and KTX2 textures it requires (the same, a KTX2Loader's transcoder).
 */
function undecoded(e: { used: string[]; required: string[] }, source: string): string | null {
  const own = 'or load it in your own three.js scene with that loader and drive it with GltfAvatar.bind and AvatarDriver (docs/embedding.md)';
  if (e.used.includes('KHR_draco_mesh_compression')) {
    return `${source} is compressed with Draco (KHR_draco_mesh_compression), which this library does not decode: export it ` +
      `without mesh compression (Ready Player Me: without meshCompression=true; meshopt compression is decoded), ${own.replace('that loader', 'a DRACOLoader')}`;
  }
  if (e.required.includes('KHR_texture_basisu')) {
    return `${source} has KTX2 (Basis Universal) textures only (KHR_texture_basisu), which this library does not decode: export ` +
      `it with PNG, JPEG or WebP textures, ${own.replace('that loader', 'a KTX2Loader')}`;
  }
  return null;
}
