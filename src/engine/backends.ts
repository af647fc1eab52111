/**
 * Which decoder runs the attention (paper Eq. 1): the WGSL kernel on WebGPU, the CPU decoder in Web Workers, or
 * the CPU decoder in the page's thread, with the fallbacks between them. Every one computes the same numbers;
 * a failure switches to the next and says why in `reason`.
 */
import { FastDecoder } from '../attention/fast-decoder';
import { DecoderPool } from '../attention/decoder-pool';
import { GpuDecoder } from '../attention/gpu-decoder';
import { vertexEmbeddingMismatch, type DecodeResult, type DecoderWeights } from '../attention/reference';
import { detectWebGPU, isHardwareAdapter, requestSharedDevice, type WebGPUSupport } from '../gpu/capabilities';
import { ModelLoadError } from '../model/artefacts';
import type { ModelConstants } from '../model/manifest';
import type { Adjacency } from '../template/mesh-topology';

export type Backend = 'webgpu' | 'cpu';

export interface BackendOptions {
  /** 'auto': WebGPU on a hardware adapter, else the CPU decoder (see EngineOptions.backend). */
  backend?: 'auto' | Backend;
  /** Web Workers for the CPU decoder (see EngineOptions.cpuWorkers). */
  cpuWorkers?: number;
}

export class DecoderBackends {
  backend: Backend;
  /** Why the backend is what it is, for the status line. */
  reason: string;
  private pool: DecoderPool | null = null;
  private disposed = false;
  /** Counts set()'s calls: a switch still waiting for WebGPU gives way to any later one (or to dispose). */
  private switches = 0;

  private constructor(
    readonly cpu: FastDecoder,
    private gpu: GpuDecoder | null,
    reason: string,
    private readonly adjacency: Adjacency,
    private readonly m: ModelConstants,
    /** Frames the WebGPU decoder's buffers hold (larger chunks are decoded in pieces). */
    private readonly gpuFrames: number,
  ) {
    this.backend = gpu ? 'webgpu' : 'cpu';
    this.reason = reason;
  }

  static async create(weights: DecoderWeights, adjacency: Adjacency, m: ModelConstants, support: WebGPUSupport, gpuFrames: number,
    options: BackendOptions = {}): Promise<DecoderBackends> {
    const mismatch = vertexEmbeddingMismatch(weights, adjacency.offsets.length - 1, m.d_model);
    if (mismatch) throw new ModelLoadError(mismatch);
    const cpu = new FastDecoder(weights, adjacency, m); // first: a throw here leaves no WebGPU buffers behind
    const hardwareGpu = isHardwareAdapter(support);
    let gpu: GpuDecoder | null = null;
    let reason = 'CPU decoder chosen';
    const wantGpu = options.backend === 'webgpu' || ((options.backend ?? 'auto') === 'auto' && hardwareGpu);
    if (support.adapter && !hardwareGpu && options.backend !== 'webgpu') {
      reason = `the WebGPU adapter (${support.description}) is software, slower than the CPU path; using the CPU decoder`;
    }
    if (wantGpu) {
      if (support.adapter) {
        try {
          gpu = new GpuDecoder(await requestSharedDevice(), weights, adjacency, m, gpuFrames);
          reason = `WebGPU: ${support.description}`;
        } catch (e) {
          reason = `WebGPU could not be used (${(e as Error).message}); using the CPU decoder`;
        }
      } else {
        reason = `no WebGPU (${support.description}); using the CPU decoder`;
      }
      if (options.backend === 'webgpu' && !gpu) throw new ModelLoadError(`WebGPU was requested but is not available: ${reason}`);
    }
    const backends = new DecoderBackends(cpu, gpu, reason, adjacency, m, gpuFrames);
    const cores = globalThis.navigator?.hardwareConcurrency ?? 1;
    backends.pool = await DecoderPool.create(options.cpuWorkers ?? Math.min(4, cores), weights, adjacency, m);
    if (!backends.pool && cores > 1 && options.cpuWorkers === undefined) backends.reason += `; CPU decoder in the page's thread (${DecoderPool.lastFailure})`;
    if (gpu) backends.watch(gpu);
    return backends;
  }

  get weights(): DecoderWeights {
    return this.cpu.weights;
  }

  /** CPU decoder threads: the workers' count, or 1 when decoding in the page's thread. */
  get cpuThreads(): number {
    return this.pool?.size ?? 1;
  }

  /** The CPU decoder's arithmetic: 'wasm-simd' (WebAssembly SIMD) or 'js' (TypeScript, where SIMD is missing). */
  get cpuKernel(): string {
    return this.pool?.kernel ?? this.cpu.kernelName;
  }

  /** The vertex tokens (F x N x d) of frames' hierarchical latents (F x 2d), as the decoders make them. */
  vertexTokens(latents: Float32Array, frames: number): Float32Array {
    return this.cpu.vertexTokens(latents, frames);
  }

  /** Offsets and poses of `frames` frames from their hierarchical latents (F x 2d) and pose tokens. */
  async decode(latents: Float32Array, poseToken: Float32Array, frames: number, vertices: number): Promise<DecodeResult> {
    if (this.disposed) throw new EngineDisposedError();
    const gpu = this.gpu;
    if (gpu) {
      try {
        return await this.decodeOnGpu(gpu, latents, poseToken, frames, vertices);
      } catch (e) {
        // The animation goes on on the CPU decoder. If this decoder is still the one in use, it failed: drop it for
        // every later chunk too. If set() switched away from it meanwhile (destroying it under this decode), that
        // is no failure: only this chunk moves.
        if (this.gpu === gpu) {
          gpu.destroy();
          this.gpu = null;
          this.backend = 'cpu';
          this.reason = `WebGPU failed (${(e as Error).message}); using the CPU decoder`;
        }
      }
    }
    if (this.disposed) throw new EngineDisposedError(); // its WebGPU buffers destroyed under the decode above
    const pool = this.pool;
    if (pool && frames > 1) {
      try {
        return await pool.decode(latents, poseToken, frames);
      } catch (e) {
        if (this.disposed) throw new EngineDisposedError(); // terminated by dispose(), not crashed
        // A crashed worker: decode in this thread from now on (same numbers), and say so (once: decodes under way
        // together all fail with it).
        if (this.pool === pool) {
          pool.terminate();
          this.pool = null;
          this.reason += `; the decoder workers failed (${(e as Error).message}), decoding in the page's thread`;
        }
      }
    }
    return this.cpu.decodeLatents(latents, poseToken, frames);
  }

  private async decodeOnGpu(gpu: GpuDecoder, latents: Float32Array, poseToken: Float32Array, frames: number, n: number): Promise<DecodeResult> {
    const out: DecodeResult = { offsets: new Float32Array(frames * n * 3), pose: new Float32Array(frames * 6) };
    const step = gpu.maxFrames;
    const d = this.m.d_model;
    for (let i = 0; i < frames; i += step) {
      const j = Math.min(frames, i + step);
      const r = await gpu.decodeLatents(latents.subarray(i * 2 * d, j * 2 * d), poseToken.subarray(i * d, j * d), j - i);
      out.offsets.set(r.offsets, i * n * 3);
      out.pose.set(r.pose, i * 6);
    }
    return out;
  }

  /** A lost device (driver reset, GPU process crash): carry on with the CPU decoder. */
  private watch(decoder: GpuDecoder): void {
    void decoder.device.lost.then((info) => {
      if (this.gpu !== decoder) return;
      this.gpu = null;
      this.backend = 'cpu';
      this.reason = `WebGPU device lost (${info.message || info.reason}); using the CPU decoder`;
    });
  }

  /**
   * Switch decoders at run time (the numbers are the same; only speed differs). The latest call wins: one still
   * waiting for WebGPU when another is made (or the engine is disposed) resolves without switching.
   */
  async set(choice: 'auto' | Backend): Promise<void> {
    const call = ++this.switches;
    const overtaken = (): boolean => call !== this.switches || this.disposed;
    const backend = choice === 'auto' ? (isHardwareAdapter(await detectWebGPU()) ? 'webgpu' : 'cpu') : choice; // as at load
    if (overtaken() || backend === this.backend) return;
    if (backend === 'cpu') {
      this.gpu?.destroy();
      this.gpu = null;
      this.backend = 'cpu';
      this.reason = 'CPU decoder chosen';
      return;
    }
    const support = await detectWebGPU();
    if (overtaken()) return;
    if (!support.adapter) throw new ModelLoadError(`WebGPU is not available: ${support.description}`);
    const device = await requestSharedDevice().catch((e: unknown) => (overtaken() ? null : Promise.reject(e)));
    if (!device || overtaken()) return;
    const decoder = new GpuDecoder(device, this.cpu.weights, this.adjacency, this.m, this.gpuFrames);
    this.watch(decoder);
    this.gpu = decoder;
    this.backend = 'webgpu';
    this.reason = `WebGPU: ${support.description}`;
  }

  /** Free the WebGPU decoder's buffers and the CPU decoder's workers; later decodes are refused. */
  dispose(): void {
    this.disposed = true;
    this.gpu?.destroy();
    this.gpu = null;
    this.pool?.terminate();
    this.pool = null;
  }
}

/** What a disposed engine's calls reject with (TalkingFaceEngine.dispose). */
export class EngineDisposedError extends Error {
  constructor() {
    super('this talking-face engine was disposed; load a new one');
    this.name = 'EngineDisposedError';
  }
}
