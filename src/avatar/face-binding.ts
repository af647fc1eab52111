/**
 * What drives a glTF avatar's face (gltf-avatar.ts binds it): its morph targets found by ARKit or Oculus viseme name
 * (names.ts), or a VRM's expressions (vrm.ts); its blinks; its head bone. A VRM's morph target that one of its
 * expressions binds is driven through an expression named after its shape (a "perfect sync" VRM's) or not at all:
 * its expressions set it (three-vrm's vrm.update(), or VrmExpressions here), so the plain loader and three-vrm agree.
 */
import type * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { ARKIT_INDEX, ARKIT_NAMES, VISEME_NAMES, arkitIndexOf, visemeIndexOf } from './names';
import { VRM_VOWELS, VrmExpressions, readVrm, threeVrmOf, type ExpressionManagerLike, type ThreeVrmLike, type VrmFile } from './vrm';
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
  /** [expression, blink channel: 0 left, 1 right, 2 both]. */
  blinks: [string, number][];
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

const isMouth = (channel: number) => /^(jaw|mouth)/.test(ARKIT_NAMES[channel]);
const isBlink = (channel: number) => channel === ARKIT_INDEX.eyeBlinkLeft || channel === ARKIT_INDEX.eyeBlinkRight;

export function bindFace(gltf: GLTF, source: string, headBone?: string | null): FaceBinding {
  const threeVrm = threeVrmOf(gltf);
  const file = threeVrm ? null : readVrm(gltf);
  const bound = threeVrm || file ? boundByExpressions(threeVrm, file) : null;
  const arkit: Target[] = [], visemes: Target[] = [];
  const names = new Set<string>();
  gltf.scene.traverse((o) => {
    const mesh = o as THREE.Mesh;
    if (!mesh.morphTargetDictionary || !mesh.morphTargetInfluences) return;
    for (const [name, at] of Object.entries(mesh.morphTargetDictionary)) {
      names.add(name);
      if (bound?.get(mesh.morphTargetInfluences)?.has(at)) continue; // a VRM's expression sets it: through one only
      const a = arkitIndexOf(name), v = visemeIndexOf(name);
      if (a >= 0) arkit.push({ influences: mesh.morphTargetInfluences, at, channel: a, weight: 1 });
      if (v >= 0) visemes.push({ influences: mesh.morphTargetInfluences, at, channel: v, weight: 1 });
    }
  });
  const threeExpressions = threeVrm?.expressionManager?.expressions ?? [];
  const expressionNames = threeVrm ? threeExpressions.map((e) => e.expressionName) : [...(file?.expressions.keys() ?? [])];
  // An expression that moves a morph target (three-vrm's binds also set materials).
  const moves = (name: string) => threeVrm
    ? !!threeExpressions.find((e) => e.expressionName === name)?.binds?.some((b) => b.primitives?.length)
    : !!file?.expressions.get(name)?.binds.length;
  // A VRM's expressions named after ARKit's shapes (a perfect-sync VRM's): their morph targets are reached so.
  const arkitExpressions = expressionNames.map((n) => [n, arkitIndexOf(n)] as [string, number]).filter(([n, c]) => c >= 0 && moves(n));
  // A few ARKit eye shapes beside the visemes (blinks, often) do not make an ARKit rig: the mouth decides.
  const arkitMouth = arkit.some((t) => isMouth(t.channel)) || arkitExpressions.some(([, c]) => isMouth(c));
  const vowels = VRM_VOWELS.map(moves);
  if (!arkit.length && !arkitExpressions.length && !visemes.length && !vowels.some(Boolean)) {
    throw noTargets(source, names, threeVrm || file ? expressionNames : null, file?.unbound ?? []);
  }
  const scheme: AvatarScheme = arkitMouth || (!visemes.length && !vowels.some(Boolean)) ? 'arkit' : visemes.length ? 'visemes' : 'vrm';

  const vrmVersion = threeVrm ? threeVrm.meta?.metaVersion ?? null : file?.version ?? null;
  const manager = threeVrm?.expressionManager ?? (file ? new VrmExpressions(file) : null);
  // Blinks: ARKit's eyeBlinkLeft / Right (targets, or three-vrm's expressions so named), else a VRM's blinkLeft and
  // blinkRight, else its blink (channel 2: both eyes).
  const blinkTargets = arkit.filter((t) => isBlink(t.channel)).map((t) => ({ ...t, channel: t.channel === ARKIT_INDEX.eyeBlinkLeft ? 0 : 1 }));
  let blinks = arkitExpressions.filter(([, c]) => isBlink(c)).map(([n, c]) => [n, c === ARKIT_INDEX.eyeBlinkLeft ? 0 : 1] as [string, number]);
  const vrmBlinks = moves('blinkLeft') && moves('blinkRight') ? ['blinkLeft', 'blinkRight'] : moves('blink') ? ['blink'] : [];
  const blinkByVrm = !blinkTargets.length && !blinks.length && vrmBlinks.length > 0;
  if (blinkByVrm) blinks = vrmBlinks.map((name) => [name, ['blinkLeft', 'blinkRight', 'blink'].indexOf(name)]);
  const face: [string, number][] = scheme === 'arkit' ? arkitExpressions.filter(([, c]) => !isBlink(c))
    : scheme === 'vrm' ? VRM_VOWELS.map((name, k) => [name, k] as [string, number]).filter((_, k) => vowels[k]) : [];
  const expressions = manager && (face.length || blinks.length) ? { manager, own: manager instanceof VrmExpressions ? manager : null, face, blinks } : null;

  const targets = scheme === 'arkit' ? arkit : scheme === 'visemes' ? visemes : [];
  const matched = scheme === 'arkit'
    ? [...new Set([...arkit.map((t) => t.channel), ...arkitExpressions.map(([, c]) => c)])].sort((x, y) => x - y).map((c) => ARKIT_NAMES[c])
    : scheme === 'visemes' ? [...new Set(visemes.map((t) => VISEME_NAMES[t.channel]))] : face.map(([name]) => name);
  if (blinkByVrm) matched.push(...vrmBlinks);
  return { scheme, targets, blinkTargets, expressions, matched, head: headOf(gltf, source, headBone, threeVrm, file), vrmVersion };
}

/**
 * The head bone: the one named `headBone`, else a VRM's humanoid head, else findHead's. With three-vrm, a humanoid
 * bone is turned through its normalized node, which vrm.update() copies to it (the bone itself it would reset).
 */
function headOf(gltf: GLTF, source: string, headBone: string | null | undefined, threeVrm: ThreeVrmLike | null, file: VrmFile | null): THREE.Object3D | null {
  const humanoid = threeVrm?.humanoid;
  if (!headBone) {
    const own = humanoid?.getNormalizedBoneNode('head') ?? file?.head;
    if (own) return own;
  }
  const head = findHead(gltf.scene, source, headBone);
  const human = Object.entries(humanoid?.humanBones ?? {}).find(([, b]) => b?.node === head)?.[0];
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

/** The message for an avatar with nothing to drive: its morph targets, or a VRM's expressions and its binds to nothing. */
function noTargets(source: string, names: Set<string>, expressions: string[] | null, unbound: string[]): AvatarLoadError {
  const list = (a: string[]) => `${a.slice(0, 60).join(', ')}${a.length > 60 ? ', …' : ''}`;
  if (expressions) {
    const lost = unbound.length ? ` (${list(unbound)} bind morph targets or nodes the file does not have)` : '';
    return new AvatarLoadError(`${source} is a VRM with no vowel expressions (aa, ih, ou, ee, oh) that move a morph target, and no morph ` +
      `targets named after ARKit's 52 blend shapes or the 15 Oculus visemes; its expressions are: ${list(expressions) || 'none'}${lost}. ` +
      `Bind its mouth's morph targets to aa, ih, ou, ee and oh (VRoid Studio; UniVRM's blend-shape clips) (docs/embedding.md, "Avatars").`);
  }
  const found = names.size
    ? `its morph targets are: ${list([...names])}. Rename them`
    : 'it has no morph targets at all: export it with its blend shapes (shape keys), named so';
  return new AvatarLoadError(`${source} has no morph targets named after ARKit's 52 blend shapes (jawOpen, eyeBlinkLeft, …) ` +
    `or the 15 Oculus visemes (viseme_aa, viseme_PP, …); ${found} (docs/embedding.md, "Avatars").`);
}
