/**
 * The decoder workers' start (src/attention/decoder-pool.ts): a worker whose decoder cannot be built says so at once,
 * and the pool gives way to the page's thread with the worker's reason (it waited 15 s and said "did not start").
 */
import { afterEach, describe, expect, it } from 'vitest';
import { DecoderPool } from '../../../src/attention/decoder-pool';
import type { DecoderWeights } from '../../../src/attention/reference';
import type { ModelConstants } from '../../../src/model/manifest';

const real = globalThis.Worker;
afterEach(() => {
  globalThis.Worker = real;
});

describe('DecoderPool.create', () => {
  it('returns null at once with the worker\'s own reason when a worker cannot build its decoder', async () => {
    const terminated: number[] = [];
    let made = 0;
    globalThis.Worker = class {
      onmessage: ((e: { data: unknown }) => void) | null = null;
      onerror: unknown = null;
      private readonly id = made++;
      postMessage(): void {
        setTimeout(() => this.onmessage?.({ data: { type: 'error', id: -1, message: 'WebAssembly SIMD is not supported here' } }), 5);
      }
      terminate(): void {
        terminated.push(this.id);
      }
    } as unknown as typeof Worker;
    const started = performance.now();
    const pool = await DecoderPool.create(2, {} as DecoderWeights, { offsets: new Uint32Array(1), indices: new Uint32Array(0) }, {} as ModelConstants);
    expect(pool).toBeNull();
    expect(performance.now() - started).toBeLessThan(1000);
    expect(DecoderPool.lastFailure).toBe('decoder worker could not start: WebAssembly SIMD is not supported here');
    expect(terminated.sort()).toEqual([0, 1]);
  });
});
