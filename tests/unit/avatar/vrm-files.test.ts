/**
 * VRM files as people make them (the VRM test avatars edited: perfect sync, ARKit- or viseme-named targets bound by
 * the vowels, binary and overriding expressions, shared binds, binds to nothing, duplicate or misnamed expressions, a
 * child node on its parent's mesh, no expressions), each bound by a plain GLTFLoader and by @pixiv/three-vrm: the
 * same scheme and the same morph targets both ways, the head turned through three-vrm's normalized bone, and the
 * messages for what cannot be used.
 */
import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { VRMLoaderPlugin, type VRM } from '@pixiv/three-vrm';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { VISEME_VOWELS, VRM_VOWELS, VrmExpressions, readVrm } from '../../../src/avatar/vrm';
import { ARKIT_NAMES, VISEME_NAMES } from '../../../src/avatar/names';
import { A, V, bothWays, bytes, edited, expressionsOf, load, oneHot, renamed } from '../helpers/vrm';

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
    for (const [w, want] of [[0.4, 0], [0.5, 0], [0.7, 1]]) {
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

  it('with three-vrm set not to copy the normalized bones, the head turns through its own bone', async () => {
    const loader = new GLTFLoader();
    loader.register((parser) => new VRMLoaderPlugin(parser, { autoUpdateHumanBones: false }));
    const gltf = await loader.parseAsync(bytes('vrm1-face.vrm'), '');
    const avatar = GltfAvatar.bind(gltf, 'still.vrm');
    expect(avatar.summary.headBone).toBe('Head');
    avatar.setHeadRotation(0.3, 0, 0);
    (gltf.userData.vrm as VRM).update(0);
    const q = gltf.scene.getObjectByName('Head')!.quaternion;
    expect(2 * Math.acos(Math.min(1, Math.abs(q.w)))).toBeCloseTo(0.3, 5);
  });

  it('says what to give it: the gltf, not three-vrm\'s VRM; a file cut short', async () => {
    const gltf = await load('vrm1-face.vrm', true);
    expect(() => GltfAvatar.bind(gltf.userData.vrm, 'me.vrm')).toThrow(/give what GLTFLoader gave \(gltf\), not gltf\.userData\.vrm/);
    await expect(GltfAvatar.parse(bytes('vrm1-face.vrm').slice(0, 60_000), 'cut.vrm')).rejects.toThrow(/cut\.vrm is cut short: its header says \d+ bytes, 60000 came/);
  });
});

describe('VRM expressions as three-vrm applies them, with the plain loader too', () => {
  const aa = (w: number) => oneHot(V, VISEME_NAMES.indexOf('viseme_aa'), w);
  const same = async (file: ArrayBuffer, arkit: Float32Array, visemes: Float32Array, idle = 0) => {
    const [plain, three] = await bothWays(file, arkit, visemes, idle);
    for (const [morph, value] of Object.entries(three.morphs)) expect(plain.morphs[morph], morph).toBeCloseTo(value, 6);
    expect({ ...plain.summary, headBone: null }).toEqual({ ...three.summary, headBone: null }); // (three-vrm's: its normalized head)
    return plain;
  };
  const withoutHappy = (json: any) => { delete expressionsOf(json).preset.happy; }; // eslint-disable-line @typescript-eslint/no-explicit-any

  it('a VRM whose vowels bind viseme-named targets, one viseme left free, speaks through its vowels', async () => {
    const file = edited('vrm1-face.vrm', (json) => {
      for (const [v, viseme] of [['A', 'aa'], ['I', 'I'], ['U', 'U'], ['E', 'E'], ['O', 'O']]) renamed(json, `Fcl_MTH_${v}`, `viseme_${viseme}`);
      withoutHappy(json);
      renamed(json, 'Fcl_ALL_Joy', 'viseme_PP');
    });
    const m = await same(file, new Float32Array(A), aa(0.8));
    expect(m.summary.scheme).toBe('vrm');
    expect(m.morphs.viseme_aa).toBeCloseTo(0.8, 6);
  });

  it('a VRM whose aa binds jawOpen, another ARKit shape left free, opens its jaw through aa', async () => {
    const file = edited('vrm1-face.vrm', (json) => { renamed(json, 'Fcl_MTH_A', 'jawOpen'); withoutHappy(json); renamed(json, 'Fcl_ALL_Joy', 'mouthSmileLeft'); });
    const m = await same(file, new Float32Array(A), aa(0.8));
    expect(m.summary.scheme).toBe('vrm');
    expect(m.morphs.jawOpen).toBeCloseTo(0.8, 6);
  });

  it('overrides: block at any weight, blend by the weight; a binary expression scaled below 1 is off', async () => {
    const overriding = (mouth: string, binary = false) => edited('vrm1-face.vrm', (json) => {
      const { preset } = expressionsOf(json);
      for (const b of ['blink', 'blinkLeft', 'blinkRight']) preset[b].overrideMouth = mouth;
      preset.aa.isBinary = binary;
    });
    expect((await same(overriding('block'), new Float32Array(A), aa(0.7), 0.3)).morphs.Fcl_MTH_A).toBe(0);
    expect((await same(overriding('blend'), new Float32Array(A), aa(0.7), 0.3)).morphs.Fcl_MTH_A).toBeCloseTo(0.7 * (1 - 0.3 - 0.3), 6);
    expect((await same(overriding('blend', true), new Float32Array(A), aa(0.7), 0.3)).morphs.Fcl_MTH_A).toBe(0);
    const vowelBlocksBlinks = edited('vrm1-face.vrm', (json) => { expressionsOf(json).preset.aa.overrideBlink = 'block'; });
    expect((await same(vowelBlocksBlinks, new Float32Array(A), aa(0.7), 1)).morphs).toMatchObject({ Fcl_MTH_A: expect.closeTo(0.7, 6), Fcl_EYE_Close_L: 0 });
  });

  it('two expressions binding one target add; a weight above 1 counts as 1', async () => {
    const shared = edited('vrm1-face.vrm', (json) => {
      const face = json.nodes.findIndex((n: { name?: string }) => n.name === 'Face');
      expressionsOf(json).preset.ih.morphTargetBinds.push({ node: face, index: 0, weight: 0.5 });
    });
    const th = oneHot(V, VISEME_NAMES.indexOf('viseme_TH'));
    const [aaOfTh, ihOfTh] = [VISEME_VOWELS[VISEME_NAMES.indexOf('viseme_TH')][0], VISEME_VOWELS[VISEME_NAMES.indexOf('viseme_TH')][1]];
    expect((await same(shared, new Float32Array(A), th)).morphs.Fcl_MTH_A).toBeCloseTo(aaOfTh + 0.5 * ihOfTh, 6);
    const file = readVrm(await load('vrm1-face.vrm', false))!;
    const expressions = new VrmExpressions(file);
    expressions.setValue('aa', 1.5);
    expressions.update();
    expect(file.expressions.get('aa')!.binds.map((b) => b.influences[b.at])).toEqual([1, 1]);
  });

  it('as three-vrm reads a file: a VRM 0.x preset\'s first group, a VRM 1.0 preset\'s own name, a node\'s own primitives', async () => {
    const twice = edited('vrm0-face.vrm', (json) => {
      const groups = json.extensions.VRM.blendShapeMaster.blendShapeGroups;
      groups.push({ name: 'A2', presetName: 'a', binds: [{ mesh: groups[0].binds[0].mesh, index: 8, weight: 100 }] });
    });
    expect((await same(twice, new Float32Array(A), aa(0.7))).morphs.Fcl_ALL_Joy).toBe(0);
    const odd = edited('vrm1-face.vrm', (json) => {
      const face = json.nodes.findIndex((n: { name?: string }) => n.name === 'Face');
      const e = expressionsOf(json);
      e.custom = { aa: { morphTargetBinds: [{ node: face, index: 4, weight: 1 }] } }; // a custom named as a preset: left out
      e.preset.jawOpen = { morphTargetBinds: [{ node: face, index: 0, weight: 1 }] }; // no preset of VRM 1.0's: left out
    });
    const m = await same(odd, new Float32Array(A), aa(0.7));
    expect([m.summary.scheme, m.morphs.Fcl_MTH_A, m.morphs.Fcl_MTH_O]).toEqual(['vrm', expect.closeTo(0.7, 6), 0]);
    // A child node that uses its parent's mesh is a node of its own, not one of the parent's primitives (the face of
    // one primitive here: three.js makes each node that mesh, the child under the parent).
    const nested = edited('vrm1-face.vrm', (json) => {
      const face = json.nodes.findIndex((n: { name?: string }) => n.name === 'Face');
      json.meshes[json.nodes[face].mesh].primitives.splice(1);
      json.nodes.push({ name: 'FaceCopy', mesh: json.nodes[face].mesh, translation: [0, 0, 0.5] });
      json.nodes[face].children = [...(json.nodes[face].children ?? []), json.nodes.length - 1];
    });
    for (const threeVrm of [false, true]) {
      const gltf = await load(nested.slice(0), threeVrm);
      GltfAvatar.bind(gltf, 'nested.vrm').setWeights(new Float32Array(A), 0, aa(0.7), 0);
      (gltf.userData.vrm as VRM | undefined)?.update(0);
      const copy: number[] = [];
      gltf.scene.getObjectByName('FaceCopy')!.traverse((o) => { const i = (o as THREE.Mesh).morphTargetDictionary?.Fcl_MTH_A; if (i !== undefined) copy.push((o as THREE.Mesh).morphTargetInfluences![i]); });
      expect(copy, String(threeVrm)).toEqual([0]);
    }
  });

  it('names the ARKit targets its other expressions hold, where nothing is left to drive', async () => {
    const held = edited('vrm1-face.vrm', (json) => {
      renamed(json, 'Fcl_ALL_Joy', 'jawOpen');
      for (const v of VRM_VOWELS) delete expressionsOf(json).preset[v];
    });
    for (const threeVrm of [false, true]) {
      await expect(load(held.slice(0), threeVrm).then((g) => GltfAvatar.bind(g, 'held.vrm'))).rejects.toThrow(/Its morph targets jawOpen are set by its other expressions only/);
    }
  });
});
