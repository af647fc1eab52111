/**
 * A stand-in engine for unit tests of streamed speech (player/speech-stream.ts, page-stream.ts): its streams are the
 * real StreamSession on a pipeline whose frames carry their index, at RATE and FPS with LOOK_AHEAD samples read ahead.
 */
import type { TalkingFaceEngine } from '../../../src/engine/engine';
import type { Frames } from '../../../src/engine/frames';
import type { Pipeline } from '../../../src/engine/pipeline';
import { StreamSession } from '../../../src/engine/stream';

export const RATE = 16000;
export const FPS = 25;
export const LOOK_AHEAD = 1600; // samples: 0.1 s

/** `pushed` counts the samples its streams received and the frames produced; `fail`: every chunk throws 'boom'. */
export function standIn(pushed: { samples: number; produced: number }, fail = false): TalkingFaceEngine {
  const pipeline = {
    manifest: { audio: { sample_rate: RATE } }, fps: FPS, newState: () => ({}), samplesBehind: () => 0,
    frameCount: (n: number) => Math.max(1, Math.round((n / RATE) * FPS)),
    samplesNeeded: (f: number) => (f * RATE) / FPS + LOOK_AHEAD,
    produce: async (_s: unknown, f0: number, f1: number): Promise<Frames> => {
      if (fail) throw new Error('boom');
      pushed.produced += f1 - f0;
      const count = f1 - f0;
      return { count, vertices: new Float32Array(count * 3), unposed: Float32Array.from({ length: count * 3 }, (_, i) => f0 + Math.floor(i / 3)),
        pose: new Float32Array(count * 6), tongue: new Float32Array(count), speech: new Float32Array(count).fill(1), phones: new Uint8Array(count) };
    },
  } as unknown as Pipeline;
  return {
    manifest: pipeline.manifest, fps: FPS, backend: 'cpu',
    createStream: (onFrames: (first: number, frames: Frames) => void, options?: object) => {
      const s = new StreamSession(pipeline, onFrames);
      streamOptions.push(options ?? {});
      const push = s.push.bind(s);
      s.push = (x: Float32Array) => ((pushed.samples += x.length), push(x));
      return s;
    },
  } as unknown as TalkingFaceEngine;
}

/** The options each stream of a stand-in engine was created with, in order (cleared by the test as it likes). */
export const streamOptions: object[] = [];
