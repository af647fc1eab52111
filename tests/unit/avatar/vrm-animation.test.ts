/**
 * A take as a VRM Animation (src/avatar/vrm-animation.ts), played by @pixiv/three-vrm-animation on the VRM test
 * avatars (1.0 and 0.x) as three-vrm loads them: at each frame, the same morph targets and the same turn of the head
 * as the avatar driven live by GltfAvatar (vowels from the visemes, the head from the pose).
 */
import { beforeAll, describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { GLTFLoader, type GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { VRMUtils, type VRM } from '@pixiv/three-vrm';
import { VRMAnimationLoaderPlugin, createVRMAnimationClip, type VRMAnimation } from '@pixiv/three-vrm-animation';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { vrmAnimation } from '../../../src/avatar/vrm-animation';
import { ARKIT_NAMES, VISEME_NAMES } from '../../../src/avatar/names';
import type { Animation } from '../../../src/engine/frames';
import { load } from '../helpers/vrm';
import { installFileReader } from '../helpers/file-reader';

beforeAll(() => installFileReader()); // GLTFExporter's, which Node lacks

const F = 24, FPS = 30, A = ARKIT_NAMES.length, V = VISEME_NAMES.length;

/** A take with varied visemes (one viseme leading each frame, the rest shared) and a head that turns about all three axes. */
function take(): Animation {
  const visemes = new Float32Array(F * V), pose = new Float32Array(F * 6);
  for (let f = 0; f < F; f++) {
    for (let v = 0; v < V; v++) visemes[f * V + v] = v === (f * 7) % V ? 0.7 : 0.3 / (V - 1);
    pose.set([0.2 * Math.sin(f / 3), 0.15 * Math.cos(f / 4), -0.1 * Math.sin(f / 5)], f * 6);
  }
  const blendshapes = { fps: FPS, frames: F, arkit: new Float32Array(F * A), visemes, headRotation: new Float32Array(F * 3) };
  return { frames: F, fps: FPS, pose, blendshapes } as unknown as Animation;
}

/** A .vrma read by three-vrm-animation's loader plugin. */
async function readVrma(bytes: ArrayBuffer): Promise<VRMAnimation> {
  const loader = new GLTFLoader();
  loader.register((parser) => new VRMAnimationLoaderPlugin(parser));
  return (await loader.parseAsync(bytes, '')).userData.vrmAnimations[0] as VRMAnimation;
}
/** Every morph target's influence by name, and the model's head bone's rotation relative to the avatar's root. */
function face(gltf: GLTF) {
  const morphs: Record<string, number> = {};
  gltf.scene.traverse((o) => {
    const m = o as THREE.Mesh;
    if (m.morphTargetDictionary) for (const [n, i] of Object.entries(m.morphTargetDictionary)) morphs[n] = m.morphTargetInfluences![i];
  });
  gltf.scene.updateMatrixWorld(true);
  const head = gltf.scene.getObjectByName('Head')!.getWorldQuaternion(new THREE.Quaternion());
  return { morphs, head: head.premultiply(gltf.scene.getWorldQuaternion(new THREE.Quaternion()).invert()) };
}

describe('vrmAnimation', () => {
  it('writes a VRM Animation that three-vrm-animation reads: a humanoid, the five vowels, one clip as long as the take', async () => {
    const animation = await readVrma(await vrmAnimation(take()));
    expect([...animation.humanoidTracks.rotation.keys()]).toEqual(['head']);
    expect([...animation.expressionTracks.preset.keys()]).toEqual(['aa', 'ih', 'ou', 'ee', 'oh']);
    expect(animation.duration).toBeCloseTo((F - 1) / FPS, 6);
    expect(animation.restHipsPosition.y).toBeCloseTo(1, 6);
  });

  it.each(['vrm1-face.vrm', 'vrm0-face.vrm'])('played on %s, gives the face the live driver gives at each frame', async (name) => {
    const t = take();
    const vrma = await readVrma(await vrmAnimation(t));
    const played = await load(name, true);
    const driven = await load(name, true);
    const [vrmPlayed, vrmDriven] = [played.userData.vrm as VRM, driven.userData.vrm as VRM];
    VRMUtils.rotateVRM0(vrmPlayed);
    VRMUtils.rotateVRM0(vrmDriven);
    const mixer = new THREE.AnimationMixer(vrmPlayed.scene);
    const action = mixer.clipAction(createVRMAnimationClip(vrma, vrmPlayed));
    action.setLoop(THREE.LoopOnce, 1).clampWhenFinished = true; // (repeating, the last frame's instant would be the first's)
    action.play();
    const avatar = GltfAvatar.bind(driven, name);
    let mouthMoved = 0;
    for (let f = 0; f < F; f++) {
      mixer.setTime(f / FPS);
      vrmPlayed.update(0);
      avatar.setWeights(t.blendshapes!.arkit, f * A, t.blendshapes!.visemes, f * V);
      avatar.setHeadRotation(t.pose[f * 6], t.pose[f * 6 + 1], t.pose[f * 6 + 2]);
      vrmDriven.update(0);
      const [p, d] = [face(played), face(driven)];
      for (const [morph, value] of Object.entries(d.morphs)) expect(p.morphs[morph], `frame ${f} ${morph}`).toBeCloseTo(value, 4);
      expect(p.head.angleTo(d.head), `frame ${f}: the head`).toBeLessThan(1e-4);
      mouthMoved = Math.max(mouthMoved, p.morphs.Fcl_MTH_A, p.morphs.Fcl_MTH_U);
    }
    expect(mouthMoved).toBeGreaterThan(0.5);
  });

  it('refuses a take made without blend shapes, saying so', async () => {
    await expect(vrmAnimation({ ...take(), blendshapes: undefined } as Animation)).rejects.toThrow(/animate with \{ blendshapes: true \}/);
  });
});
