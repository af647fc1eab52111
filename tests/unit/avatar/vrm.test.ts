/**
 * VRM avatars (src/avatar/vrm.ts, gltf-avatar.ts): the viseme -> vowel table is the non-negative least-squares mix
 * it says it is; the test avatars (VRoid's morph names, driven only through their VRM 1.0 or 0.x extension) bind
 * from a plain GLTFLoader and from @pixiv/three-vrm's VRMLoaderPlugin, and both give the same morph targets and the
 * same turn of the head bone; a VRM 0.x avatar (facing -z) nods and turns as a VRM 1.0 one does.
 */
import { beforeAll, describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import * as THREE from 'three';
import { GLTFLoader, type GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { VRMLoaderPlugin, VRMUtils, type VRM } from '@pixiv/three-vrm';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { AvatarDriver } from '../../../src/avatar/avatar-driver';
import { VISEME_VOWELS, VRM_VOWELS } from '../../../src/avatar/vrm';
import { arkitBasis, type ArkitBasis } from '../../../src/avatar/basis';
import { visemeAsArkit } from '../../../src/avatar/avatar-mesh';
import { ARKIT_NAMES, VISEME_NAMES } from '../../../src/avatar/names';
import { innerLipGaps } from '../../../src/template/lip-gap';
import { ROOT, loadManifest, loadTemplateFile } from '../helpers/exported';

const bytes = (name: string) => {
  const b = readFileSync(resolve(ROOT, 'examples/avatars', name));
  return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer;
};
async function load(name: string | ArrayBuffer, threeVrm: boolean): Promise<GLTF> {
  const loader = new GLTFLoader();
  if (threeVrm) loader.register((parser) => new VRMLoaderPlugin(parser));
  return loader.parseAsync(typeof name === 'string' ? bytes(name) : name, '');
}
/** A test VRM with its glTF JSON changed by `edit` (the binary chunk kept). */
function edited(name: string, edit: (json: any) => void): ArrayBuffer { // eslint-disable-line @typescript-eslint/no-explicit-any
  const b = Buffer.from(bytes(name));
  const length = b.readUInt32LE(12);
  const json = JSON.parse(b.subarray(20, 20 + length).toString());
  edit(json);
  let text = JSON.stringify(json);
  while (text.length % 4) text += ' ';
  const out = Buffer.concat([b.subarray(0, 12), Buffer.alloc(8), Buffer.from(text), b.subarray(20 + length)]);
  out.writeUInt32LE(out.length, 8);
  out.writeUInt32LE(text.length, 12);
  out.write('JSON', 16);
  return out.buffer.slice(out.byteOffset, out.byteOffset + out.length) as ArrayBuffer;
}
/** The face's influence of each named morph target, the same in each of its two primitives (meshes). */
const morphs = (gltf: GLTF) => {
  const meshes: THREE.Mesh[] = [];
  gltf.scene.traverse((o) => { if ((o as THREE.Mesh).morphTargetDictionary?.Fcl_MTH_I !== undefined) meshes.push(o as THREE.Mesh); });
  const [face, ...others] = meshes;
  expect(others.length).toBe(1);
  for (const other of others) expect(other.morphTargetInfluences).toEqual(face.morphTargetInfluences);
  return Object.fromEntries(Object.entries(face.morphTargetDictionary!).map(([n, i]) => [n, face.morphTargetInfluences![i]]));
};
const oneHot = (n: number, k: number, v = 1) => Float32Array.from({ length: n }, (_, i) => (i === k ? v : 0));
const arkitZero = new Float32Array(ARKIT_NAMES.length);

describe('VISEME_VOWELS', () => {
  let basis: ArkitBasis;
  let upper: Uint32Array, lower: Uint32Array;
  beforeAll(async () => {
    const t = await loadTemplateFile(loadManifest());
    basis = arkitBasis(t);
    upper = Uint32Array.from(t.regions.lips_inner_upper);
    lower = Uint32Array.from(t.regions.lips_inner_lower);
  });
  const n3 = () => basis.n * 3;
  const shapeOf = (arkit: Float32Array) => {
    const d = new Float64Array(n3());
    for (let k = 0; k < arkit.length; k++) if (arkit[k]) for (let i = 0; i < d.length; i++) d[i] += arkit[k] * basis.shapes[k * n3() + i];
    return d;
  };
  const dot = (a: Float64Array, b: Float64Array) => a.reduce((s, x, i) => s + x * b[i], 0);
  /** The exact non-negative least-squares mix of `cols` closest to `y` (every support tried: five columns). */
  function nnls(cols: Float64Array[], y: Float64Array): number[] {
    const G = cols.map((a) => cols.map((b) => dot(a, b))), r = cols.map((c) => dot(c, y));
    let best = cols.map(() => 0), bestErr = dot(y, y);
    for (let mask = 1; mask < 1 << cols.length; mask++) {
      const idx = cols.map((_, k) => k).filter((k) => mask & (1 << k));
      const A = idx.map((i) => idx.map((j) => G[i][j])), x = idx.map((i) => r[i]);
      for (let c = 0; c < idx.length; c++) for (let q = c + 1; q < idx.length; q++) {
        const f = A[q][c] / A[c][c];
        for (let z = c; z < idx.length; z++) A[q][z] -= f * A[c][z];
        x[q] -= f * x[c];
      }
      for (let c = idx.length - 1; c >= 0; c--) { for (let z = c + 1; z < idx.length; z++) x[c] -= A[c][z] * x[z]; x[c] /= A[c][c]; }
      if (x.some((v) => v < 0)) continue;
      const full = cols.map(() => 0);
      idx.forEach((k, j) => (full[k] = x[j]));
      let err = dot(y, y);
      for (let i = 0; i < full.length; i++) { err -= 2 * full[i] * r[i]; for (let j = 0; j < full.length; j++) err += full[i] * full[j] * G[i][j]; }
      if (err < bestErr - 1e-12) { bestErr = err; best = full; }
    }
    return best;
  }
  const gap = (arkit: Float32Array) => {
    const d = shapeOf(arkit);
    return innerLipGaps(Float32Array.from(basis.neutral, (x, i) => x + d[i]), 1, basis.n, upper, lower)[0];
  };
  const VOWEL_VISEMES = ['viseme_aa', 'viseme_I', 'viseme_U', 'viseme_E', 'viseme_O'] as const; // VRM_VOWELS order

  it('is the non-negative mix of the five vowels\' shapes closest to each viseme\'s, to 0.01', () => {
    const cols = VOWEL_VISEMES.map((v) => shapeOf(visemeAsArkit(v)));
    for (const [k, viseme] of VISEME_NAMES.entries()) {
      if (viseme === 'viseme_PP') continue;
      const mix = nnls(cols, shapeOf(visemeAsArkit(viseme)));
      for (let j = 0; j < 5; j++) expect(VISEME_VOWELS[k][j], `${viseme} ${VRM_VOWELS[j]}`).toBeCloseTo(mix[j], 2);
    }
  });

  it('gives PP none: its lips are closed, and the closest mix would part them', () => {
    expect(VISEME_VOWELS[VISEME_NAMES.indexOf('viseme_PP')]).toEqual([0, 0, 0, 0, 0]);
    const cols = VOWEL_VISEMES.map((v) => shapeOf(visemeAsArkit(v)));
    const mix = nnls(cols, shapeOf(visemeAsArkit('viseme_PP')));
    const mixed = new Float32Array(ARKIT_NAMES.length);
    mix.forEach((w, j) => visemeAsArkit(VOWEL_VISEMES[j]).forEach((x, k) => (mixed[k] += w * x)));
    expect(gap(visemeAsArkit('viseme_PP'))).toBeLessThan(0.5);
    expect(gap(mixed)).toBeGreaterThan(1);
  });
});

describe.each([['vrm1-face.vrm', '1'], ['vrm0-face.vrm', '0']] as const)('%s (VRM %s)', (file, version) => {
  it('binds its vowel and blink expressions and its humanoid head from a plain GLTFLoader, facing as its version does', async () => {
    const avatar = GltfAvatar.bind(await load(file, false), file);
    expect(avatar.summary).toEqual({ scheme: 'vrm', matched: [...VRM_VOWELS, 'blinkLeft', 'blinkRight'], headBone: 'Head' });
    expect(avatar.facing).toBe(version === '0' ? '-z' : '+z');
    expect(avatar.canBlink).toBe(true);
    expect(GltfAvatar.bind(await load(file, false), file, null, { facing: '+z' }).facing).toBe('+z');
  });

  it('moves the morph target each vowel binds, none on PP, blinks each eye', async () => {
    const gltf = await load(file, false);
    const avatar = GltfAvatar.bind(gltf, file);
    const V = VISEME_NAMES.length;
    avatar.setWeights(arkitZero, 0, oneHot(V, VISEME_NAMES.indexOf('viseme_aa'), 0.7), 0);
    expect(morphs(gltf)).toMatchObject({ Fcl_MTH_A: expect.closeTo(0.7, 6), Fcl_MTH_I: 0, Fcl_MTH_U: 0, Fcl_MTH_E: 0, Fcl_MTH_O: 0, Fcl_ALL_Joy: 0 });
    avatar.setWeights(arkitZero, 0, oneHot(V, VISEME_NAMES.indexOf('viseme_RR')), 0);
    expect(morphs(gltf)).toMatchObject({ Fcl_MTH_A: 0, Fcl_MTH_U: expect.closeTo(0.33, 6), Fcl_MTH_O: expect.closeTo(0.22, 6) });
    avatar.setWeights(oneHot(ARKIT_NAMES.length, ARKIT_NAMES.indexOf('eyeBlinkLeft'), 0.9), 0, oneHot(V, VISEME_NAMES.indexOf('viseme_PP')), 0);
    expect(morphs(gltf)).toMatchObject({ Fcl_MTH_A: 0, Fcl_MTH_I: 0, Fcl_MTH_U: 0, Fcl_MTH_E: 0, Fcl_MTH_O: 0,
      Fcl_EYE_Close_L: expect.closeTo(0.9, 6), Fcl_EYE_Close_R: 0, Fcl_EYE_Close: 0 });
    avatar.setIdleBlink(1);
    expect(morphs(gltf)).toMatchObject({ Fcl_EYE_Close_L: 1, Fcl_EYE_Close_R: 1 });
    avatar.setWeights(arkitZero, 0, oneHot(V, VISEME_NAMES.indexOf('viseme_aa')), 0);
    expect(morphs(gltf).Fcl_MTH_A).toBe(1);
    avatar.reset();
    expect(Object.values(morphs(gltf)).every((v) => v === 0 || v === 1)).toBe(true); // (the idle blink stays until its end)
    avatar.setIdleBlink(0);
    expect(Object.values(morphs(gltf)).every((v) => v === 0)).toBe(true);
  });

  it('with three-vrm, drives its expressions and normalized head to the same morph targets and head turn', async () => {
    const plainGltf = await load(file, false);
    const plain = new AvatarDriver(GltfAvatar.bind(plainGltf, file), 0, () => 0.5);
    const vrmGltf = await load(file, true);
    const vrm = vrmGltf.userData.vrm as VRM;
    VRMUtils.rotateVRM0(vrm); // as three-vrm's examples do: the page's choice, which the turn must not depend on
    const avatar = GltfAvatar.bind(vrmGltf, file);
    expect(avatar.summary.scheme).toBe('vrm');
    expect(avatar.facing).toBe(version === '0' ? '-z' : '+z');
    const driven = new AvatarDriver(avatar, 0, () => 0.5);
    const F = 3, V = VISEME_NAMES.length;
    const visemes = new Float32Array(F * V), arkit = new Float32Array(F * ARKIT_NAMES.length), pose = new Float32Array(F * 6);
    let seed = 7;
    const random = () => ((seed = (seed * 16807) % 2147483647) / 2147483647);
    visemes.forEach((_, i) => (visemes[i] = random() / 4));
    arkit.forEach((_, i) => (arkit[i] = random() / 2));
    pose.forEach((_, i) => (pose[i] = i % 6 < 3 ? (random() - 0.5) * 0.4 : 0));
    const take = { pose, blendshapes: { fps: 30, frames: F, arkit, visemes, headRotation: pose } };
    for (let f = 0; f < F; f++) {
      for (const d of [plain, driven]) { d.show(take as never, f); d.update(1000 + 200 * f); }
      vrm.update(1 / 30);
      for (const [name, value] of Object.entries(morphs(plainGltf))) expect(morphs(vrmGltf)[name], `frame ${f} ${name}`).toBeCloseTo(value, 5);
      const turn = (gltf: GLTF) => {
        gltf.scene.updateMatrixWorld(true);
        const head = gltf.scene.getObjectByName('Head')!.getWorldQuaternion(new THREE.Quaternion());
        return head.premultiply(gltf.scene.getWorldQuaternion(new THREE.Quaternion()).invert()); // in the avatar's frame
      };
      expect(turn(vrmGltf).angleTo(turn(plainGltf)), `frame ${f}`).toBeLessThan(1e-5);
    }
  });
});

it('a VRM 0.x avatar (facing -z) nods and turns as a VRM 1.0 one', async () => {
  const forwardUp = async (file: string) => {
    const gltf = await load(file, false);
    const avatar = GltfAvatar.bind(gltf, file);
    avatar.setHeadRotation(0.2, 0.15, -0.1);
    gltf.scene.updateMatrixWorld(true);
    const q = gltf.scene.getObjectByName('Head')!.getWorldQuaternion(new THREE.Quaternion());
    const own = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 1, 0), avatar.facing === '-z' ? -Math.PI : 0);
    return [new THREE.Vector3(0, 0, 1), new THREE.Vector3(0, 1, 0)].map((v) => v.applyQuaternion(q).applyQuaternion(own)); // in its own frame
  };
  const [f1, u1] = await forwardUp('vrm1-face.vrm'), [f0, u0] = await forwardUp('vrm0-face.vrm');
  expect(f1.y).toBeLessThan(-0.1); // a nod down (positive pitch)
  expect(f0.distanceTo(f1)).toBeLessThan(1e-6);
  expect(u0.distanceTo(u1)).toBeLessThan(1e-6);
});

/** VRM 1.0's expressions in an edited file's JSON. */
const expressionsOf = (json: { extensions: { VRMC_vrm: { expressions: { preset: Record<string, any>; custom?: Record<string, any> } } } }) => json.extensions.VRMC_vrm.expressions; // eslint-disable-line @typescript-eslint/no-explicit-any
const renamed = (json: { meshes: { extras?: { targetNames?: string[] } }[] }, from: string, to: string) => {
  for (const m of json.meshes) if (m.extras?.targetNames) m.extras.targetNames = m.extras.targetNames.map((n) => (n === from ? to : n));
};
/** One frame through a plain-loaded and a three-vrm-loaded copy of `file`: each one's morph targets after it is shown. */
async function bothWays(file: ArrayBuffer, arkit: Float32Array, visemes: Float32Array, idleBlink = 0) {
  const out = [];
  for (const threeVrm of [false, true]) {
    const gltf = await load(file.slice(0), threeVrm);
    const avatar = GltfAvatar.bind(gltf, 'edited.vrm');
    avatar.setWeights(arkit, 0, visemes, 0);
    avatar.setIdleBlink(idleBlink);
    (gltf.userData.vrm as VRM | undefined)?.update(0);
    out.push({ summary: avatar.summary, morphs: morphs(gltf) });
  }
  return out;
}
const V = VISEME_NAMES.length, A = ARKIT_NAMES.length;

describe('VRM files as people make them', () => {
  it('a perfect-sync VRM (ARKit-named targets and expressions) moves with three-vrm as with the plain loader', async () => {
    const file = edited('vrm1-face.vrm', (json) => {
      renamed(json, 'Fcl_MTH_A', 'jawOpen');
      const face = json.nodes.findIndex((n: { name?: string }) => n.name === 'Face');
      expressionsOf(json).custom = { jawOpen: { morphTargetBinds: [{ node: face, index: 0, weight: 1 }] } };
    });
    for (const { summary, morphs: m } of await bothWays(file, oneHot(A, ARKIT_NAMES.indexOf('jawOpen'), 0.8), new Float32Array(V))) {
      expect(summary).toEqual({ scheme: 'arkit', matched: ['jawOpen', 'blinkLeft', 'blinkRight'], headBone: expect.any(String) }); // (its blinks: the VRM's)
      expect(m.jawOpen, 'through its jawOpen expression: vrm.update() resets a target an expression binds').toBeCloseTo(0.8, 6);
    }
  });

  it('an ARKit-named target bound only by a vowel expression is reached through the vowels', async () => {
    const file = edited('vrm1-face.vrm', (json) => renamed(json, 'Fcl_MTH_A', 'jawOpen'));
    for (const { summary, morphs: m } of await bothWays(file, new Float32Array(A), oneHot(V, VISEME_NAMES.indexOf('viseme_aa'), 0.6))) {
      expect(summary.scheme).toBe('vrm');
      expect(m.jawOpen).toBeCloseTo(0.6, 6);
    }
  });

  it('binary expressions and overrides act as three-vrm has them, with the plain loader too', async () => {
    const file = edited('vrm1-face.vrm', (json) => {
      const { preset } = expressionsOf(json);
      preset.aa.isBinary = true;
      for (const b of ['blink', 'blinkLeft', 'blinkRight']) preset[b].overrideMouth = 'block';
    });
    const at = (v: number) => oneHot(V, VISEME_NAMES.indexOf('viseme_aa'), v);
    for (const [w, want] of [[0.4, 0], [0.7, 1]]) {
      for (const { morphs: m } of await bothWays(file, new Float32Array(A), at(w))) expect(m.Fcl_MTH_A, `aa ${w}`).toBe(want);
    }
    // The model's own small eyeBlink weights do not block the mouth; an idle blink does, while it lasts.
    const small = oneHot(A, ARKIT_NAMES.indexOf('eyeBlinkLeft'), 0.04);
    for (const { morphs: m } of await bothWays(file, small, at(0.7))) expect([m.Fcl_MTH_A, m.Fcl_EYE_Close_L]).toEqual([1, 0]);
    for (const { morphs: m } of await bothWays(file, small, at(0.7), 1)) expect([m.Fcl_MTH_A, m.Fcl_EYE_Close_L]).toEqual([0, 1]);
  });

  it('binds to what the file does not have are left out: empty blinkLeft / Right leave blink; vowels bound to nothing are named', async () => {
    const blinkBinds = (left: object, right: object) => edited('vrm1-face.vrm', (json) => {
      const { preset } = expressionsOf(json);
      Object.assign(preset.blinkLeft.morphTargetBinds[0], left);
      Object.assign(preset.blinkRight.morphTargetBinds[0], right);
    });
    for (const { summary, morphs: m } of await bothWays(blinkBinds({ index: 99 }, { index: 50 }), new Float32Array(A), new Float32Array(V), 1)) {
      expect(summary.matched).toEqual([...VRM_VOWELS, 'blink']);
      expect(m.Fcl_EYE_Close).toBe(1);
    }
    // (a bind to a node the file lacks: three-vrm 3.5.5 throws on it where no one catches it, so the plain loader only)
    const avatar = GltfAvatar.bind(await load(blinkBinds({ node: 999 }, { index: -1 }), false), 'lost.vrm');
    expect(avatar.summary.matched).toEqual([...VRM_VOWELS, 'blink']);
    const mute = edited('vrm1-face.vrm', (json) => { for (const v of VRM_VOWELS) expressionsOf(json).preset[v].morphTargetBinds[0].index = 99; });
    await expect(load(mute, false).then((g) => GltfAvatar.bind(g, 'mute.vrm'))).rejects.toThrow(
      /mute\.vrm is a VRM with no vowel expressions .* its expressions are: aa, ih, ou, ee, oh, blink, blinkLeft, blinkRight, happy \(aa, ih, ou, ee, oh bind morph targets or nodes the file does not have\)\. Bind its mouth's morph targets/);
    await expect(load(mute, true).then((g) => GltfAvatar.bind(g, 'mute.vrm'))).rejects.toThrow(/mute\.vrm is a VRM with no vowel expressions/);
  });

  it('with three-vrm the head turns through its normalized bone: without expressions, and when the head bone is named', async () => {
    const bare = edited('vrm1-face.vrm', (json) => { delete json.extensions.VRMC_vrm.expressions; renamed(json, 'Fcl_MTH_A', 'jawOpen'); });
    for (const [file, headBone] of [[bare, null], [bytes('vrm1-face.vrm'), 'Head']] as const) {
      const gltf = await load(file.slice(0), true);
      const avatar = GltfAvatar.bind(gltf, 'turned.vrm', headBone);
      expect(avatar.summary.headBone).toBe('Normalized_Head');
      avatar.setHeadRotation(0.3, 0, 0);
      (gltf.userData.vrm as VRM).update(0);
      const q = gltf.scene.getObjectByName('Head')!.quaternion;
      expect(2 * Math.acos(Math.min(1, Math.abs(q.w))), String(headBone)).toBeCloseTo(0.3, 5);
    }
  });

  it('says what to give it: the gltf, not three-vrm\'s VRM; a file cut short', async () => {
    const gltf = await load('vrm1-face.vrm', true);
    expect(() => GltfAvatar.bind(gltf.userData.vrm, 'me.vrm')).toThrow(/give what GLTFLoader gave \(gltf\), not gltf\.userData\.vrm/);
    await expect(GltfAvatar.parse(bytes('vrm1-face.vrm').slice(0, 60_000), 'cut.vrm')).rejects.toThrow(/cut\.vrm is cut short: its header says \d+ bytes, 60000 came/);
  });
});
