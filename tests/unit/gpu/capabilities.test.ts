/**
 * WebGPU probing (src/gpu/capabilities.ts) with stand-in navigator.gpu objects: every way there can be no adapter
 * gets its own reason, a software adapter says so, the answer is shared, and a failed device request is retried.
 */
import { afterEach, describe, expect, it, vi } from 'vitest';

type Capabilities = typeof import('../../../src/gpu/capabilities');

async function fresh(gpu: unknown): Promise<Capabilities> {
  vi.resetModules();
  vi.stubGlobal('navigator', gpu === undefined ? {} : { gpu });
  return import('../../../src/gpu/capabilities');
}

const adapter = (info: Record<string, unknown>, requestDevice = vi.fn()) => ({ info, requestDevice });

afterEach(() => vi.unstubAllGlobals());

describe('detectWebGPU', () => {
  it('no navigator.gpu, a failing request, no adapter: each says why', async () => {
    expect((await (await fresh(undefined)).detectWebGPU()).description).toMatch(/navigator.gpu is missing/);
    const failing = await fresh({ requestAdapter: () => Promise.reject(new Error('blocked by policy')) });
    expect(await failing.detectWebGPU()).toMatchObject({ available: false, description: expect.stringMatching(/blocked by policy/) });
    expect((await (await fresh({ requestAdapter: async () => null })).detectWebGPU()).description).toMatch(/no adapter/);
  });

  it('names the adapter, marks a software one, and asks the browser once', async () => {
    const requestAdapter = vi.fn(async () => adapter({ vendor: 'google', architecture: 'swiftshader', device: '', isFallbackAdapter: true }));
    const m = await fresh({ requestAdapter });
    const [a, b] = await Promise.all([m.detectWebGPU(), m.detectWebGPU()]);
    expect(a).toBe(b);
    expect(requestAdapter).toHaveBeenCalledTimes(1);
    expect(a.description).toBe('google swiftshader (fallback adapter, software)');
    expect(a.info?.isFallbackAdapter).toBe(true);
  });

  it('reads an adapter of a browser before GPUAdapter.info (Chrome 113-126): its async info, or none, not a TypeError', async () => {
    const older = { requestAdapterInfo: async () => ({ vendor: 'acme', architecture: 'gen9', device: '' }), isFallbackAdapter: false, requestDevice: vi.fn() };
    expect(await (await fresh({ requestAdapter: async () => older })).detectWebGPU()).toMatchObject({ available: true, description: 'acme gen9' });
    const bare = { requestDevice: vi.fn() };
    expect(await (await fresh({ requestAdapter: async () => bare })).detectWebGPU()).toMatchObject({ available: true, description: 'unnamed adapter' });
  });

  it('an adapter request that never answers: the page goes on without WebGPU after a while, and keeps that answer', async () => {
    vi.useFakeTimers();
    try {
      const requestAdapter = vi.fn(() => new Promise<never>(() => undefined));
      const m = await fresh({ requestAdapter });
      const probed = m.detectWebGPU();
      await vi.advanceTimersByTimeAsync(60_000);
      expect(await probed).toMatchObject({ available: false, description: expect.stringMatching(/no answer within 60 s/) });
      expect(await m.detectWebGPU()).toBe(await probed); // (not another 10 s for every later caller)
      expect(requestAdapter).toHaveBeenCalledTimes(1);
    } finally {
      vi.useRealTimers();
    }
  });

  it('shares one device, and retries after a failed device request', async () => {
    const device = { lost: new Promise(() => undefined) };
    const requestDevice = vi.fn().mockRejectedValueOnce(new Error('out of memory')).mockResolvedValue(device);
    const m = await fresh({ requestAdapter: async () => adapter({ vendor: 'acme', architecture: 'x', device: 'y' }, requestDevice) });
    await expect(m.requestSharedDevice()).rejects.toThrow(/out of memory/);
    await new Promise((r) => setTimeout(r, 0));
    const [d1, d2] = await Promise.all([m.requestSharedDevice(), m.requestSharedDevice()]);
    expect(d1).toBe(device);
    expect(d2).toBe(device);
    expect(requestDevice).toHaveBeenCalledTimes(2);
  });
});
