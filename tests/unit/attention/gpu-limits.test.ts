/**
 * How many frames a WebGPU batch may hold (src/attention/gpu-decoder.ts gpuFramesWithin): past a device's limits
 * WebGPU only logs an error and the batch reads back zeros, so a decoder is sized within them or refused.
 */
import { describe, expect, it } from 'vitest';
import { GpuDecoder, gpuFramesWithin } from '../../../src/attention/gpu-decoder';
import type { DecoderWeights } from '../../../src/attention/reference';
import type { ModelConstants } from '../../../src/model/manifest';

const DEFAULTS = { maxStorageBufferBindingSize: 134_217_728, maxBufferSize: 268_435_456, maxComputeWorkgroupsPerDimension: 65_535 };

describe('gpuFramesWithin', () => {
  it('keeps the frames asked for where they fit: the shipped face (468 vertices, d 32) at 96 frames', () => {
    expect(gpuFramesWithin(DEFAULTS, 468, 32, 200_000, 96)).toBe(96); // 96 x 469 x 96 x 4 bytes = 17 MB
  });

  it('holds fewer frames a batch where q, k and v of every frame would pass the storage binding', () => {
    // 5,023 vertices (FLAME) at d 32: 1.93 MB a frame, 69 fit in 128 MiB, not 96
    const frames = gpuFramesWithin(DEFAULTS, 5023, 32, 200_000, 96);
    expect(frames).toBe(Math.floor(134_217_728 / (5024 * 3 * 32 * 4)));
    expect(frames * 5024 * 3 * 32 * 4).toBeLessThanOrEqual(134_217_728);
    // a device that grants more keeps them all
    expect(gpuFramesWithin({ ...DEFAULTS, maxStorageBufferBindingSize: 1 << 30, maxBufferSize: 1 << 30 }, 5023, 32, 200_000, 96)).toBe(96);
    // the buffer size caps a binding as well
    expect(gpuFramesWithin({ ...DEFAULTS, maxStorageBufferBindingSize: 1 << 30, maxBufferSize: 1 << 27 }, 5023, 32, 200_000, 96)).toBe(frames);
  });

  it('refuses, saying which limit, a mesh or model no batch can hold', () => {
    expect(() => gpuFramesWithin(DEFAULTS, 70_000, 32, 200_000, 96)).toThrow(/70001 tokens exceed this device's 65535 workgroups per dispatch/);
    expect(() => gpuFramesWithin(DEFAULTS, 468, 32, 40_000_000, 96)).toThrow(/weights \(160000000 bytes\) exceed this device's 134217728-byte storage binding/);
    expect(() => gpuFramesWithin({ ...DEFAULTS, maxStorageBufferBindingSize: 1 << 20 }, 5023, 32, 1000, 96)).toThrow(/one frame of 5024 tokens of 32/);
  });

  it('refuses, before touching the device, a model the shader cannot run', () => {
    const build = (d_model: number, heads: number) => () =>
      new GpuDecoder({} as GPUDevice, {} as DecoderWeights, { offsets: new Uint32Array(1), indices: new Uint32Array(0) },
        { d_model, heads, ffn: 64 } as ModelConstants, 8);
    expect(build(4, 1)).toThrow(/d_model 4 must be a power of two from 8 to 256/); // pose channels 4 and 5 unwritten
    expect(build(48, 4)).toThrow(/power of two/);
    expect(build(32, 3)).toThrow(/3 heads do not divide d_model 32/);
  });
});
