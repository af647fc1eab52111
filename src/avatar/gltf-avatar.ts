/**
 * A user's glTF avatar bound to this project's output: its morph targets found by ARKit name or by Oculus viseme
 * name (names.ts: case-insensitive, exporter prefixes stripped, `_L` / `_R` spelled out), or, for a VRM, its five
 * vowel expressions and its blinks (vrm.ts); and a head bone to turn with the predicted head pose. No renderer here
 * (avatar-view.ts draws it), so it loads in Node too.
 */
import * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { ARKIT_INDEX, ARKIT_NAMES, VISEME_NAMES, arkitIndexOf, visemeIndexOf } from './names';
import { VRM_VOWELS, readVrm, threeVrmOf, vowelsOf, type ThreeVrmLike, type VrmFile } from './vrm';

export class AvatarLoadError extends Error {
  override name = 'AvatarLoadError';
}

/** One morph target driven by one output channel: influences[at] gets the channel's value x weight (summed where several drive it). */
interface Target {
  influences: number[];
  at: number;
  channel: number;
  weight: number;
}

/** A VRM's expressions as three-vrm's manager drives them (the page's VRMLoaderPlugin): the vowels and blinks it has. */
interface ThreeVrmFace {
  manager: NonNullable<ThreeVrmLike['expressionManager']>;
  vowels: boolean[];
  /** Its blink expressions, by blink channel (0 left, 1 right, 2 both). */
  blinks: [name: string, channel: number][];
}

export type AvatarScheme = 'arkit' | 'visemes' | 'vrm';

export interface AvatarSummary {
  /**
   * Which output drives the face: ARKit weights when the avatar has ARKit mouth or jaw targets, else the visemes
   * when it has viseme targets (with eyeBlinkLeft / eyeBlinkRight, if it has them, still driven as blinks), else,
   * for a VRM, its vowel expressions (aa ih ou ee oh, made from the visemes: vrm.ts) and its blink expressions.
   */
  scheme: AvatarScheme;
  /** ARKit (or viseme, or VRM expression) names the avatar has, out of 52 (15, 8). */
  matched: string[];
  /** The bone turned with the head pose, or null. */
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

  private constructor(
    readonly gltf: GLTF,
    readonly scheme: AvatarScheme,
    private readonly targets: Target[],
    readonly matched: string[],
    readonly head: THREE.Object3D | null,
    /** eyeBlinkLeft / eyeBlinkRight targets (channel 0 / 1), whatever drives the rest of the face. */
    private readonly blinkTargets: Target[],
    readonly facing: '+z' | '-z',
    /** A VRM loaded with three-vrm: its expressions are set through its manager, which vrm.update() applies. */
    private readonly threeVrm: ThreeVrmFace | null = null,
  ) {
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
        : `${source} is not a glTF file (a .glb starts with "glTF"; this one starts with ${JSON.stringify(magic)}): export the avatar as .glb`);
    }
    const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
    let gltf: GLTF;
    try {
      gltf = await new GLTFLoader().parseAsync(bytes, folderOf(source));
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
    if (!gltf?.scene) throw new AvatarLoadError(`${source} has no scene: export the avatar with its scene`);
    const threeVrm = threeVrmOf(gltf);
    const vrm = threeVrm ? null : readVrm(gltf);
    const facing = options.facing ?? ((threeVrm?.meta?.metaVersion ?? vrm?.version) === '0' ? '-z' : '+z');
    if (facing !== '+z' && facing !== '-z') throw new TypeError(`GltfAvatar.bind(${source}): facing is '+z' or '-z', not ${JSON.stringify(facing)}`);
    const arkit: Target[] = [];
    const visemes: Target[] = [];
    const names = new Set<string>();
    gltf.scene.traverse((o) => {
      const mesh = o as THREE.Mesh;
      if (!mesh.morphTargetDictionary || !mesh.morphTargetInfluences) return;
      for (const [name, at] of Object.entries(mesh.morphTargetDictionary)) {
        names.add(name);
        const a = arkitIndexOf(name), v = visemeIndexOf(name);
        if (a >= 0) arkit.push({ influences: mesh.morphTargetInfluences, at, channel: a, weight: 1 });
        if (v >= 0) visemes.push({ influences: mesh.morphTargetInfluences, at, channel: v, weight: 1 });
      }
    });
    // A few ARKit eye shapes beside the visemes (blinks, often) do not make an ARKit rig: the mouth decides.
    const arkitMouth = arkit.some((t) => /^(jaw|mouth)/.test(ARKIT_NAMES[t.channel]));
    const has = (name: string) => (threeVrm ? threeVrm.expressionManager!.getExpression(name) != null : !!vrm?.expressions.get(name)?.length);
    const vrmMouth = VRM_VOWELS.some(has);
    if (!arkit.length && !visemes.length && !vrmMouth) {
      const found = names.size
        ? `its morph targets are: ${[...names].slice(0, 60).join(', ')}${names.size > 60 ? ', …' : ''}. Rename them`
        : 'it has no morph targets at all: export it with its blend shapes (shape keys), named so';
      throw new AvatarLoadError(`${source} has no morph targets named after ARKit's 52 blend shapes (jawOpen, eyeBlinkLeft, …) ` +
        `or the 15 Oculus visemes (viseme_aa, viseme_PP, …)${threeVrm || vrm ? ', and its VRM expressions have no vowels (aa, ih, ou, ee, oh)' : ''}; ` +
        `${found} (docs/embedding.md, "Avatars").`);
    }
    const scheme = arkitMouth || (!visemes.length && !vrmMouth) ? 'arkit' : visemes.length ? 'visemes' : 'vrm';
    const head = headBone || !(threeVrm || vrm)
      ? findHead(gltf.scene, source, headBone)
      : threeVrm?.humanoid?.getNormalizedBoneNode('head') ?? vrm?.head ?? findHead(gltf.scene, source, null);
    // Blinks: eyeBlinkLeft / Right (channels 0, 1), else a VRM's blinkLeft / Right, else its blink (2: both eyes).
    const blinkNames = has('blinkLeft') && has('blinkRight') ? ['blinkLeft', 'blinkRight'] : has('blink') ? ['blink'] : [];
    const vrmBlinkChannel = (name: string) => ['blinkLeft', 'blinkRight', 'blink'].indexOf(name);
    let blinks = arkit.filter((t) => t.channel === ARKIT_INDEX.eyeBlinkLeft || t.channel === ARKIT_INDEX.eyeBlinkRight)
      .map((t) => ({ ...t, channel: t.channel === ARKIT_INDEX.eyeBlinkLeft ? 0 : 1 }));
    if (!blinks.length && vrm) blinks = blinkNames.flatMap((name) => vrm.expressions.get(name)!.map((b) => ({ ...b, channel: vrmBlinkChannel(name) })));
    if (scheme !== 'vrm') {
      const targets = scheme === 'arkit' ? arkit : visemes;
      const all: readonly string[] = scheme === 'arkit' ? ARKIT_NAMES : VISEME_NAMES;
      const matched = [...new Set(targets.map((t) => all[t.channel]))];
      return new GltfAvatar(gltf, scheme, targets, matched, head, blinks, facing);
    }
    const vowels = VRM_VOWELS.map(has);
    const matched = [...VRM_VOWELS.filter((_, k) => vowels[k]), ...blinkNames];
    if (threeVrm) {
      const face = { manager: threeVrm.expressionManager!, vowels, blinks: blinkNames.map((n) => [n, vrmBlinkChannel(n)] as [string, number]) };
      return new GltfAvatar(gltf, scheme, [], matched, head, [], facing, face);
    }
    const targets = VRM_VOWELS.flatMap((name, channel) => (vrm as VrmFile).expressions.get(name)?.map((b) => ({ ...b, channel })) ?? []);
    return new GltfAvatar(gltf, scheme, targets, matched, head, blinks, facing);
  }

  get summary(): AvatarSummary {
    return { scheme: this.scheme, matched: this.matched, headBone: this.head?.name ?? null };
  }

  /** Whether the avatar can blink (it has eyeBlinkLeft / eyeBlinkRight targets, or a VRM's blink expressions). */
  get canBlink(): boolean {
    return this.blinkTargets.length > 0 || !!this.threeVrm?.blinks.length;
  }

  /**
   * Set the morph targets from one frame of output: ARKit weights (52) and visemes (15), each from its index `at`
   * (a VRM's vowels are made from the visemes). With three-vrm, its expressions are set, which vrm.update() applies.
   */
  setWeights(arkit: ArrayLike<number>, arkitAt: number, visemes: ArrayLike<number>, visemesAt: number): void {
    let values: ArrayLike<number> = this.scheme === 'arkit' ? arkit : visemes;
    let at = this.scheme === 'arkit' ? arkitAt : visemesAt;
    if (this.scheme === 'vrm') {
      values = vowelsOf(visemes, visemesAt, this.vowels);
      at = 0;
    }
    this.writeTargets(values, at);
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
   * Every driven morph target back to 0 and the head to its rest pose: after turns on top of the page's animation,
   * the animation's rotation they turned (the page's, where it has set the bone since).
   */
  reset(): void {
    this.writeTargets(ZEROS, 0);
    this.modelBlink.fill(0);
    this.applyBlink();
    const q = this.head?.quaternion; // (not turned since binding or the last reset: left as the page has it)
    if (q && this.wroteOnTop === false) q.copy(this.rest);
    else if (q && this.wroteOnTop && q.equals(this.written)) q.copy(this.onTopBase);
    this.wroteOnTop = null;
  }

  /** Each target to its channel's value x its weight (0 first: a VRM's expressions may share a morph target, and add). */
  private writeTargets(values: ArrayLike<number>, at: number): void {
    for (const t of this.targets) t.influences[t.at] = 0;
    for (const t of this.targets) t.influences[t.at] += values[at + t.channel] * t.weight;
    const face = this.threeVrm;
    if (face) for (let k = 0; k < VRM_VOWELS.length; k++) if (face.vowels[k]) face.manager.setValue(VRM_VOWELS[k], values[at + k]);
  }

  /** A blink channel's closure: 0 left, 1 right, 2 both (a VRM's one blink expression), with the idle blink on top. */
  private blinkOf(channel: number): number {
    const model = channel === 2 ? Math.max(this.modelBlink[0], this.modelBlink[1]) : this.modelBlink[channel];
    return Math.max(model, this.idleBlink);
  }

  private applyBlink(): void {
    for (const t of this.blinkTargets) t.influences[t.at] = this.blinkOf(t.channel) * t.weight;
    if (this.threeVrm) for (const [name, channel] of this.threeVrm.blinks) this.threeVrm.manager.setValue(name, this.blinkOf(channel));
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

/** The file's bytes as an ArrayBuffer of their own (a view's bytes copied out), or a TypeError saying what came. */
function bufferOf(data: ArrayBuffer | ArrayBufferView, source: string): ArrayBuffer {
  if (data instanceof ArrayBuffer) return data;
  if (ArrayBuffer.isView(data)) return new Uint8Array(data.buffer, data.byteOffset, data.byteLength).slice().buffer;
  const what = data === null ? 'null' : typeof data === 'object' ? (data as object).constructor?.name ?? 'an object' : typeof data;
  throw new TypeError(`GltfAvatar.parse(${source}): give the file's bytes (an ArrayBuffer or a Uint8Array), not ${what}` +
    (what === 'Blob' || what === 'File' ? ' (await its arrayBuffer() first)' : ''));
}

/** The folder a .gltf's external files are read from ('' for a blob: or data: URL, which has none). */
function folderOf(source: string): string {
  try {
    const url = new URL(source, globalThis.location?.href ?? 'file:///');
    return url.protocol === 'blob:' || url.protocol === 'data:' ? '' : new URL('.', url).href;
  } catch {
    return ''; // deliberate: a name that is no URL has no folder; an embedded .glb needs none
  }
}

const ZEROS = new Float32Array(ARKIT_NAMES.length);
const scratch = new THREE.Quaternion();
const inverse = new THREE.Quaternion();
const sceneWorld = new THREE.Quaternion();
const parentWorld = new THREE.Quaternion();
const axis = new THREE.Vector3();

/** The rotation of the head's parent relative to the avatar's root (gltf.scene), from their world rotations now. */
function parentInScene(head: THREE.Object3D, scene: THREE.Object3D): THREE.Quaternion {
  if (!head.parent) return parentWorld.identity();
  head.parent.getWorldQuaternion(parentWorld);
  scene.getWorldQuaternion(sceneWorld);
  return parentWorld.premultiply(sceneWorld.invert()); // scene^-1 * parent
}

/** The head bone: the named one, else a bone (or node) named Head / head, else one whose name ends in "head". */
function findHead(scene: THREE.Object3D, source: string, name?: string | null): THREE.Object3D | null {
  const nodes: THREE.Object3D[] = [];
  scene.traverse((o) => nodes.push(o));
  if (name) {
    // three.js's loader spells node names its own way (`mixamorig:Head` -> `mixamorigHead`): either spelling is found.
    const sanitised = THREE.PropertyBinding.sanitizeNodeName(name);
    const found = nodes.find((o) => o.name === name) ?? nodes.find((o) => o.name === sanitised);
    if (!found) {
      const bones = nodes.filter((o) => (o as THREE.Bone).isBone).map((o) => o.name);
      const named = bones.length ? bones : nodes.map((o) => o.name).filter(Boolean);
      throw new AvatarLoadError(`${source} has no node named "${name}" (the head bone asked for: avatar-head-bone, or bind's headBone); ` +
        `its ${bones.length ? 'bones' : 'nodes'} are: ${named.slice(0, 60).join(', ')}`);
    }
    return found;
  }
  return nodes.find((o) => o.name === 'Head' || o.name === 'head')
    ?? nodes.find((o) => (o as THREE.Bone).isBone && /(^|[^a-z])head$/i.test(o.name.replace(/^mixamorig:?/i, '')))
    ?? null;
}
