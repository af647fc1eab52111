/**
 * DecoderBackends (src/engine/backends.ts) when its decoder workers fail under two decodes at once (an animation and a
 * stream, say): both go on in the page's thread with the same numbers, the workers are let go once, and the reason
 * says so once. The pool is stood in for (Node has no Web Workers): its decodes wait, then fail together.
 */
import { describe, expect, it, vi } from 'vitest';
import { loadDecoderWeights, loadManifest, loadTemplateFile } from '../helpers/exported';

const pool = vi.hoisted(() => ({ terminated: 0, fail: (_e: Error) => undefined as void }));

vi.mock('../../../src/attention/decoder-pool', () => ({
  DecoderPool: class {
    static lastFailure = null;
    static async create(): Promise<unknown> {
      const waiting: ((e: Error) => void)[] = [];
      pool.fail = (e) => waiting.splice(0).forEach((reject) => reject(e));
      return {
        kernel: 'stand-in', size: 2,
        decode: () => new Promise((_, reject) => waiting.push(reject)),
        terminate: () => { pool.terminated++; pool.fail(new Error('terminated')); },
      };
    }
  },
}));

const { DecoderBackends } = await import('../../../src/engine/backends');

describe('DecoderBackends: workers failing under two decodes at once', () => {
  it('decodes both in the page\'s thread, letting the workers go once', async () => {
    const manifest = loadManifest();
    const m = manifest.model.config;
    const template = await loadTemplateFile(manifest);
    const n = template.adjacency.offsets.length - 1;
    const noGpu = { available: false, description: 'none in this test', adapter: null, info: null };
    const b = await DecoderBackends.create(loadDecoderWeights(manifest), template.adjacency, m, noGpu, 8, { backend: 'cpu', cpuWorkers: 2 });
    const frames = 3;
    const latents = Float32Array.from({ length: frames * 2 * m.d_model }, (_, i) => Math.sin(i));
    const poseToken = Float32Array.from({ length: frames * m.d_model }, (_, i) => Math.cos(i));
    const both = [b.decode(latents, poseToken, frames, n), b.decode(latents, poseToken, frames, n)];
    pool.fail(new Error('a worker crashed'));
    const [x, y] = await Promise.all(both);
    const direct = b.cpu.decodeLatents(latents, poseToken, frames);
    expect(x.offsets).toEqual(direct.offsets);
    expect(y.offsets).toEqual(direct.offsets);
    expect(pool.terminated).toBe(1);
    expect(b.reason.match(/the decoder workers failed/g)).toHaveLength(1);
    b.dispose();
  });
});
