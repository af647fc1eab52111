/** What <talking-face> sends with its events (docs/embedding.md, "Events"). */
import type { Animation, Backend, Frames, TalkingFaceEngine } from '../engine/engine';
import type { StreamSession } from '../engine/stream';
import type { AvatarSummary } from '../avatar/gltf-avatar';
import { frameWeights, type FrameWeights } from '../avatar/weights';
import { SHORT_CLIP_SECONDS } from '../player/audio-notes';

export interface ReadyDetail {
  backend: Backend;
  reason: string;
  vertices: number;
  model: string;
  /**
   * Threads the work runs on: onnxruntime's per session (1 where the page is not cross-origin isolated: docs/embedding.md,
   * Build and host) and the CPU decoder's workers (1: in the page's thread).
   */
  threads: { encoders: number; decoder: number };
  /** With the `avatar` attribute: which naming scheme drives it, the names matched, the head bone. */
  avatar?: AvatarSummary;
  /**
   * False where nothing is drawn: the browser has no WebGL here (an `error` event, stage 'render', said so just before);
   * speech still plays and `frame` events still come.
   */
  drawn: boolean;
}

/** With an avatar or the `blendshapes` attribute, also the frame's ARKit weights, visemes and head rotation. */
export interface FrameDetail extends Partial<FrameWeights> {
  /** Frame index in the current take (offline), since the microphone started (live), or since the stream began (stream). */
  frame: number;
  /** Seconds into the audio. */
  time: number;
  /** 'stream': speech written to speakStream(), one event per frame shown. */
  mode: 'playback' | 'live' | 'stream';
  backend: Backend;
  /** Playback: compute time per frame of the animation (ms); not set live or for a stream. */
  inferenceMs?: number;
  /** Live and stream: the measured latency from a sample in to its frame out (ms). */
  latencyMs?: number;
  /**
   * Live: frames skipped so far to stay live (0 while the device keeps up). Above 0 the device is slower than real
   * time: the face shows fewer frames than the voice has, and a page may say so or lighten its own work.
   */
  skippedFrames?: number;
  /**
   * Stream: frames so far whose sound played before they were computed (0 while the device keeps up with the
   * stream's delay). Above 0 the face lags its voice; a longer `delayMs` would help.
   */
  lateFrames?: number;
  /** Offline: seconds of audio per second of compute. */
  realTimeFactor?: number;
}

export interface TalkingFaceErrorDetail {
  message: string;
  /** What failed: loading the model, decoding audio, the microphone, inference, the avatar, or drawing the face. */
  stage: 'model' | 'audio' | 'microphone' | 'inference' | 'avatar' | 'render';
}

/** What a failed speak() or startMicrophone() rejects with: the `error` event's message, and its stage. */
export class TalkingFaceError extends Error {
  override name = 'TalkingFaceError';
  constructor(readonly stage: TalkingFaceErrorDetail['stage'], message: string) {
    super(message);
  }
}

/** The element's events by name (typed listeners: `face.addEventListener('ready', (e) => e.detail.backend)`). */
export interface TalkingFaceEventMap extends Omit<HTMLElementEventMap, 'error'> {
  ready: CustomEvent<ReadyDetail>;
  frame: CustomEvent<FrameDetail>;
  ended: Event;
  error: CustomEvent<TalkingFaceErrorDetail>;
}

/** A frame of a take being played: its compute time and real-time factor (none for a clip too short to say). */
export function playbackFrameDetail(engine: TalkingFaceEngine, a: Animation, frame: number, computeMs: number, audioSeconds: number): FrameDetail {
  return {
    frame, time: frame / a.fps, mode: 'playback', backend: engine.backend,
    inferenceMs: Number.isFinite(computeMs) ? computeMs / a.frames : undefined, // (not for a streamed take: NaN)
    realTimeFactor: audioSeconds < SHORT_CLIP_SECONDS || !Number.isFinite(computeMs) ? undefined : audioSeconds / (computeMs / 1000),
    ...(a.blendshapes && frameWeights(a.blendshapes, frame)),
  };
}

/** The last frame of a live chunk (frames first ..), with the stream's measured latency and the frames it skipped. */
export function liveFrameDetail(engine: TalkingFaceEngine, first: number, frames: Frames, stream: StreamSession | undefined): FrameDetail {
  const last = frames.count - 1;
  return {
    frame: first + last, time: (first + last) / engine.fps, mode: 'live', backend: engine.backend,
    latencyMs: stream?.latency.lastMs, skippedFrames: stream?.skippedFrames ?? 0,
    ...(frames.blendshapes && frameWeights(frames.blendshapes, last)),
  };
}

/** Frame `at` of `frames`, the stream's frame `frame`, shown as its sound plays (speakStream). */
export function streamFrameDetail(engine: TalkingFaceEngine, frame: number, frames: Frames, at: number, lateFrames: number): FrameDetail {
  return {
    frame, time: frame / engine.fps, mode: 'stream', backend: engine.backend, lateFrames,
    ...(frames.blendshapes && frameWeights(frames.blendshapes, at)),
  };
}

/** The `ready` event's detail for `engine`, showing `avatar` (or the model's face: undefined), or nothing (`drawn` false). */
export function readyDetail(engine: TalkingFaceEngine, avatar: AvatarSummary | undefined, drawn = true): ReadyDetail {
  return { backend: engine.backend, reason: engine.backendReason, vertices: engine.template.vertexCount, model: engine.manifest.model.name,
    threads: { encoders: engine.encoderThreads, decoder: engine.cpuThreads }, avatar, drawn };
}
