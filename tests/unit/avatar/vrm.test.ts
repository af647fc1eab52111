/**
 * VRM avatars (src/avatar/vrm.ts, gltf-avatar.ts): the viseme -> vowel table is the non-negative least-squares mix
 * it says it is; the test avatars (VRoid's morph names, driven only through their VRM 1.0 or 0.x extension) bind
 * from a plain GLTFLoader and from @pixiv/three-vrm's VRMLoaderPlugin, and both give the same morph targets and the
 * same turn of the head bone; a VRM 0.x avatar (facing -z) nods and turns as a VRM 1.0 one does.
 */
import { beforeAll, describe, expect, it } from 'vitest';
import * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { VRMUtils, type VRM } from '@pixiv/three-vrm';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { AvatarDriver } from '../../../src/avatar/avatar-driver';
import { VISEME_VOWELS, VRM_BLINK_FLOOR, VRM_VOWELS } from '../../../src/avatar/vrm';
import { arkitBasis, type ArkitBasis } from '../../../src/avatar/basis';
import { visemeAsArkit } from '../../../src/avatar/avatar-mesh';
import { ARKIT_NAMES, VISEME_NAMES } from '../../../src/avatar/names';
import { innerLipGaps } from '../../../src/template/lip-gap';
import { loadManifest, loadTemplateFile } from '../helpers/exported';
import { arkitZero, load, morphs, oneHot } from '../helpers/vrm';

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
      Fcl_EYE_Close_L: expect.closeTo((0.9 - VRM_BLINK_FLOOR) / (1 - VRM_BLINK_FLOOR), 6), Fcl_EYE_Close_R: 0, Fcl_EYE_Close: 0 });
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
