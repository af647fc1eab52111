/** allOrFree (src/model/all-or-free.ts): a load whose part fails gives the failure at once and frees every other part. */
import { describe, expect, it, vi } from 'vitest';
import { allOrFree } from '../../../src/model/all-or-free';

describe('allOrFree', () => {
  it('gives every part when all arrive, and frees none', async () => {
    const session = { release: vi.fn(async () => undefined) };
    expect(await allOrFree([Promise.resolve(session), Promise.resolve(3)])).toEqual([session, 3]);
    expect(session.release).not.toHaveBeenCalled();
  });

  it('rejects with the first failure at once, freeing the parts made before and after it', async () => {
    const early = { release: vi.fn(async () => undefined) };
    const late = { dispose: vi.fn() };
    let arrive!: (v: typeof late) => void;
    const loading = allOrFree([Promise.resolve(early), Promise.reject(new Error('hierarchical.onnx: HTTP 404')), new Promise<typeof late>((r) => { arrive = r; }), Promise.resolve({ plain: true })]);
    await expect(loading).rejects.toThrow('hierarchical.onnx: HTTP 404'); // not held up by the part still on its way
    await Promise.resolve();
    expect(early.release).toHaveBeenCalledTimes(1);
    expect(late.dispose).not.toHaveBeenCalled();
    arrive(late);
    await new Promise((r) => setTimeout(r, 0));
    expect(late.dispose).toHaveBeenCalledTimes(1);
  });

  it('a part whose freeing fails is no unhandled rejection', async () => {
    const stubborn = { release: () => Promise.reject(new Error('already released')) };
    await expect(allOrFree([Promise.resolve(stubborn), Promise.reject(new Error('offline'))])).rejects.toThrow('offline');
    await new Promise((r) => setTimeout(r, 0));
  });
});
