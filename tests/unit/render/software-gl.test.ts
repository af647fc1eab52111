/** Software WebGL (src/render/software-gl.ts): which renderer names count as a software rasteriser; no WebGL at all. */
import { afterEach, describe, expect, it, vi } from 'vitest';
import { isSoftwareRenderer, pixelRatio, softwareWebGL, webglAvailable } from '../../../src/render/software-gl';

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

afterEach(() => vi.unstubAllGlobals());

describe('software WebGL', () => {
  it('names the software rasterisers, and leaves GPUs as hardware', () => {
    for (const [name, software] of NAMES) expect(isSoftwareRenderer(name), name).toBe(software);
  });

  it('assumes a GPU where there is no document to probe', () => {
    expect(softwareWebGL()).toBe(false);
  });

  it('draws at the screen\'s pixel ratio (at most 2) on a GPU, at 1 in software', async () => {
    vi.stubGlobal('devicePixelRatio', 3);
    expect(pixelRatio()).toBe(2);
    vi.stubGlobal('devicePixelRatio', 1.5);
    expect(pixelRatio()).toBe(1.5);
    // A page whose WebGL names SwiftShader (the probe runs once per page: a fresh module).
    const gl = { getExtension: (n: string) => (n === 'WEBGL_debug_renderer_info' ? { UNMASKED_RENDERER_WEBGL: 1 } : { loseContext() {} }),
      getParameter: () => 'ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero)), SwiftShader driver)' };
    vi.stubGlobal('document', { createElement: () => ({ getContext: () => gl }) });
    vi.resetModules();
    const fresh = await import('../../../src/render/software-gl');
    vi.stubGlobal('devicePixelRatio', 2);
    expect(fresh.softwareWebGL()).toBe(true);
    expect(fresh.pixelRatio()).toBe(1);
    expect(fresh.webglAvailable()).toBe(true);
  });

  it('tells a page without WebGL (its canvases give no context) from one that has it', async () => {
    expect(webglAvailable(), 'no document to ask: assumed').toBe(true);
    vi.stubGlobal('document', { createElement: () => ({ getContext: () => null }) });
    vi.resetModules();
    const fresh = await import('../../../src/render/software-gl');
    expect(fresh.webglAvailable()).toBe(false);
    expect(fresh.softwareWebGL()).toBe(false);
  });
});
