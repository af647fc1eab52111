/**
 * Whether this page's WebGL draws in software (SwiftShader, llvmpipe, WARP): a computer without a usable GPU, where
 * every pixel is drawn by the CPU that the model's sessions start on. There the views draw without multisampling:
 * under SwiftShader the demo was ready sooner without it in six alternating pairs of `npm run bench --
 * --first-load-only` (medians 2.45 against 2.90 s; README, First load), and the face shown sooner too. On a GPU,
 * multisampling costs next to nothing and the edges stay smooth.
 */

/** Renderer names of software rasterisers, as WEBGL_debug_renderer_info gives them (ANGLE wraps them in its own). */
const SOFTWARE = /SwiftShader|llvmpipe|softpipe|Software Rasterizer|Microsoft Basic Render/i;

/** What this page's WebGL is: drawn by a GPU, in software, or not there at all. */
type Gl = 'gpu' | 'software' | 'none';
let probed: Gl | undefined;

/** True where `renderer` (WEBGL_debug_renderer_info's UNMASKED_RENDERER_WEBGL) names a software rasteriser. */
export function isSoftwareRenderer(renderer: string): boolean {
  return SOFTWARE.test(renderer);
}

/**
 * Whether WebGL is software here: probed once per page, on a throwaway canvas whose context is released at once
 * (about 20 ms under SwiftShader). Where the browser does not name its renderer, a GPU is assumed.
 */
export function softwareWebGL(): boolean {
  return (probed ??= probe()) === 'software';
}

/**
 * Whether this page can draw 3D at all: false where the browser gives no WebGL (hardware acceleration turned off, a
 * graphics driver it blocks with no software fallback, a policy); true where there is no document to ask (a server).
 */
export function webglAvailable(): boolean {
  return (probed ??= probe()) !== 'none';
}

function probe(): Gl {
  if (typeof document === 'undefined') return 'gpu';
  const canvas = document.createElement('canvas');
  const gl = canvas.getContext('webgl2'); // three.js draws with WebGL 2 only: WebGL 1 alone is none
  if (!gl) return 'none';
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const renderer = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  gl.getExtension('WEBGL_lose_context')?.loseContext();
  return isSoftwareRenderer(renderer) ? 'software' : 'gpu';
}

/** What a visitor is told where the face cannot be drawn (webglAvailable() false). */
export const NO_WEBGL = 'this browser cannot draw 3D here (WebGL is turned off or unavailable): turn on hardware acceleration in its settings, or try another browser';

/**
 * The drawing buffer's pixels per CSS pixel: the screen's (at most 2) on a GPU; 1 where WebGL draws in software, where
 * every pixel costs the CPU the model runs on: four times the pixels of a 2x screen left the live face a slideshow
 * (`npm run bench -- --live-only`; README, the figures after the bench table).
 */
export function pixelRatio(): number {
  return softwareWebGL() ? 1 : Math.min(globalThis.devicePixelRatio ?? 1, 2);
}
