/**
 * models/manifest.json: the one source of every number the browser shares with training
 * (sample rate, Mel, fps, window, token size), written by training/src/talkingface/export.py.
 */

export const MANIFEST_FORMAT = 'talking-face-model';
/** 2: hierarchical.onnx gives each frame's latents and the decoder makes the vertex tokens (gava.safetensors' hierarchical.*). */
export const MANIFEST_VERSION = 2;

/** Where the app, the element and the dev pages find the shipped model (models/ is served at /models/). */
export const DEFAULT_MANIFEST_URL = '/models/manifest.json';

export interface AudioConstants {
  sample_rate: number;
  frame_size: number;
  hop: number;
  n_mels: number;
  fps: number;
  feature_rate: number;
}

export interface ModelConstants {
  features: string;
  decoder: string;
  variant: string;
  d_model: number;
  heads: number;
  layers: number;
  ffn: number;
  content_classes: number;
  window: number;
  window_future: number;
  content_stride: number;
  pose_channels: number;
  max_rotation: number;
  max_translation_mm: number;
}

export interface Manifest {
  format: typeof MANIFEST_FORMAT;
  version: number;
  model: { name: string; config: ModelConstants; trained_steps: number; trained_minutes: number; parameters: number; layer_norm_eps: number };
  audio: AudioConstants;
  template: { id: string; units: string; vertices: number; path: string };
  files: Record<string, string>;
  runtime_files: string[];
  sha256: Record<string, string>;
  decoder_tensors: Record<string, number[]>;
  /** Each ONNX file's inputs and outputs with their shapes (strings are free dimensions, e.g. "K"). */
  onnx: Record<string, { inputs: Record<string, (number | string)[]>; outputs: Record<string, (number | string)[]> }>;
  fixtures: { file: string; frames: number; token_frames: number };
  /** Mel frames each encoder output reads after its own position (look-ahead) and before it (context). */
  receptive_field: { content_mel_frames: number; pose_mel_frames: number; content_mel_frames_back: number; pose_mel_frames_back: number };
  look_ahead_ms: number;
  /** The head's own motion (tensors head_motion.* in the decoder weights), or null for a model exported without it. */
  head_motion?: { tensors: string; default_seed: number; process: string } | null;
  /** The model's closure retargeted to the face's own lip gap (engine/lip-closure.ts), or null for a model exported without it. */
  /** mouth_gain: the mouth's amplitude factor (absent in models exported before it: 1). */
  lip_closure?: { reference_gap_mm: number; mouth_gain?: number; calibrated_on: string | null; rule: string } | null;
  /** The content encoder's classes in logit order (ARPAbet phones, SIL, <blank>). */
  content_phones: string[];
}

/** What the browser loads of every model: the four ONNX encoders and the decoder's weights. */
const RUNTIME_KEYS = ['content_encoder', 'hierarchical', 'pose_conv', 'pose_lstm', 'decoder_weights'];

export class ManifestError extends Error {
  override name = 'ManifestError';
}

export function checkManifest(m: unknown): Manifest {
  const x = m as Manifest;
  if (!x || x.format !== MANIFEST_FORMAT) throw new ManifestError(`not a talking-face model manifest (expected "format": "${MANIFEST_FORMAT}")`);
  if (x.version !== MANIFEST_VERSION) {
    throw new ManifestError(`model manifest version ${x.version} is not supported by this build (${MANIFEST_VERSION}): `
      + 're-export the model with this build\'s exporter');
  }
  for (const key of ['sample_rate', 'frame_size', 'hop', 'n_mels', 'fps', 'feature_rate'] as const) {
    if (!Number.isFinite(x.audio?.[key])) throw new ManifestError(`model manifest lacks audio.${key}`);
  }
  for (const key of ['d_model', 'heads', 'layers', 'ffn', 'content_classes', 'window', 'window_future', 'content_stride', 'pose_channels'] as const) {
    if (!Number.isInteger(x.model?.config?.[key])) throw new ManifestError(`model manifest lacks model.config.${key} (re-export the model)`);
  }
  // The files the browser loads: each named, with its digest (a missing one is no "corrupt" download, nor a TypeError).
  const missing = RUNTIME_KEYS.filter((k) => !x.runtime_files?.includes(k) || typeof x.files?.[k] !== 'string' || typeof x.sha256?.[k] !== 'string');
  if (missing.length) throw new ManifestError(`model manifest lacks ${missing.join(', ')} in runtime_files, files or sha256 (re-export the model)`);
  if (!Array.isArray(x.content_phones) || x.content_phones.length !== x.model?.config?.content_classes) {
    throw new ManifestError('model manifest lacks content_phones, one name per content class (re-export the model)');
  }
  for (const key of ['content_mel_frames', 'pose_mel_frames', 'content_mel_frames_back', 'pose_mel_frames_back'] as const) {
    if (!Number.isFinite(x.receptive_field?.[key])) throw new ManifestError(`model manifest lacks receptive_field.${key} (re-export the model)`);
  }
  if (!(x.model?.layer_norm_eps > 0)) throw new ManifestError('model manifest lacks model.layer_norm_eps (re-export the model)');
  for (const key of x.runtime_files ?? []) {
    if (key !== 'decoder_weights' && !x.onnx?.[key]?.inputs) throw new ManifestError(`model manifest lacks onnx.${key}.inputs (re-export the model)`);
  }
  return x;
}

/** Mel frame of animation frame i: round(i / fps * feature_rate), half to even (numpy's rounding). */
export function frameToMelIndex(frame: number, a: AudioConstants): number {
  const x = (frame / a.fps) * a.feature_rate;
  const r = Math.round(x);
  // Math.round rounds halves up; numpy rounds them to even.
  return Math.abs(x - Math.trunc(x)) === 0.5 && r % 2 !== 0 ? r - 1 : r;
}
