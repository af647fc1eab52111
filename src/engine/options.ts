/** The options of TalkingFaceEngine.load and animate (engine.ts). */
import type { ArtefactOptions } from '../model/artefacts';
import type { ExecutionProvider } from '../encoders/onnx-model';
import type { Backend } from './backends';
import type { Frames } from './frames';

export interface EngineOptions extends ArtefactOptions {
  /**
   * 'auto' (default): WebGPU on a hardware adapter, else the CPU decoder. A software fallback adapter
   * (SwiftShader) computes the same numbers, more slowly than the CPU path; ask for 'webgpu' to use it anyway.
   * 'cpu': no WebGPU adapter is asked for, and the encoders run on WebAssembly too (unless onnxProviders says else).
   */
  backend?: 'auto' | Backend;
  /**
   * Web Workers for the CPU decoder (default: one per core, up to 4; 0 or 1 decodes in the page's
   * thread). Each chunk's frames are split between them; the numbers are the same either way.
   */
  cpuWorkers?: number;
  /** Execution providers for the ONNX encoders, in order of preference (default: webgpu then wasm on a hardware adapter, else wasm). */
  onnxProviders?: ExecutionProvider[];
  /**
   * The head's own motion (docs/engine.md): the seed it is drawn with (default 0), or null for the pose head's mean
   * pose alone (a head that barely moves). Ignored for a model exported without it.
   */
  headMotionSeed?: number | null;
  /**
   * How far the head's own motion turns the head (default 1, as fitted: the corpus's typical speaker; 0.5 a calm
   * one, 1.5 a lively one; 0 the mean pose alone). Speakers differ in this and their voices do not say it.
   */
  headMotionScale?: number;
}

export interface AnimateOptions {
  /** Frames per chunk (default DEFAULT_CHUNK_FRAMES, 96). */
  chunkFrames?: number;
  /** Called after each chunk with the frames done so far. */
  onProgress?: (done: number, total: number) => void;
  /** Receives each chunk's frames instead of (or as well as) the returned buffer; `frames` has all of the chunk. */
  onFrames?: (first: number, vertices: Float32Array, pose: Float32Array, frames: Frames) => void;
  /** false: do not keep all frames (use onFrames); memory then stays one chunk. Default true. */
  keep?: boolean;
  /** Also keep the unposed face I + O per frame (what a renderer that poses the head itself wants). */
  unposed?: boolean;
  /**
   * Also compute, per frame, the 52 ARKit blend-shape weights, the 15 Oculus visemes and the head's yaw, pitch and
   * roll (Animation.blendshapes; src/avatar/, docs/avatar.md). Off by default: it costs a solve per frame.
   */
  blendshapes?: boolean;
  /** How far the head's own motion turns the head in this animation (default: engine.headMotionScale). */
  headMotionScale?: number;
  signal?: AbortSignal;
}
