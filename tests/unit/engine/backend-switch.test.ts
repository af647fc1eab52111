/**
 * DecoderBackends.set (src/engine/backends.ts) when choices overlap: the latest wins. WebGPU is stood in for (no
 * adapter in Node): the adapter probe and the device request are promises the test settles when it chooses, and
 * GpuDecoder is a stand-in that counts what was made and destroyed.
 */
import { beforeEach, describe, expect, it, vi } from 'vitest';
import type { DecoderBackends as Backends } from '../../../src/engine/backends';
import { loadDecoderWeights, loadManifest, loadTemplateFile } from '../helpers/exported';

const gpu = vi.hoisted(() => {
  const deferred = <T>(): { promise: Promise<T>; resolve: (v: T) => void } => {
    let resolve!: (v: T) => void;
    const promise = new Promise<T>((r) => { resolve = r; });
    return { promise, resolve };
  };
  const state = {
    deferred,
    device: deferred<unknown>(),
    made: [] as { destroyed: boolean }[],
  };
  return state;
});

vi.mock('../../../src/gpu/capabilities', () => ({
  detectWebGPU: () => Promise.resolve({ available: true, description: 'a stand-in adapter', adapter: {}, info: null }),
  isHardwareAdapter: () => true,
  requestSharedDevice: () => gpu.device.promise,
}));

vi.mock('../../../src/attention/gpu-decoder', () => ({
  GpuDecoder: class {
    destroyed = false;
    readonly device = { lost: new Promise(() => undefined) }; // never lost in these tests
    constructor() { gpu.made.push(this); }
    destroy(): void { this.destroyed = true; }
  },
}));

const { DecoderBackends } = await import('../../../src/engine/backends');

async function cpuBackends(): Promise<Backends> {
  const manifest = loadManifest();
  const template = await loadTemplateFile(manifest);
  const noGpu = { available: false, description: 'none at load', adapter: null, info: null };
  return DecoderBackends.create(loadDecoderWeights(manifest), template.adjacency, manifest.model.config, noGpu, 8,
    { backend: 'cpu', cpuWorkers: 1 });
}

describe('DecoderBackends.set: the latest choice wins', () => {
  beforeEach(() => {
    gpu.device = gpu.deferred();
    gpu.made.length = 0;
  });

  it('a CPU choice made while WebGPU is still being set up stays the decoder', async () => {
    const b = await cpuBackends();
    const toGpu = b.set('webgpu');
    await b.set('cpu');
    gpu.device.resolve({});
    await toGpu;
    expect(b.backend).toBe('cpu');
    expect(b.reason).toBe('CPU decoder chosen');
    expect(gpu.made).toEqual([]); // no WebGPU decoder was made for the choice overtaken
    b.dispose();
  });

  it('two WebGPU choices in a row make one decoder', async () => {
    const b = await cpuBackends();
    const first = b.set('webgpu');
    const second = b.set('webgpu');
    gpu.device.resolve({});
    await Promise.all([first, second]);
    expect(b.backend).toBe('webgpu');
    expect(gpu.made.length).toBe(1);
    b.dispose();
    expect(gpu.made[0].destroyed).toBe(true);
  });

  it('a switch still waiting when the engine is disposed makes nothing', async () => {
    const b = await cpuBackends();
    const toGpu = b.set('webgpu');
    b.dispose();
    gpu.device.resolve({});
    await toGpu;
    expect(gpu.made).toEqual([]);
  });

  it('an uncontested switch still happens', async () => {
    const b = await cpuBackends();
    const toGpu = b.set('webgpu');
    gpu.device.resolve({});
    await toGpu;
    expect(b.backend).toBe('webgpu');
    expect(b.reason).toBe('WebGPU: a stand-in adapter');
    await b.set('cpu');
    expect(gpu.made[0].destroyed).toBe(true);
    b.dispose();
  });
});
