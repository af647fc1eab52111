/**
 * The template as a glTF avatar, made from the ARKit basis (basis.ts): a mesh whose morph targets are named
 * after ARKit's 52 shapes (or the 15 Oculus visemes, each a mix of them), hung under a node named "Head" at the
 * template's origin, the point the model's head pose turns about. The weights export (export.ts) and the test
 * avatars (scripts/make-avatars.ts) are built from it. glTF's units are metres; +y up, the face towards +z.
 */
import * as THREE from 'three';
import type { FaceTemplate } from '../template/face-template';
import { ARKIT_INDEX, ARKIT_NAMES, VISEME_NAMES, type ArkitName, type VisemeName } from './names';
import { FUNNEL, JAW_OPEN_DEGREES, PUCKER, arkitBasis, type ArkitBasis } from './basis';

const SKIN = 0xe0ac8e;
/** The corpus rig's jaw at 1 (rig.py RigScale.jaw_degrees): its jaw parameter in jawOpen units is jaw * this. */
const RIG_JAW = 8 / JAW_OPEN_DEGREES;

/**
 * Each viseme as ARKit weights, made from the corpus rig's target for a phone it stands for
 * (training/src/talkingface/corpus/visemes.py: jaw, lip_open, round, protrude, spread, close, labiodental) with
 * the basis's correspondences: jaw -> jawOpen, lip_open -> mouthUpperUp / mouthLowerDown, rounding ->
 * mouthPucker, protrusion -> mouthFunnel, spreading -> half mouthSmile and half mouthStretch, closure ->
 * mouthClose as much as the jaw opens, the lower lip to the teeth -> mouthRollLower.
 */
const VISEME_PHONES: Record<VisemeName, [number, number, number, number, number, number, number]> = {
  //            jaw   lip_open round protrude spread close labiodental
  viseme_sil: [0, 0, 0, 0, 0, 0, 0],
  viseme_PP: [0.1, 0, 0, 0, 0, 1, 0], // P
  viseme_FF: [0.15, 0, 0, 0, 0, 0, 1], // F
  viseme_TH: [0.25, 0.25, 0, 0, 0, 0, 0], // TH
  viseme_DD: [0.25, 0.15, 0, 0, 0, 0, 0], // T
  viseme_kk: [0.3, 0.2, 0, 0, 0, 0, 0], // K
  viseme_CH: [0.15, 0.2, 0.55, 0.7, 0, 0, 0], // CH
  viseme_SS: [0.1, 0.12, 0, 0, 0.4, 0, 0], // S
  viseme_nn: [0.25, 0.15, 0, 0, 0, 0, 0], // N
  viseme_RR: [0.2, 0.15, 0.5, 0.4, 0, 0, 0], // R
  viseme_aa: [0.95, 0.65, 0, 0, 0.1, 0, 0], // AA
  viseme_E: [0.55, 0.4, 0, 0, 0.35, 0, 0], // EH
  viseme_I: [0.35, 0.3, 0, 0, 0.45, 0, 0], // IH
  viseme_O: [0.55, 0.35, 0.8, 0.55, 0, 0, 0], // OW
  viseme_U: [0.2, 0.15, 1, 0.85, 0, 0, 0], // UW
};

/** A viseme's ARKit weights (52, ARKIT_NAMES order). */
export function visemeAsArkit(viseme: VisemeName): Float32Array {
  const [jaw, open, round, protrude, spread, close, labio] = VISEME_PHONES[viseme];
  const w = new Float32Array(ARKIT_NAMES.length);
  const set = (name: ArkitName, v: number) => (w[ARKIT_INDEX[name]] = Math.min(1, Math.max(0, v)));
  set('jawOpen', jaw * RIG_JAW);
  set('mouthClose', close * jaw * RIG_JAW);
  for (const side of ['Left', 'Right'] as const) {
    set(`mouthUpperUp${side}`, open * 0.5); // the rig raises the upper lip 0.06 W, mouthUpperUp 0.12 W
    set(`mouthLowerDown${side}`, open * 0.42); // 0.05 W against 0.12 W
    set(`mouthSmile${side}`, spread * 0.5);
    set(`mouthStretch${side}`, spread * 0.5);
  }
  // The rig's rounding narrows the lips by 0.28 of their half-width and moves them 0.04 W forward; its protrusion
  // moves them 0.09 W forward. Pucker (a) and funnel (b) give the same narrowing and the same forward motion:
  //   PUCKER.narrow a + FUNNEL.narrow b = 0.28 round,   PUCKER.forward a + FUNNEL.forward b = 0.04 round + 0.09 protrude.
  const narrow = 0.28 * round, forward = 0.04 * round + 0.09 * protrude;
  const det = PUCKER.narrow * FUNNEL.forward - FUNNEL.narrow * PUCKER.forward;
  set('mouthPucker', (narrow * FUNNEL.forward - FUNNEL.narrow * forward) / det);
  set('mouthFunnel', (PUCKER.narrow * forward - narrow * PUCKER.forward) / det);
  set('mouthRollLower', labio * 0.6);
  return w;
}

/** A morph target of another naming scheme, made as a mix of the ARKit shapes (52 weights). */
export type MorphAsArkit = readonly [name: string, arkit: Float32Array];

export interface AvatarMeshOptions {
  /** Which morph targets the mesh has: ARKit's 52, the 15 visemes, or the ones listed. */
  morphs: 'arkit' | 'visemes' | readonly MorphAsArkit[];
  /** The mesh's name (animation tracks refer to it). */
  name?: string;
}

/** The template's neutral face (lips closed) with named morph targets, under a "Head" node; in metres. */
export function avatarScene(template: FaceTemplate, basis: ArkitBasis, options: AvatarMeshOptions): { scene: THREE.Scene; mesh: THREE.Mesh; head: THREE.Object3D } {
  const toMetres = 1 / 1000; // the basis is in mm
  const n3 = basis.n * 3;
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(basis.neutral, (x) => x * toMetres), 3));
  geometry.setIndex(new THREE.BufferAttribute(template.triangles, 1));
  const shape = (k: number) => basis.shapes.subarray(k * n3, (k + 1) * n3);
  const targets: THREE.BufferAttribute[] = [];
  const morphs: readonly MorphAsArkit[] = options.morphs === 'arkit' ? [] : options.morphs === 'visemes'
    ? VISEME_NAMES.map((name) => [name, visemeAsArkit(name)] as const) : options.morphs;
  const names: string[] = options.morphs === 'arkit' ? [...ARKIT_NAMES] : morphs.map(([name]) => name);
  for (const [j, name] of names.entries()) {
    const d = new Float32Array(n3);
    if (options.morphs === 'arkit') d.set(shape(ARKIT_INDEX[name as ArkitName]));
    else {
      const w = morphs[j][1];
      for (let k = 0; k < w.length; k++) if (w[k]) for (let i = 0; i < n3; i++) d[i] += w[k] * shape(k)[i];
    }
    for (let i = 0; i < n3; i++) d[i] *= toMetres;
    const attribute = new THREE.BufferAttribute(d, 3);
    attribute.name = name;
    targets.push(attribute);
  }
  geometry.morphAttributes.position = targets;
  geometry.morphTargetsRelative = true;
  geometry.computeVertexNormals();
  const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ color: SKIN, roughness: 0.6, side: THREE.DoubleSide }));
  mesh.name = options.name ?? 'face';
  mesh.updateMorphTargets(); // names -> morphTargetDictionary, which the exporter writes as extras.targetNames
  const head = new THREE.Bone();
  head.name = 'Head';
  head.add(mesh, ...eyesAndMouth(template, basis.neutral, toMetres));
  const scene = new THREE.Scene();
  scene.add(head);
  return { scene, mesh, head };
}

/**
 * What the template mask lacks behind its openings (as the face view draws them, render/face-view.ts): an eyeball
 * behind each lid opening, sized from it, and a dark backing behind the lips. They turn with the head.
 */
function eyesAndMouth(template: FaceTemplate, neutral: Float32Array, scale: number): THREE.Mesh[] {
  const r = template.regions;
  const box = (idx: ArrayLike<number>) => {
    const b = new THREE.Box3();
    for (let i = 0; i < idx.length; i++) b.expandByPoint(new THREE.Vector3().fromArray(neutral, 3 * idx[i]).multiplyScalar(scale));
    return { center: b.getCenter(new THREE.Vector3()), size: b.getSize(new THREE.Vector3()), min: b.min, max: b.max };
  };
  const out: THREE.Mesh[] = [];
  for (const side of ['left', 'right'] as const) {
    const lids = box([...r[`eye_${side}_upper`], ...r[`eye_${side}_lower`]]);
    const radius = lids.size.x * 0.62;
    const eye = new THREE.Mesh(new THREE.SphereGeometry(radius, 16, 12), new THREE.MeshStandardMaterial({ color: 0xf4f1ec, roughness: 0.25 }));
    eye.name = `eye_${side}`;
    eye.position.set(lids.center.x, lids.center.y, lids.max.z - radius - lids.size.z * 0.15);
    const iris = new THREE.Mesh(new THREE.CircleGeometry(radius * 0.34, 16), new THREE.MeshStandardMaterial({ color: 0x3b2a1e, roughness: 0.3 }));
    iris.name = `iris_${side}`;
    iris.position.z = radius * 1.001;
    eye.add(iris);
    out.push(eye);
  }
  const inner = box([...r.lips_inner_upper, ...r.lips_inner_lower]);
  const outer = box(r.lips_outer);
  const mouth = new THREE.Mesh(new THREE.SphereGeometry(1, 16, 12), new THREE.MeshStandardMaterial({ color: 0x2a0a0c, roughness: 0.9 }));
  mouth.name = 'mouth_backing';
  mouth.scale.set(inner.size.x * 0.48, outer.size.y * 0.9, inner.size.x * 0.4);
  mouth.position.set(inner.center.x, inner.center.y - outer.size.y * 0.15, outer.min.z - inner.size.x * 0.18);
  out.push(mouth);
  return out;
}

/** A test avatar as .glb bytes: the template with ARKit (or viseme) morph targets under a "Head" node. */
export async function buildAvatarGlb(template: FaceTemplate, morphs: 'arkit' | 'visemes'): Promise<ArrayBuffer> {
  const { scene, mesh } = avatarScene(template, arkitBasis(template), { morphs, name: morphs === 'arkit' ? 'face_arkit' : 'face_visemes' });
  const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
  const bytes = (await new GLTFExporter().parseAsync(scene, { binary: true })) as ArrayBuffer;
  mesh.geometry.dispose();
  (mesh.material as THREE.Material).dispose();
  return bytes;
}
