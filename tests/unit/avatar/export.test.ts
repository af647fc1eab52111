/**
 * The three exports of the blend-shape output (src/avatar/export.ts): JSON, CSV in Live Link Face's layout, and a
 * .glb whose morph targets carry ARKit's names and whose animation plays the weights. (TalkingHead's `anim`:
 * talkinghead.test.ts.)
 */
import { beforeAll, describe, expect, it } from 'vitest';
import { blendshapesGlb, blendshapesJson, liveLinkFaceCsv, liveLinkTimecode } from '../../../src/avatar/export';
import { arkitBasis, type ArkitBasis } from '../../../src/avatar/basis';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { ARKIT_NAMES, LIVE_LINK_FACE_COLUMNS, VISEME_NAMES } from '../../../src/avatar/names';
import { emptyBlendshapes, type Animation } from '../../../src/engine/frames';
import type { FaceTemplate } from '../../../src/template/face-template';
import { loadManifest, loadTemplateFile } from '../helpers/exported';
import { installFileReader } from '../helpers/file-reader';

/** 40 frames at 30 fps: jawOpen = f / 40, mouthRight = 0.5, eyeBlinkLeft only at frame 7; head yaw 0.01 f. */
function take(): Animation {
  const F = 40;
  const b = emptyBlendshapes(F);
  const pose = new Float32Array(F * 6);
  for (let f = 0; f < F; f++) {
    b.arkit[f * 52 + ARKIT_NAMES.indexOf('jawOpen')] = f / F;
    b.arkit[f * 52 + ARKIT_NAMES.indexOf('mouthRight')] = 0.5;
    b.visemes[f * 15 + (f % 15)] = 1;
    b.headRotation[f * 3] = 0.01 * f;
    pose[f * 6 + 1] = 0.01 * f; // a turn about y: yaw
  }
  b.arkit[7 * 52 + ARKIT_NAMES.indexOf('eyeBlinkLeft')] = 1;
  return { fps: 30, frames: F, vertices: new Float32Array(0), pose, phones: new Uint8Array(F), tongue: new Float32Array(F), speech: new Float32Array(F), blendshapes: b };
}

describe('exports', () => {
  let template: FaceTemplate, basis: ArkitBasis;
  beforeAll(async () => {
    template = await loadTemplateFile(loadManifest());
    basis = arkitBasis(template);
  });

  it("Live Link Face's timecode: HH:MM:SS:FF.fff, frames counted at the take's rate", () => {
    expect(liveLinkTimecode(0, 30)).toBe('00:00:00:00.000');
    expect(liveLinkTimecode(29, 30)).toBe('00:00:00:29.000');
    expect(liveLinkTimecode(30, 30)).toBe('00:00:01:00.000');
    expect(liveLinkTimecode(3661 * 30 + 12, 30)).toBe('01:01:01:12.000');
    expect(liveLinkTimecode(3, 25)).toBe('00:00:00:03.000');
  });

  it('CSV: the header of a Live Link Face recording, one row per frame, each weight in its column', () => {
    const lines = liveLinkFaceCsv(take()).trimEnd().split('\n');
    expect(lines[0]).toBe(`Timecode,BlendShapeCount,${LIVE_LINK_FACE_COLUMNS.join(',')}`);
    expect(lines[0].startsWith('Timecode,BlendShapeCount,EyeBlinkLeft,EyeLookDownLeft,')).toBe(true);
    expect(lines[0].endsWith(',TongueOut,HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll')).toBe(true);
    expect(lines).toHaveLength(41);
    const col = (row: number, name: string) => lines[row + 1].split(',')[2 + LIVE_LINK_FACE_COLUMNS.indexOf(name as never)];
    for (const l of lines.slice(1)) expect(l.split(',')).toHaveLength(63);
    expect(lines[11].split(',').slice(0, 2)).toEqual(['00:00:00:10.000', '61']);
    expect(Number(col(10, 'JawOpen'))).toBeCloseTo(0.25, 6);
    expect(Number(col(10, 'MouthRight'))).toBe(0.5);
    expect(Number(col(10, 'MouthLeft'))).toBe(0);
    expect(Number(col(7, 'EyeBlinkLeft'))).toBe(1);
    expect(Number(col(8, 'EyeBlinkLeft'))).toBe(0);
    expect(Number(col(20, 'HeadYaw'))).toBeCloseTo(0.2, 6);
    expect(Number(col(20, 'LeftEyeYaw'))).toBe(0);
  });

  it('JSON: names, rate and per frame the weights, visemes and head angles', () => {
    const j = JSON.parse(blendshapesJson(take()));
    expect(j).toMatchObject({ format: 'talking-face-blendshapes', version: 1, fps: 30, frames: 40 });
    expect(j.arkitNames).toEqual([...ARKIT_NAMES]);
    expect(j.visemeNames).toEqual([...VISEME_NAMES]);
    expect(j.arkit[10][ARKIT_NAMES.indexOf('jawOpen')]).toBeCloseTo(0.25, 5);
    expect(j.visemes[16][1]).toBe(1);
    expect(j.head[20][0]).toBeCloseTo(0.2, 5);
    expect(() => blendshapesJson({ ...take(), blendshapes: undefined })).toThrow(/animate with \{ blendshapes: true \}/);
    // No take yet (an element's currentAnimation before it spoke), or something else: said, not a TypeError on a property.
    expect(() => blendshapesJson(null as unknown as Animation)).toThrow(/no take to export \(null\): animate or speak first/);
    expect(() => liveLinkFaceCsv({} as Animation)).toThrow(/expected a take/);
  });

  it('.glb: the template with the 52 ARKit targets under a Head bone, the weights and the head keyed per frame', async () => {
    installFileReader();
    await expect(blendshapesGlb(take(), template, undefined as unknown as typeof basis)).rejects.toThrow(/give the engine's template and engine\.avatarWeights\.basis/);
    const bytes = await blendshapesGlb(take(), template, basis);
    const a = await GltfAvatar.parse(bytes, 'take.glb');
    expect(a.summary).toEqual({ scheme: 'arkit', matched: [...ARKIT_NAMES], headBone: 'Head' });
    const clip = a.gltf.animations[0];
    expect(clip.duration).toBeCloseTo(39 / 30, 5);
    const weights = clip.tracks.find((t) => t.name.endsWith('.morphTargetInfluences'))!;
    expect(weights.times).toHaveLength(40);
    expect(weights.values).toHaveLength(40 * 52);
    expect(weights.values[10 * 52 + ARKIT_NAMES.indexOf('jawOpen')]).toBeCloseTo(0.25, 6);
    const head = clip.tracks.find((t) => t.name === 'Head.quaternion')!;
    expect(head.values[20 * 4 + 1]).toBeCloseTo(Math.sin(0.1), 5); // a 0.2 rad turn about y
  });
});
