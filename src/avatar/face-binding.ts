/**
 * What drives a glTF avatar's face (gltf-avatar.ts binds it): its morph targets found by ARKit or Oculus viseme name
 * (names.ts), or a VRM's expressions (vrm.ts); its blinks; its head bone. A VRM's morph target that one of its
 * expressions binds is set by its expressions only (three-vrm's vrm.update(), or VrmExpressions here, so the plain
 * loader and three-vrm agree): through an expression named after its shape (a "perfect sync" VRM's), or through the
 * vowels that bind it.
 */
import type * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { ARKIT_INDEX, ARKIT_NAMES, VISEME_NAMES, arkitIndexOf, visemeIndexOf } from './names';
import { VRM_BLINK_FLOOR, VRM_VOWELS, VrmExpressions, readVrm, threeVrmOf, type ExpressionManagerLike, type ThreeVrmLike, type VrmFile } from './vrm';
import { AvatarLoadError, findHead } from './gltf-nodes';

export type AvatarScheme = 'arkit' | 'visemes' | 'vrm';

/** One morph target driven by one output channel: influences[at] gets the channel's value x weight. */
export interface Target {
  influences: number[];
  at: number;
  channel: number;
  weight: number;
}

/** Expressions driven by name, each from one output channel; `own`: the VrmExpressions to update() after setting them. */
export interface ExpressionDrive {
  manager: ExpressionManagerLike;
  own: VrmExpressions | null;
  /** [expression, channel of the frame's values (ARKit's, or the vowels')]. */
  face: [string, number][];
  /** [expression, blink channel: 0 left, 1 right, 2 both, the floor of the model's own weights it gets]. */
  blinks: [string, number, number][];
}

export interface FaceBinding {
  scheme: AvatarScheme;
  targets: Target[];
  /** eyeBlinkLeft / eyeBlinkRight targets (channel 0 / 1), whatever drives the rest of the face. */
  blinkTargets: Target[];
  expressions: ExpressionDrive | null;
  matched: string[];
  head: THREE.Object3D | null;
  /** '0' for a VRM 0.x file (made facing -z), else null. */
  vrmVersion: string | null;
}

/** ARKit's shapes that open the mouth: the jaw, and the lips parted (a smile or a press beside visemes opens nothing). */
const OPENS_MOUTH = new Set((['jawOpen', 'mouthLowerDownLeft', 'mouthLowerDownRight', 'mouthUpperUpLeft', 'mouthUpperUpRight'] as const).map((n) => ARKIT_INDEX[n]));
const isBlink = (channel: number) => channel === ARKIT_INDEX.eyeBlinkLeft || channel === ARKIT_INDEX.eyeBlinkRight;
const VRM_BLINKS = ['blinkLeft', 'blinkRight', 'blink'];

/** A VRM's expressions as the binding sees them: their names, and whether one moves a morph target. */
interface Expressions {
  names: string[];
  moves(name: string): boolean;
}

/** What drives `gltf`'s face (`source` names it in messages; `headBone`: the node to turn, if named); throws AvatarLoadError for nothing. */
export function bindFace(gltf: GLTF, source: string, headBone?: string | null): FaceBinding {
  const threeVrm = threeVrmOf(gltf);
  const file = threeVrm ? null : readVrm(gltf);
  const vrm = expressionsOf(threeVrm, file);
  const bound = vrm ? boundByExpressions(threeVrm, file) : null;
  const arkit: Target[] = [], visemes: Target[] = [];
  const names = new Set<string>(), boundNames: string[] = [];
  gltf.scene.traverse((o) => {
    const mesh = o as THREE.Mesh;
    if (!mesh.morphTargetDictionary || !mesh.morphTargetInfluences) return;
    for (const [name, at] of Object.entries(mesh.morphTargetDictionary)) {
      names.add(name);
      const a = arkitIndexOf(name), v = visemeIndexOf(name);
      if (bound?.get(mesh.morphTargetInfluences)?.has(at)) { // a VRM's expression sets it: through one only
        if (a >= 0 || v >= 0) boundNames.push(name);
        continue;
      }
      if (a >= 0) arkit.push({ influences: mesh.morphTargetInfluences, at, channel: a, weight: 1 });
      if (v >= 0) visemes.push({ influences: mesh.morphTargetInfluences, at, channel: v, weight: 1 });
    }
  });
  // A VRM's expressions named after ARKit's shapes (a perfect-sync VRM's): their morph targets are reached so.
  const arkitExpressions = (vrm?.names ?? []).map((n) => [n, arkitIndexOf(n)] as [string, number]).filter(([n, c]) => c >= 0 && vrm!.moves(n));
  const vowels = VRM_VOWELS.map((v) => !!vrm?.moves(v));
  const scheme = schemeOf(arkit, arkitExpressions, visemes, vowels, !!vrm);
  if (!scheme) throw noTargets(source, names, vrm ? { names: vrm.names, unbound: (file ?? readVrm(gltf))?.unbound ?? [], boundNames } : null);

  const manager = threeVrm?.expressionManager ?? (file ? new VrmExpressions(file) : null);
  const { blinkTargets, blinks, vrmBlinks } = blinksOf(arkit, arkitExpressions, vrm);
  const face: [string, number][] = scheme === 'arkit' ? arkitExpressions.filter(([, c]) => !isBlink(c))
    : scheme === 'vrm' ? VRM_VOWELS.map((name, k) => [name, k] as [string, number]).filter((_, k) => vowels[k]) : [];
  const expressions = manager && (face.length || blinks.length) ? { manager, own: manager instanceof VrmExpressions ? manager : null, face, blinks } : null;
  const targets = scheme === 'arkit' ? arkit : scheme === 'visemes' ? visemes : [];
  const matched = scheme === 'arkit'
    ? [...new Set([...arkit.map((t) => t.channel), ...arkitExpressions.map(([, c]) => c)])].sort((x, y) => x - y).map((c) => ARKIT_NAMES[c])
    : scheme === 'visemes' ? [...new Set(visemes.map((t) => VISEME_NAMES[t.channel]))] : face.map(([name]) => name);
  matched.push(...vrmBlinks);
  const vrmVersion = threeVrm ? threeVrm.meta?.metaVersion ?? null : file?.version ?? null;
  return { scheme, targets, blinkTargets, expressions, matched, head: headOf(gltf, source, headBone, threeVrm, file), vrmVersion };
}

/** A VRM's expressions, from three-vrm's manager or the file; null for an avatar that is no VRM. */
function expressionsOf(threeVrm: ThreeVrmLike | null, file: VrmFile | null): Expressions | null {
  if (threeVrm) {
    const list = threeVrm.expressionManager?.expressions ?? [];
    // (three-vrm's binds also set materials: one that moves a morph target has primitives)
    return { names: list.map((e) => e.expressionName), moves: (name) => !!list.find((e) => e.expressionName === name)?.binds?.some((b) => b.primitives?.length) };
  }
  return file ? { names: [...file.expressions.keys()], moves: (name) => !!file.expressions.get(name)?.binds.length } : null;
}

/**
 * Which output drives the face, or null for nothing to drive. ARKit when it has an ARKit shape that opens the mouth
 * (jawOpen, or the lips parted: OPENS_MOUTH), else the visemes when it has viseme targets, else a VRM's vowels; an
 * avatar with only other ARKit shapes (eyes, a smile) and no visemes is ARKit's too. For a
 * VRM, only a scheme that opens the mouth: ARKit where jawOpen is reached (a target no expression binds, or an
 * expression named so), the visemes where viseme_aa is; else its vowels, whatever else it has (a VRM whose vowels
 * bind its viseme or ARKit targets leaves the others alone, and they cannot open its mouth).
 */
function schemeOf(arkit: Target[], arkitExpressions: [string, number][], visemes: Target[], vowels: boolean[], isVrm: boolean): AvatarScheme | null {
  const anyVowel = vowels.some(Boolean);
  const arkitMouth = isVrm
    ? arkit.some((t) => t.channel === ARKIT_INDEX.jawOpen) || arkitExpressions.some(([, c]) => c === ARKIT_INDEX.jawOpen)
    : arkit.some((t) => OPENS_MOUTH.has(t.channel));
  const visemeMouth = isVrm ? visemes.some((t) => VISEME_NAMES[t.channel] === 'viseme_aa') : visemes.length > 0;
  if (arkitMouth) return 'arkit';
  if (visemeMouth) return 'visemes';
  if (anyVowel) return 'vrm';
  // Nothing opens the mouth: what there is (eye shapes, a VRM's stray targets), ARKit's first.
  if (arkit.length || arkitExpressions.length) return 'arkit';
  return visemes.length ? 'visemes' : null;
}

/**
 * The blinks: ARKit's eyeBlinkLeft / Right (targets, or a VRM's expressions so named), else a VRM's blinkLeft and
 * blinkRight, else its blink (channel 2: both eyes); `vrmBlinks` names the VRM's, where they are used. Each
 * expression's third value is the floor below which the model's own weights do not reach it (VRM_BLINK_FLOOR, for
 * VRM's blink expressions: vrm.ts).
 */
function blinksOf(arkit: Target[], arkitExpressions: [string, number][], vrm: Expressions | null) {
  const blinkTargets = arkit.filter((t) => isBlink(t.channel)).map((t) => ({ ...t, channel: t.channel === ARKIT_INDEX.eyeBlinkLeft ? 0 : 1 }));
  const named = arkitExpressions.filter(([, c]) => isBlink(c)).map(([n, c]) => [n, c === ARKIT_INDEX.eyeBlinkLeft ? 0 : 1, 0] as [string, number, number]);
  const own = vrm?.moves('blinkLeft') && vrm.moves('blinkRight') ? ['blinkLeft', 'blinkRight'] : vrm?.moves('blink') ? ['blink'] : [];
  const byVrm = !blinkTargets.length && !named.length && own.length > 0;
  const blinks = byVrm ? own.map((name) => [name, VRM_BLINKS.indexOf(name), VRM_BLINK_FLOOR] as [string, number, number]) : named;
  return { blinkTargets, blinks, vrmBlinks: byVrm ? own : [] };
}

/**
 * The head bone: the one named `headBone`, else a VRM's humanoid head, else findHead's. With three-vrm, a humanoid
 * bone is turned through its normalized node, which vrm.update() copies to it (the bone itself it would reset);
 * where the page turned that copying off (autoUpdateHumanBones false), the bone itself, which vrm.update() then
 * leaves alone.
 */
function headOf(gltf: GLTF, source: string, headBone: string | null | undefined, threeVrm: ThreeVrmLike | null, file: VrmFile | null): THREE.Object3D | null {
  const humanoid = threeVrm?.humanoid;
  const normalized = humanoid?.autoUpdateHumanBones !== false;
  if (!headBone) {
    const own = (normalized ? humanoid?.getNormalizedBoneNode('head') : humanoid?.humanBones?.head?.node) ?? file?.head;
    if (own) return own;
  }
  const head = findHead(gltf.scene, source, headBone);
  const human = normalized ? Object.entries(humanoid?.humanBones ?? {}).find(([, b]) => b?.node === head)?.[0] : undefined;
  return (human && humanoid?.getNormalizedBoneNode(human)) || head;
}

/**
 * The morph targets a VRM's expressions bind (by the mesh's influences array, then index): three-vrm's vrm.update()
 * sets them, as VrmExpressions.update() does, so nothing else may.
 */
function boundByExpressions(vrm: ThreeVrmLike | null, file: VrmFile | null): Map<number[], Set<number>> {
  const out = new Map<number[], Set<number>>();
  const add = (influences: number[], at: number) => {
    if (!out.has(influences)) out.set(influences, new Set());
    out.get(influences)!.add(at);
  };
  for (const e of vrm?.expressionManager?.expressions ?? []) {
    for (const b of e.binds ?? []) for (const p of b.primitives ?? []) if (p.morphTargetInfluences && b.index !== undefined) add(p.morphTargetInfluences, b.index);
  }
  for (const e of file?.expressions.values() ?? []) for (const b of e.binds) add(b.influences, b.at);
  return out;
}

/** The message for an avatar with nothing to drive: its morph targets, or a VRM's expressions and what they hold. */
function noTargets(source: string, names: Set<string>, vrm: { names: string[]; unbound: string[]; boundNames: string[] } | null): AvatarLoadError {
  const list = (a: string[]) => `${a.slice(0, 60).join(', ')}${a.length > 60 ? ', …' : ''}`;
  if (vrm) {
    const lost = vrm.unbound.length ? ` (${list(vrm.unbound)} bind morph targets or nodes the file does not have)` : '';
    const held = vrm.boundNames.length ? ` Its morph targets ${list([...new Set(vrm.boundNames)])} are set by its other expressions only.` : '';
    return new AvatarLoadError(`${source} is a VRM with no vowel expressions (aa, ih, ou, ee, oh) that move a morph target, and no morph ` +
      `targets named after ARKit's 52 blend shapes or the 15 Oculus visemes that it leaves free; its expressions are: ${list(vrm.names) || 'none'}${lost}.${held} ` +
      `Bind its mouth's morph targets to aa, ih, ou, ee and oh (VRoid Studio; UniVRM's blend-shape clips) (docs/embedding.md, "Avatars").`);
  }
  const found = names.size
    ? `its morph targets are: ${list([...names])}. Rename them`
    : 'it has no morph targets at all: export it with its blend shapes (shape keys), named so';
  return new AvatarLoadError(`${source} has no morph targets named after ARKit's 52 blend shapes (jawOpen, eyeBlinkLeft, …) ` +
    `or the 15 Oculus visemes (viseme_aa, viseme_PP, …); ${found} (docs/embedding.md, "Avatars").`);
}
