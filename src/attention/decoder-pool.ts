/**
 * The CPU decoder on several cores: Web Workers each running FastDecoder, every chunk's frames split
 * between them in contiguous runs. Frames are independent in the decoder, so the result is exactly
 * what one FastDecoder computes (same code, same order of operations per frame). Where workers are
 * unavailable (no Worker, a CSP that forbids them, one core) the engine uses FastDecoder in-thread.
 */
import type { DecodeResult, DecoderWeights } from './reference';
import type { ModelConstants } from '../model/manifest';
import type { Adjacency } from '../template/mesh-topology';

interface Pending {
  resolve: (r: { offsets: Float32Array; pose: Float32Array }) => void;
  reject: (e: Error) => void;
}

export class DecoderPool {
  private readonly pending = new Map<number, Pending>();
  private nextId = 0;
  private failed: Error | null = null;

  private constructor(
    private readonly workers: Worker[],
    private readonly n: number,
    private readonly d: number,
    /** The workers' decoder arithmetic ('wasm-simd' or 'js'). */
    readonly kernel: string,
  ) {
    for (const w of workers) {
      w.onmessage = (e: MessageEvent<{ type: string; id: number; offsets?: Float32Array; pose?: Float32Array; message?: string }>) => {
        const m = e.data;
        const p = this.pending.get(m.id);
        if (!p) return;
        this.pending.delete(m.id);
        if (m.type === 'done') p.resolve({ offsets: m.offsets!, pose: m.pose! });
        else p.reject(new Error(m.message ?? 'decoder worker failed'));
      };
      w.onerror = (e) => this.fail(new Error(`decoder worker crashed: ${e.message}`));
    }
  }

  /** Why the last create() returned null (for the engine's status), or null. */
  static lastFailure: string | null = null;

  /** Start `size` workers with the decoder's weights; null (and `lastFailure` says why) if workers cannot run here. */
  static async create(size: number, weights: DecoderWeights, adjacency: Adjacency, m: ModelConstants): Promise<DecoderPool | null> {
    DecoderPool.lastFailure = null;
    if (typeof Worker === 'undefined') {
      DecoderPool.lastFailure = 'no Web Workers here';
      return null;
    }
    if (size < 2) {
      DecoderPool.lastFailure = `one decoder thread asked for (${size})`;
      return null;
    }
    const workers: Worker[] = [];
    const kernels: string[] = [];
    try {
      for (let i = 0; i < size; i++) {
        workers.push(new Worker(new URL('./decoder-worker.ts', import.meta.url), { type: 'module', name: `gava-decoder-${i}` }));
      }
      await Promise.all(workers.map((w) => new Promise<void>((resolve, reject) => {
        const timer = setTimeout(() => reject(new Error('decoder worker did not start')), 15_000);
        w.onmessage = (e) => {
          if (e.data?.type === 'ready') {
            clearTimeout(timer);
            kernels.push(e.data.kernel);
            resolve();
          } else if (e.data?.type === 'error') { // its decoder could not be built: at once, and why
            clearTimeout(timer);
            reject(new Error(`decoder worker could not start: ${e.data.message}`));
          }
        };
        w.onerror = (e) => {
          clearTimeout(timer);
          reject(new Error(e.message || 'decoder worker failed to load'));
        };
        w.postMessage({ type: 'init', weights, adjacency, constants: m });
      })));
    } catch (e) {
      for (const w of workers) w.terminate();
      DecoderPool.lastFailure = (e as Error).message;
      return null;
    }
    return new DecoderPool(workers, adjacency.offsets.length - 1, m.d_model, kernels[0]);
  }

  get size(): number {
    return this.workers.length;
  }

  /** latents (F x 2d), poseToken (F x d) -> offsets (F x N x 3), pose (F x 6), as FastDecoder.decodeLatents. */
  async decode(latents: Float32Array, poseToken: Float32Array, frames: number): Promise<DecodeResult> {
    if (this.failed) throw this.failed;
    const { n, d } = this;
    const parts = Math.min(this.workers.length, frames);
    const bounds = Array.from({ length: parts + 1 }, (_, i) => Math.round((i * frames) / parts));
    const results = await Promise.all(Array.from({ length: parts }, (_, i) => {
      const [a, b] = [bounds[i], bounds[i + 1]];
      const id = this.nextId++;
      return new Promise<{ offsets: Float32Array; pose: Float32Array }>((resolve, reject) => {
        this.pending.set(id, { resolve, reject });
        const l = latents.slice(a * 2 * d, b * 2 * d);
        const p = poseToken.slice(a * d, b * d);
        this.workers[i].postMessage({ type: 'decode', id, latents: l, poseToken: p, frames: b - a }, [l.buffer, p.buffer]);
      });
    }));
    const offsets = new Float32Array(frames * n * 3);
    const pose = new Float32Array(frames * 6);
    results.forEach((r, i) => {
      offsets.set(r.offsets, bounds[i] * n * 3);
      pose.set(r.pose, bounds[i] * 6);
    });
    return { offsets, pose };
  }

  private fail(e: Error): void {
    this.failed = e;
    for (const p of this.pending.values()) p.reject(e);
    this.pending.clear();
  }

  terminate(): void {
    for (const w of this.workers) w.terminate();
    this.fail(new Error('decoder pool terminated'));
  }
}
