/**
 * The two naming schemes avatars are rigged with, and how a glTF file's morph-target names are matched to them:
 * - ARKit's 52 face blend shapes (Apple, ARFaceAnchor.BlendShapeLocation), the scheme of Ready Player Me, VRoid
 *   exports made ARKit-ready, Character Creator, MetaHuman's ARKit pose asset and MediaPipe's face landmarker;
 * - the 15 Oculus (Meta) visemes, `viseme_sil` ... `viseme_U`, the scheme of TalkingHead's and HeadAudio's avatars.
 */

/** ARKit's 52 names in Apple's order (left eye, right eye, jaw and mouth, brows, cheeks, nose, tongue). */
export const ARKIT_NAMES = [
  'eyeBlinkLeft', 'eyeLookDownLeft', 'eyeLookInLeft', 'eyeLookOutLeft', 'eyeLookUpLeft', 'eyeSquintLeft', 'eyeWideLeft',
  'eyeBlinkRight', 'eyeLookDownRight', 'eyeLookInRight', 'eyeLookOutRight', 'eyeLookUpRight', 'eyeSquintRight', 'eyeWideRight',
  'jawForward', 'jawLeft', 'jawRight', 'jawOpen',
  'mouthClose', 'mouthFunnel', 'mouthPucker', 'mouthLeft', 'mouthRight',
  'mouthSmileLeft', 'mouthSmileRight', 'mouthFrownLeft', 'mouthFrownRight', 'mouthDimpleLeft', 'mouthDimpleRight',
  'mouthStretchLeft', 'mouthStretchRight', 'mouthRollLower', 'mouthRollUpper', 'mouthShrugLower', 'mouthShrugUpper',
  'mouthPressLeft', 'mouthPressRight', 'mouthLowerDownLeft', 'mouthLowerDownRight', 'mouthUpperUpLeft', 'mouthUpperUpRight',
  'browDownLeft', 'browDownRight', 'browInnerUp', 'browOuterUpLeft', 'browOuterUpRight',
  'cheekPuff', 'cheekSquintLeft', 'cheekSquintRight',
  'noseSneerLeft', 'noseSneerRight',
  'tongueOut',
] as const;
export type ArkitName = (typeof ARKIT_NAMES)[number];

/** Index of each ARKit name in ARKIT_NAMES (and in every weights array this project hands out). */
export const ARKIT_INDEX = Object.fromEntries(ARKIT_NAMES.map((n, i) => [n, i])) as Record<ArkitName, number>;

/** The 15 Oculus visemes, in Meta's order (OVRLipSync's viseme reference). */
export const VISEME_NAMES = [
  'viseme_sil', 'viseme_PP', 'viseme_FF', 'viseme_TH', 'viseme_DD', 'viseme_kk', 'viseme_CH', 'viseme_SS',
  'viseme_nn', 'viseme_RR', 'viseme_aa', 'viseme_E', 'viseme_I', 'viseme_O', 'viseme_U',
] as const;
export type VisemeName = (typeof VISEME_NAMES)[number];

/**
 * A morph-target name reduced for matching: lower case, exporter prefixes dropped (`blendShape1.jawOpen`,
 * `Face.jawOpen`, `mixamorig:jawOpen` -> `jawopen`), separators dropped, and the `_L` / `_R` / `.L` suffixes of
 * Blender and Character Creator rigs spelled out (`eyeBlink_L` -> `eyeblinkleft`). Viseme names keep their
 * `viseme` stem (`viseme_PP` -> `visemepp`).
 */
export function normaliseMorphName(name: string): string {
  let s = name.trim();
  // The side first (a trailing ".L" is a side, not a prefix separator), then the prefix before the last separator
  // left: `Face.eyeBlink.L` -> `eyeBlinkLeft`.
  s = s.replace(/[._\s-]([LR])$/i, (_, side: string) => (side.toUpperCase() === 'L' ? 'Left' : 'Right'));
  const cut = Math.max(s.lastIndexOf('.'), s.lastIndexOf(':'), s.lastIndexOf('|'));
  if (cut >= 0) s = s.slice(cut + 1);
  return s.replace(/[^A-Za-z0-9]/g, '').toLowerCase();
}

const ARKIT_BY_KEY = new Map(ARKIT_NAMES.map((n, i) => [normaliseMorphName(n), i]));
const VISEME_BY_KEY = new Map(VISEME_NAMES.map((n, i) => [normaliseMorphName(n), i]));

/** The ARKit index a morph-target name stands for, or -1. */
export function arkitIndexOf(morphName: string): number {
  return ARKIT_BY_KEY.get(normaliseMorphName(morphName)) ?? -1;
}

/** The viseme index a morph-target name stands for, or -1 (`viseme_aa`, `Viseme_AA`, `blendShape1.viseme_aa`). */
export function visemeIndexOf(morphName: string): number {
  return VISEME_BY_KEY.get(normaliseMorphName(morphName)) ?? -1;
}

/** Live Link Face's CSV columns after Timecode and BlendShapeCount: its own order of the 52, then head and eyes. */
export const LIVE_LINK_FACE_COLUMNS = [
  'EyeBlinkLeft', 'EyeLookDownLeft', 'EyeLookInLeft', 'EyeLookOutLeft', 'EyeLookUpLeft', 'EyeSquintLeft', 'EyeWideLeft',
  'EyeBlinkRight', 'EyeLookDownRight', 'EyeLookInRight', 'EyeLookOutRight', 'EyeLookUpRight', 'EyeSquintRight', 'EyeWideRight',
  'JawForward', 'JawRight', 'JawLeft', 'JawOpen', 'MouthClose', 'MouthFunnel', 'MouthPucker', 'MouthRight', 'MouthLeft',
  'MouthSmileLeft', 'MouthSmileRight', 'MouthFrownLeft', 'MouthFrownRight', 'MouthDimpleLeft', 'MouthDimpleRight',
  'MouthStretchLeft', 'MouthStretchRight', 'MouthRollLower', 'MouthRollUpper', 'MouthShrugLower', 'MouthShrugUpper',
  'MouthPressLeft', 'MouthPressRight', 'MouthLowerDownLeft', 'MouthLowerDownRight', 'MouthUpperUpLeft', 'MouthUpperUpRight',
  'BrowDownLeft', 'BrowDownRight', 'BrowInnerUp', 'BrowOuterUpLeft', 'BrowOuterUpRight', 'CheekPuff', 'CheekSquintLeft',
  'CheekSquintRight', 'NoseSneerLeft', 'NoseSneerRight', 'TongueOut',
  'HeadYaw', 'HeadPitch', 'HeadRoll', 'LeftEyeYaw', 'LeftEyePitch', 'LeftEyeRoll', 'RightEyeYaw', 'RightEyePitch', 'RightEyeRoll',
] as const;
