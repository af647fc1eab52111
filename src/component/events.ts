/** What <talking-face> sends with its events (docs/embedding.md, "Events"). */
import type { Backend } from '../engine/engine';
import type { AvatarSummary } from '../avatar/gltf-avatar';
import type { FrameWeights } from '../avatar/weights';

export interface ReadyDetail {
  backend: Backend;
  reason: string;
  vertices: number;
  model: string;
  /** With the `avatar` attribute: which naming scheme drives it, the names matched, the head bone. */
  avatar?: AvatarSummary;
}

/** With an avatar or the `blendshapes` attribute, also the frame's ARKit weights, visemes and head rotation. */
export interface FrameDetail extends Partial<FrameWeights> {
  /** Frame index in the current take (offline) or since the microphone started (live). */
  frame: number;
  /** Seconds into the audio. */
  time: number;
  mode: 'playback' | 'live';
  backend: Backend;
  /** Offline: compute time per frame of the animation (ms). Live: measured sample-in -> frame-out latency (ms). */
  inferenceMs?: number;
  latencyMs?: number;
  /** Offline: seconds of audio per second of compute. */
  realTimeFactor?: number;
}

export interface TalkingFaceErrorDetail {
  message: string;
  /** What failed: loading the model, decoding audio, the microphone, inference, or the avatar. */
  stage: 'model' | 'audio' | 'microphone' | 'inference' | 'avatar';
}
