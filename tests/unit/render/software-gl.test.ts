/** Software WebGL (src/render/software-gl.ts): which renderer names count as a software rasteriser. */
import { describe, expect, it } from 'vitest';
import { isSoftwareRenderer, softwareWebGL } from '../../../src/render/software-gl';

/** Renderer names as browsers report them (WEBGL_debug_renderer_info), and whether each is software. */
const NAMES: [string, boolean][] = [
  ['ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero) (0x0000C0DE)), SwiftShader driver)', true],
  ['llvmpipe (LLVM 15.0.6, 256 bits)', true],
  ['ANGLE (Microsoft, Microsoft Basic Render Driver Direct3D11 vs_5_0 ps_5_0, D3D11)', true],
  ['Google SwiftShader', true],
  ['ANGLE (NVIDIA, NVIDIA GeForce RTX 3060 (0x00002503) Direct3D11 vs_5_0 ps_5_0, D3D11)', false],
  ['Apple M2', false],
  ['Mali-G78', false],
  ['ANGLE (Intel, Mesa Intel(R) UHD Graphics 620 (KBL GT2), OpenGL 4.6)', false],
  ['', false], // not named: a GPU is assumed
];

describe('software WebGL', () => {
  it('names the software rasterisers, and leaves GPUs as hardware', () => {
    for (const [name, software] of NAMES) expect(isSoftwareRenderer(name), name).toBe(software);
  });

  it('assumes a GPU where there is no document to probe', () => {
    expect(softwareWebGL()).toBe(false);
  });
});
