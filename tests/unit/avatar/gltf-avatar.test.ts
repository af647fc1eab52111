/**
 * Binding a glTF avatar (src/avatar/gltf-avatar.ts) in Node: the project's test avatars (examples/avatars/, exactly
 * what npm run make-avatars writes), which naming scheme drives them, the head bone found and turned about its
 * pivot under a rotated parent, the idle blink, and the messages for files that cannot be used.
 */
import { beforeAll, describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { ARKIT_NAMES, VISEME_NAMES } from '../../../src/avatar/names';
import { AVATARS, makeAvatars } from '../../../scripts/make-avatars';
import { ROOT } from '../helpers/exported';

const file = (name: string) => {
  const b = readFileSync(resolve(ROOT, 'examples/avatars', name));
  return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer;
};
const influences = (a: GltfAvatar) => {
  let mesh: THREE.Mesh | null = null;
  a.gltf.scene.traverse((o) => { if ((o as THREE.Mesh).morphTargetInfluences) mesh = o as THREE.Mesh; });
  const m = mesh as unknown as THREE.Mesh;
  return (name: string) => m.morphTargetInfluences![m.morphTargetDictionary![name]];
};
/** A glTF stand-in: one mesh with morph targets of the given names, under the given bones. */
function fake(names: string[], bones: string[] = []): GLTF {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(9), 3));
  geometry.morphAttributes.position = names.map(() => new THREE.BufferAttribute(new Float32Array(9), 3));
  const mesh = new THREE.Mesh(geometry);
  mesh.updateMorphTargets();
  mesh.morphTargetDictionary = Object.fromEntries(names.map((n, i) => [n, i]));
  let parent: THREE.Object3D = new THREE.Scene();
  const scene = parent;
  for (const b of bones) { const bone = new THREE.Bone(); bone.name = b; parent.add(bone); parent = bone; }
  parent.add(mesh);
  return { scene, animations: [] } as unknown as GLTF;
}

describe('the test avatars', () => {
  it('are exactly what npm run make-avatars writes', async () => {
    const made = await makeAvatars();
    for (const name of Object.keys(AVATARS)) expect(Buffer.compare(Buffer.from(made[name]), Buffer.from(file(name))), name).toBe(0);
  });
});

describe('GltfAvatar', () => {
  let arkit: GltfAvatar, visemes: GltfAvatar;
  beforeAll(async () => {
    arkit = await GltfAvatar.parse(file('arkit-face.glb'), 'arkit-face.glb');
    visemes = await GltfAvatar.parse(file('visemes-face.glb'), 'visemes-face.glb');
  });

  it('drives an ARKit avatar by the 52 weights and a viseme-only avatar by the 15 visemes', () => {
    expect(arkit.summary).toEqual({ scheme: 'arkit', matched: [...ARKIT_NAMES], headBone: 'Head' });
    expect(visemes.summary).toEqual({ scheme: 'visemes', matched: [...VISEME_NAMES], headBone: 'Head' });
    const w = Float32Array.from(ARKIT_NAMES, (_, k) => k / 100);
    const v = Float32Array.from(VISEME_NAMES, (_, k) => k / 20);
    arkit.setWeights(w, 0, v, 0);
    visemes.setWeights(w, 0, v, 0);
    expect(influences(arkit)('jawOpen')).toBeCloseTo(ARKIT_NAMES.indexOf('jawOpen') / 100, 6);
    expect(influences(visemes)('viseme_aa')).toBeCloseTo(VISEME_NAMES.indexOf('viseme_aa') / 20, 6);
    expect(arkit.canBlink).toBe(true);
    expect(visemes.canBlink).toBe(false);
    arkit.setIdleBlink(0.9); // on top of the model's own eyeBlink weight
    expect(influences(arkit)('eyeBlinkLeft')).toBeCloseTo(0.9, 6);
    arkit.setIdleBlink(0);
    expect(influences(arkit)('eyeBlinkLeft')).toBeCloseTo(0, 6);
    arkit.reset();
    expect(influences(arkit)('jawOpen')).toBe(0);
  });

  it('finds prefixed and suffixed ARKit names, and prefers them to visemes when it has both', () => {
    const a = GltfAvatar.bind(fake(['blendShape1.jawOpen', 'Mouth_Smile_L', 'viseme_aa', 'somethingElse']), 'x.glb');
    expect(a.summary.scheme).toBe('arkit');
    expect(a.summary.matched).toEqual(['jawOpen', 'mouthSmileLeft']);
    expect(a.summary.headBone).toBeNull();
  });

  it('drives the visemes of a viseme rig that also has ARKit blinks, and the blinks as blinks', () => {
    const names = [...VISEME_NAMES, 'eyeBlinkLeft', 'eyeBlinkRight'];
    const a = GltfAvatar.bind(fake(names), 'x.glb');
    expect(a.summary.scheme).toBe('visemes');
    expect(a.summary.matched).toEqual([...VISEME_NAMES]);
    expect(a.canBlink).toBe(true);
    const w = new Float32Array(ARKIT_NAMES.length);
    w[ARKIT_NAMES.indexOf('eyeBlinkRight')] = 0.7;
    const v = new Float32Array(VISEME_NAMES.length);
    v[VISEME_NAMES.indexOf('viseme_PP')] = 0.8;
    a.setWeights(w, 0, v, 0);
    expect(influences(a)('viseme_PP')).toBeCloseTo(0.8, 6);
    expect(influences(a)('eyeBlinkRight')).toBeCloseTo(0.7, 6);
    // One ARKit shape that opens the mouth beside them is an ARKit rig (ARKit wins when it has the mouth)...
    expect(GltfAvatar.bind(fake([...names, 'jawOpen']), 'x.glb').summary.scheme).toBe('arkit');
    expect(GltfAvatar.bind(fake([...names, 'mouthLowerDown_L', 'mouthLowerDown_R']), 'x.glb').summary.scheme).toBe('arkit');
    // ...and ARKit smiles or presses, which open nothing, leave the visemes driving the mouth (as Character Creator exports).
    const smiling = GltfAvatar.bind(fake([...names, 'mouthSmile_L', 'mouthSmile_R', 'mouthPressLeft']), 'x.glb');
    expect(smiling.summary.scheme).toBe('visemes');
    expect(smiling.summary.matched).toEqual([...VISEME_NAMES]);
    // Without visemes, ARKit shapes that do not open the mouth are still what there is to drive.
    expect(GltfAvatar.bind(fake(['mouthSmile_L', 'eyeBlinkLeft']), 'x.glb').summary.scheme).toBe('arkit');
  });

  it("takes the file's bytes as an ArrayBuffer, a Uint8Array or Node's Buffer, and says what else it was given", async () => {
    const b = readFileSync(resolve(ROOT, 'examples/avatars', 'arkit-face.glb')); // a Buffer: a view into a larger pool
    for (const data of [b, new Uint8Array(b), file('arkit-face.glb')]) {
      expect((await GltfAvatar.parse(data, 'arkit-face.glb')).summary.matched.length, data.constructor.name).toBe(52);
    }
    await expect(GltfAvatar.parse(new Blob([b]) as unknown as ArrayBuffer, 'a.glb')).rejects.toThrow(/give the file's bytes .* not Blob \(await its arrayBuffer\(\) first\)/);
    await expect(GltfAvatar.parse(null as unknown as ArrayBuffer, 'a.glb')).rejects.toThrow(/not null/);
  });

  it('says what it found when neither scheme is there, and when the file is not glTF', async () => {
    expect(() => GltfAvatar.bind(fake(['smile', 'blink', 'A']), 'face.glb')).toThrow(/face\.glb has no morph targets named after ARKit's 52 .* its morph targets are: smile, blink, A\./);
    expect(() => GltfAvatar.bind(fake([]), 'bare.glb')).toThrow(/it has no morph targets at all: export it with its blend shapes \(shape keys\), named so/);
    // The loader's scene instead of its result, and a facing that is not one.
    expect(() => GltfAvatar.bind(fake(['jawOpen']).scene as never, 'me.glb')).toThrow(/give what GLTFLoader gave \(gltf\), not its scene/);
    expect(() => GltfAvatar.bind(fake(['jawOpen']), 'me.glb', null, { facing: 'z' as never })).toThrow(/facing is '\+z' or '-z', not "z"/);
    await expect(GltfAvatar.parse(new TextEncoder().encode('ID3\u0004 an mp3').buffer as ArrayBuffer, 'song.mp3')).rejects.toThrow(/song\.mp3 is not a glTF file .*starts with "ID3/);
    for (const page of ['<!doctype html><html></html>', '\ufeff\n<html>']) { // a host's page for a missing file, a byte-order mark or not
      await expect(GltfAvatar.parse(new TextEncoder().encode(page).buffer as ArrayBuffer, 'me.glb')).rejects.toThrow(/^me\.glb is not a glTF file but an HTML page, as hosts send for a missing file: is the URL right\?$/);
    }
    // A .gltf (JSON) with a byte-order mark is read as JSON, not refused at its first byte.
    const json = (text: string) => new TextEncoder().encode(text).buffer as ArrayBuffer;
    await expect(GltfAvatar.parse(json('\ufeff{"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0}'), 'me.gltf')).rejects.toThrow(/it has no morph targets at all/);
    await expect(GltfAvatar.parse(json('{"asset":{"version":"2.0"}}'), 'empty.gltf')).rejects.toThrow(/^empty\.gltf has no scene: export the avatar with its scene$/);
    const broken = new Uint8Array(file('arkit-face.glb').slice(0, 200)); // a .glb cut short
    await expect(GltfAvatar.parse(broken.buffer, 'cut.glb')).rejects.toThrow(/^cut\.glb is cut short: its header says \d+ bytes, 200 came \(an interrupted download or upload\?\)$/);
  });

  it('finds the head bone: Head or head, a prefixed one (mixamorigHead, J_Bip_C_Head), or the one named', () => {
    for (const [bones, head] of [[['Hips', 'Neck', 'Head'], 'Head'], [['root', 'head'], 'head'], [['mixamorigHips', 'mixamorigHead'], 'mixamorigHead'],
      [['J_Bip_C_Neck', 'J_Bip_C_Head'], 'J_Bip_C_Head'], [['Hips', 'HeadTop_End'], null]] as const) {
      expect(GltfAvatar.bind(fake(['jawOpen'], [...bones]), 'x.glb').summary.headBone, bones.join('/')).toBe(head);
    }
    expect(GltfAvatar.bind(fake(['jawOpen'], ['Hips', 'Neck', 'Skull']), 'x.glb', 'Skull').summary.headBone).toBe('Skull');
    // Named as in the file: three.js's loader drops ':' and '.' from node names (mixamorig:Head -> mixamorigHead).
    expect(GltfAvatar.bind(fake(['jawOpen'], ['mixamorigHips', 'mixamorigHead']), 'x.glb', 'mixamorig:Head').summary.headBone).toBe('mixamorigHead');
    expect(() => GltfAvatar.bind(fake(['jawOpen'], ['Hips', 'Neck']), 'x.glb', 'Skull')).toThrow(/no node named "Skull" \(the head bone asked for: avatar-head-bone, or bind's headBone\); its bones are: Hips, Neck/);
  });

  it("turns the head about its pivot by a rotation given in world axes, whatever its parent's rotation", () => {
    const gltf = fake(['jawOpen'], ['Hips', 'Head']);
    const hips = gltf.scene.getObjectByName('Hips')!, head = gltf.scene.getObjectByName('Head')!;
    hips.quaternion.setFromAxisAngle(new THREE.Vector3(0, 1, 0), Math.PI / 2); // a parent turned a quarter about y
    head.quaternion.setFromAxisAngle(new THREE.Vector3(1, 0, 0), 0.2); // and the bone's own rest rotation
    const a = GltfAvatar.bind(gltf, 'x.glb');
    const restWorld = head.getWorldQuaternion(new THREE.Quaternion());
    a.setHeadRotation(0.3, 0, 0); // nod about the world's x axis
    gltf.scene.updateMatrixWorld(true);
    const want = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(1, 0, 0), 0.3).multiply(restWorld);
    expect(head.getWorldQuaternion(new THREE.Quaternion()).angleTo(want)).toBeLessThan(1e-6);
    a.reset();
    gltf.scene.updateMatrixWorld(true);
    expect(head.getWorldQuaternion(new THREE.Quaternion()).angleTo(restWorld)).toBeLessThan(1e-6);
  });

  it("nods about the avatar's own x axis when the page has turned it, before binding or after", () => {
    for (const when of ['before', 'after'] as const) {
      const gltf = fake(['jawOpen'], ['Hips', 'Head']);
      const hips = gltf.scene.getObjectByName('Hips')!, head = gltf.scene.getObjectByName('Head')!;
      hips.quaternion.setFromAxisAngle(new THREE.Vector3(0, 1, 0), Math.PI / 2);
      const world = new THREE.Group();
      world.add(gltf.scene);
      const turn = () => { world.rotation.y = Math.PI; gltf.scene.rotation.z = 0.4; }; // facing the page's camera, leaning
      if (when === 'before') turn();
      const a = GltfAvatar.bind(gltf, 'x.glb');
      if (when === 'after') turn();
      world.updateMatrixWorld(true);
      const inScene = () => gltf.scene.getWorldQuaternion(new THREE.Quaternion()).invert()
        .multiply(head.getWorldQuaternion(new THREE.Quaternion()));
      const rest = inScene();
      a.setHeadRotation(0.3, 0, 0); // a nod about the avatar's own x axis
      world.updateMatrixWorld(true);
      const want = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(1, 0, 0), 0.3).multiply(rest);
      expect(inScene().angleTo(want), when).toBeLessThan(1e-6);
    }
  });

  it("nods a -z facing avatar (VRM 0.x) as a +z one when bound facing: '-z'", () => {
    // The same rig twice, the second with its face towards -z, as a VRM 0.x model is made.
    const made = (turned: boolean) => {
      const gltf = fake(['jawOpen'], ['Hips', 'Head']);
      const head = gltf.scene.getObjectByName('Head')!;
      const nose = new THREE.Object3D(); // a point in front of the face
      nose.position.set(0, 0, turned ? -1 : 1);
      head.add(nose);
      return { gltf, nose };
    };
    const plain = made(false), vrm = made(true);
    const a = GltfAvatar.bind(plain.gltf, 'a.glb'), b = GltfAvatar.bind(vrm.gltf, 'b.vrm', null, { facing: '-z' });
    expect(b.facing).toBe('-z');
    a.setHeadRotation(0.3, 0.2, 0.1);
    b.setHeadRotation(0.3, 0.2, 0.1);
    const at = (o: THREE.Object3D) => { o.updateWorldMatrix(true, false); return o.getWorldPosition(new THREE.Vector3()); };
    const p = at(plain.nose), q = at(vrm.nose);
    expect(p.y).toBeLessThan(-0.2); // the nose goes down in a nod
    // The -z face moves as the +z one, mirrored through the y axis (its nose at -z).
    expect([q.x, q.y, q.z].map((v) => v.toFixed(6))).toEqual([-p.x, p.y, -p.z].map((v) => v.toFixed(6)));
  });

  it('puts the turn on top of the animated head bone, and never adds turns up where nothing animates it', () => {
    const gltf = fake(['jawOpen'], ['Hips', 'Head']);
    const head = gltf.scene.getObjectByName('Head')!;
    const a = GltfAvatar.bind(gltf, 'x.glb');
    const nod = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(1, 0, 0), 0.3);
    const animated = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 1, 0), 0.5);
    head.quaternion.copy(animated); // a clip sets the bone
    a.setHeadRotation(0.3, 0, 0, true);
    expect(head.quaternion.angleTo(nod.clone().multiply(animated))).toBeLessThan(1e-6);
    // The clip stopped: nothing sets the bone; frame after frame (and twice in one), the turn stays one turn.
    for (let k = 0; k < 5; k++) a.setHeadRotation(0.3, 0, 0, true);
    expect(head.quaternion.angleTo(nod.clone().multiply(animated))).toBeLessThan(1e-6);
    a.setHeadRotation(0, 0, 0, true); // and a zero turn gives the clip's rotation back
    expect(head.quaternion.angleTo(animated)).toBeLessThan(1e-6);
    // The clip sets it again, elsewhere: the turn goes on top of that.
    const later = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 1, 0), -0.2);
    head.quaternion.copy(later);
    a.setHeadRotation(0.3, 0, 0, true);
    expect(head.quaternion.angleTo(nod.clone().multiply(later))).toBeLessThan(1e-6);
    // reset() gives the animation's rotation back, not the bind-time rest (a clip that holds a pose does not set it
    // again: three's mixer writes only what changes).
    a.reset();
    expect(head.quaternion.angleTo(later)).toBeLessThan(1e-6);
    a.reset(); // again, or before any turn: the bone is left as the page's clip holds it, not snapped to the rest
    expect(head.quaternion.angleTo(later)).toBeLessThan(1e-6);
    // A turn without onTop, then one with: one turn, on top of the rest (not on top of the first turn).
    head.quaternion.identity();
    const b = GltfAvatar.bind(gltf, 'x.glb');
    b.setHeadRotation(0.2, 0, 0);
    b.setHeadRotation(0.2, 0, 0, true);
    expect(head.quaternion.angleTo(new THREE.Quaternion())).toBeCloseTo(0.2, 6);
  });
});
