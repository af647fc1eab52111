/** The engine's arguments, checked: a wrong one is a TypeError or RangeError that names it, never a silent wrong result. */
import type { Backend } from './backends';
export { checkedStallSeconds } from '../model/fetch-body';

/** Far beyond any audio scale (floats in [-1, 1], 16- or 32-bit integers); the Mel power of larger values overflows float32. */
const MAX_SAMPLE = 1e12;

/** `samples` as animate() and push() take them: a Float32Array of finite audio samples. */
export function checkedSamples(samples: unknown, what: string): Float32Array {
  if (!(samples instanceof Float32Array)) {
    const got = samples === null ? 'null' : typeof samples === 'object' ? (samples as object).constructor?.name ?? 'an object' : typeof samples;
    throw new TypeError(`${what}: samples must be a Float32Array of mono audio at the model's rate, not ${got}` +
      (got === 'AudioBuffer' ? ' (decodeAudio() gives both: pass its samples)' : ''));
  }
  for (let i = 0; i < samples.length; i++) {
    const v = samples[i];
    if (!(Math.abs(v) <= MAX_SAMPLE)) throw new RangeError(`${what}: sample ${i} is ${v}: audio samples must be finite numbers within +-${MAX_SAMPLE}`);
  }
  return samples;
}

/** animate()'s chunkFrames: a whole number (below 1 means 1). */
export function checkedChunk(chunkFrames: number): number {
  if (!Number.isInteger(chunkFrames)) throw new RangeError(`chunkFrames must be a whole number of frames, not ${chunkFrames}`);
  return Math.max(1, chunkFrames);
}

/** attentionAt()'s frame: a number (clamped to the clip). */
export function checkedFrame(frame: number, frames: number): number {
  if (!Number.isFinite(frame)) throw new RangeError(`frame must be a frame number from 0 to ${frames - 1}, not ${frame}`);
  return Math.min(Math.max(0, Math.floor(frame)), frames - 1);
}

/** A backend by name: auto, cpu or webgpu. */
export function checkedBackend(backend: unknown): 'auto' | Backend {
  if (backend === 'auto' || backend === 'cpu' || backend === 'webgpu') return backend;
  throw new RangeError(`backend must be 'auto', 'cpu' or 'webgpu', not ${JSON.stringify(backend)}`);
}

/** Most decoder workers a page may ask for: more than any core count a browser reports for a page's use. */
const MAX_CPU_WORKERS = 64;

/** load()'s cpuWorkers: a whole number from 0 to MAX_CPU_WORKERS (0 or 1: the page's thread). */
export function checkedWorkers(workers: unknown): number {
  if (typeof workers !== 'number' || !Number.isInteger(workers) || workers < 0 || workers > MAX_CPU_WORKERS) {
    throw new RangeError(`cpuWorkers must be a whole number from 0 to ${MAX_CPU_WORKERS}, not ${JSON.stringify(workers) ?? String(workers)}`);
  }
  return workers;
}

/** attentionAt()'s layer: 0 to layers - 1 (the decoder's layers count from 0). */
export function checkedLayer(layer: unknown, layers: number): number {
  if (typeof layer !== 'number' || !Number.isInteger(layer) || layer < 0 || layer >= layers) {
    throw new RangeError(`layer must be a whole number from 0 to ${layers - 1} (the decoder's layers count from 0), not ${JSON.stringify(layer) ?? String(layer)}`);
  }
  return layer;
}

/** The head motion's seed: an integer JavaScript holds exactly (beyond 2^53 it is rounded, and the motion would not be
 * Python's for the same seed), or null (the pose head's mean pose alone). */
export function checkedSeed(seed: unknown): number | null {
  if (seed !== null && !Number.isSafeInteger(seed)) {
    throw new RangeError(`headMotionSeed must be an integer from -(2^53 - 1) to 2^53 - 1, or null, not ${String(seed)}`);
  }
  return seed as number | null;
}
