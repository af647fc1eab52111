/** The naming schemes (src/avatar/names.ts): ARKit's 52, the 15 visemes, Live Link Face's columns, and name matching. */
import { describe, expect, it } from 'vitest';
import { ARKIT_NAMES, LIVE_LINK_FACE_COLUMNS, VISEME_NAMES, arkitIndexOf, normaliseMorphName, visemeIndexOf } from '../../../src/avatar/names';

describe('naming schemes', () => {
  it('52 distinct ARKit names, 15 distinct visemes', () => {
    expect(new Set(ARKIT_NAMES).size).toBe(52);
    expect(new Set(VISEME_NAMES).size).toBe(15);
  });

  it("Live Link Face's columns: the same 52 shapes in its own order, then head and eye rotations", () => {
    expect(LIVE_LINK_FACE_COLUMNS).toHaveLength(61);
    const shapes = LIVE_LINK_FACE_COLUMNS.slice(0, 52).map((c) => arkitIndexOf(c));
    expect(new Set(shapes).size).toBe(52); // each ARKit shape once
    expect(shapes).not.toEqual(ARKIT_NAMES.map((_, i) => i)); // a different order (JawRight before JawLeft...)
    expect(LIVE_LINK_FACE_COLUMNS.slice(52)).toEqual(['HeadYaw', 'HeadPitch', 'HeadRoll', 'LeftEyeYaw', 'LeftEyePitch', 'LeftEyeRoll', 'RightEyeYaw', 'RightEyePitch', 'RightEyeRoll']);
  });

  it('matches ARKit names whatever the case, exporter prefix or side suffix', () => {
    const jawOpen = ARKIT_NAMES.indexOf('jawOpen');
    for (const n of ['jawOpen', 'JawOpen', 'JAWOPEN', 'blendShape1.jawOpen', 'Face.jawOpen', 'mixamorig:jawOpen', 'jaw_open', ' jawOpen ']) {
      expect(arkitIndexOf(n), n).toBe(jawOpen);
    }
    expect(arkitIndexOf('eyeBlink_L')).toBe(ARKIT_NAMES.indexOf('eyeBlinkLeft'));
    expect(arkitIndexOf('EyeBlink.R')).toBe(ARKIT_NAMES.indexOf('eyeBlinkRight'));
    expect(arkitIndexOf('Mouth_Smile_L')).toBe(ARKIT_NAMES.indexOf('mouthSmileLeft')); // Character Creator's spelling
    expect(arkitIndexOf('blendShape2.mouthSmile_R')).toBe(ARKIT_NAMES.indexOf('mouthSmileRight'));
    // A prefix and a dotted side together (both dots): the side is read first, then the prefix dropped.
    expect(arkitIndexOf('Face.eyeBlink.L')).toBe(ARKIT_NAMES.indexOf('eyeBlinkLeft'));
    expect(arkitIndexOf('Armature|Face.mouthSmile.R')).toBe(ARKIT_NAMES.indexOf('mouthSmileRight'));
    for (const n of ARKIT_NAMES) expect(arkitIndexOf(`Face.${n.replace(/Left$/, '.L').replace(/Right$/, '.R')}`), n).toBe(ARKIT_NAMES.indexOf(n));
    for (const n of ['mouthSmile', 'smile', 'jawOpened', 'viseme_aa', '']) expect(arkitIndexOf(n), n).toBe(-1);
  });

  it('matches viseme names (viseme_PP, Viseme_AA, prefixed) and nothing else', () => {
    expect(visemeIndexOf('viseme_PP')).toBe(1);
    expect(visemeIndexOf('Viseme_AA')).toBe(VISEME_NAMES.indexOf('viseme_aa'));
    expect(visemeIndexOf('blendShape1.viseme_sil')).toBe(0);
    expect(visemeIndexOf('viseme_kk')).toBe(VISEME_NAMES.indexOf('viseme_kk'));
    for (const n of ['PP', 'aa', 'jawOpen', 'viseme_xx']) expect(visemeIndexOf(n), n).toBe(-1);
    expect(normaliseMorphName('blendShape1.viseme_PP')).toBe('visemepp');
  });
});
