/** What the engine hands out: frames of a chunk, a whole animation, and how long each stage took. */
import type { BlendshapeFrames } from '../avatar/weights';
import { ARKIT_NAMES, VISEME_NAMES } from '../avatar/names';

const ARKIT_COUNT = ARKIT_NAMES.length;
const VISEME_COUNT = VISEME_NAMES.length;

/** Frames of one chunk: posed vertices and I + O in the template's units, poses (axis-angle, mm). */
export interface Frames {
  count: number;
  vertices: Float32Array;
  unposed: Float32Array;
  pose: Float32Array;
  /** (count): the content class heard most at each frame (manifest.content_phones). */
  phones: Uint8Array;
  /** (count): how raised the tongue is, 0..1 (the posteriors of /t d n l th dh/ summed; encoders/content.ts). */
  tongue: Float32Array;
  /** ARKit weights, visemes and head rotation per frame, when the stream was created with `blendshapes: true`. */
  blendshapes?: BlendshapeFrames;
  /** (count): the probability that each frame is speech (encoders/voice-activity.ts). */
  speech: Float32Array;
}

export interface Animation {
  fps: number;
  frames: number;
  /** (frames x N x 3) posed vertices in the template's units, or empty when keep = false. */
  vertices: Float32Array;
  /** (frames x 6): axis-angle (rad), translation (mm). */
  pose: Float32Array;
  /** (frames x N x 3) I + O in the template's units, when asked for. */
  unposed?: Float32Array;
  /** (frames): the content class the encoder heard most at each frame (names: manifest.content_phones). */
  phones: Uint8Array;
  /** (frames): how raised the tongue is, 0..1 (the posteriors of /t d n l th dh/ summed; encoders/content.ts). */
  tongue: Float32Array;
  /** Per frame: 52 ARKit weights, 15 visemes, head yaw / pitch / roll (animate with `blendshapes: true`). */
  blendshapes?: BlendshapeFrames;
  /** (frames): the probability that each frame is speech: 1 - P(silence) where the signal is loud enough (encoders/voice-activity.ts). */
  speech: Float32Array;
}

/** Milliseconds spent in each stage since the last resetTimes(). */
export interface StageTimes {
  mel: number;
  content: number;
  hierarchical: number;
  pose: number;
  decoder: number;
  posing: number;
  /** The avatar stage (ARKit weights, visemes), when asked for. */
  blendshapes: number;
}

/** Chunks of streamed frames joined into one animation (they must be consecutive, from frame 0): placeFrames without gaps. */
export function joinFrames(chunks: Frames[], fps: number): Animation {
  let first = 0;
  const placed = chunks.map((frames) => ({ first: (first += frames.count) - frames.count, frames }));
  return placeFrames(placed, first, fps);
}

/**
 * Streamed chunks placed at their first frames in an animation of `total` frames: where no chunk has a frame (a
 * live stream skipped it to keep up, StreamingSession's maxLagFrames), the frame before it is held (before the
 * first chunk, its first frame).
 */
export function placeFrames(chunks: { first: number; frames: Frames }[], total: number, fps: number): Animation {
  const sorted = chunks.filter((c) => c.frames.count > 0).sort((a, b) => a.first - b.first);
  const per = sorted.length ? sorted[0].frames.vertices.length / sorted[0].frames.count : 0;
  const vertices = new Float32Array(total * per);
  const unposed = new Float32Array(total * per);
  const pose = new Float32Array(total * 6);
  const phones = new Uint8Array(total);
  const tongue = new Float32Array(total);
  const speech = new Float32Array(total);
  const blendshapes = sorted.length && sorted.every((c) => c.frames.blendshapes) ? emptyBlendshapes(total) : undefined;
  let k = 0;
  let from: Frames | null = sorted[0]?.frames ?? null, at = 0; // the frame shown at f: `from`'s frame `at`
  for (let f = 0; f < total && from; f++) {
    while (k < sorted.length && sorted[k].first + sorted[k].frames.count <= f) k++;
    if (k < sorted.length && sorted[k].first <= f) [from, at] = [sorted[k].frames, f - sorted[k].first];
    vertices.set(from.vertices.subarray(at * per, (at + 1) * per), f * per);
    unposed.set(from.unposed.subarray(at * per, (at + 1) * per), f * per);
    pose.set(from.pose.subarray(at * 6, at * 6 + 6), f * 6);
    phones[f] = from.phones[at];
    tongue[f] = from.tongue[at];
    speech[f] = from.speech[at];
    if (blendshapes && from.blendshapes) {
      const b = from.blendshapes;
      blendshapes.arkit.set(b.arkit.subarray(at * ARKIT_COUNT, (at + 1) * ARKIT_COUNT), f * ARKIT_COUNT);
      blendshapes.visemes.set(b.visemes.subarray(at * VISEME_COUNT, (at + 1) * VISEME_COUNT), f * VISEME_COUNT);
      blendshapes.headRotation.set(b.headRotation.subarray(at * 3, at * 3 + 3), f * 3);
    }
  }
  return { fps, frames: total, vertices, pose, unposed, phones, tongue, speech, blendshapes };
}

/** Room for `frames` frames of blendshape output. */
export function emptyBlendshapes(frames: number): BlendshapeFrames {
  return { arkit: new Float32Array(frames * ARKIT_COUNT), visemes: new Float32Array(frames * VISEME_COUNT), headRotation: new Float32Array(frames * 3) };
}

/** Copy a chunk's blendshape output into `all` from frame `at`. */
export function setBlendshapes(all: BlendshapeFrames, chunk: BlendshapeFrames, at: number): void {
  all.arkit.set(chunk.arkit, at * ARKIT_COUNT);
  all.visemes.set(chunk.visemes, at * VISEME_COUNT);
  all.headRotation.set(chunk.headRotation, at * 3);
}

/** What long work on the page's thread tells and is told: how far it is (0 to 1), and when to stop. */
export interface Slicing {
  onProgress?: (done: number) => void;
  signal?: AbortSignal;
}

/**
 * Long work on the page's thread, cut into slices: call the returned step after each of `total` units; once
 * `sliceMs` have passed since the last yield it reports the share done, yields to the event loop (input, drawing,
 * timers run) and throws the signal's reason if it was aborted meanwhile.
 */
export function slicer(total: number, { onProgress, signal }: Slicing, sliceMs = 25): () => Promise<void> {
  let done = 0;
  let last = performance.now();
  return async () => {
    done++;
    if (performance.now() - last < sliceMs) return;
    onProgress?.(Math.min(1, done / total));
    await yieldToEventLoop();
    signal?.throwIfAborted();
    last = performance.now();
  };
}

/** Resolve on a new task (not a microtask): lets the browser handle input, rendering and timers. */
export function yieldToEventLoop(): Promise<void> {
  return new Promise((resolve) => {
    const channel = new MessageChannel();
    channel.port1.onmessage = () => {
      channel.port1.close();
      resolve();
    };
    channel.port2.postMessage(null);
  });
}
