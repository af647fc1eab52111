/**
 * Whether this page's WebGL draws in software (SwiftShader, llvmpipe, WARP): a computer without a usable GPU, where
 * every pixel is drawn by the CPU that the model's sessions start on. There the views draw without multisampling:
 * under SwiftShader the demo was ready sooner without it in six alternating pairs of `npm run bench --
 * --first-load-only` (medians 2.45 against 2.90 s; README, First load), and the face shown sooner too. On a GPU,
 * multisampling costs next to nothing and the edges stay smooth.
 */

/** Renderer names of software rasterisers, as WEBGL_debug_renderer_info gives them (ANGLE wraps them in its own). */
const SOFTWARE = /SwiftShader|llvmpipe|softpipe|Software Rasterizer|Microsoft Basic Render/i;

let probed: boolean | undefined;

/** True where `renderer` (WEBGL_debug_renderer_info's UNMASKED_RENDERER_WEBGL) names a software rasteriser. */
export function isSoftwareRenderer(renderer: string): boolean {
  return SOFTWARE.test(renderer);
}

/**
 * Whether WebGL is software here: probed once per page, on a throwaway canvas whose context is released at once
 * (about 20 ms under SwiftShader). Where the browser does not name its renderer, a GPU is assumed.
 */
export function softwareWebGL(): boolean {
  if (probed === undefined) probed = probe();
  return probed;
}

function probe(): boolean {
  if (typeof document === 'undefined') return false;
  const canvas = document.createElement('canvas');
  const gl = canvas.getContext('webgl2') ?? canvas.getContext('webgl');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const renderer = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  gl.getExtension('WEBGL_lose_context')?.loseContext();
  return isSoftwareRenderer(renderer);
}

/**
 * The drawing buffer's pixels per CSS pixel: the screen's (at most 2) on a GPU; 1 where WebGL draws in software, where
 * every pixel costs the CPU the model runs on: four times the pixels of a 2x screen left the live face a slideshow
 * (`npm run bench -- --live-only`; README, the figures after the bench table).
 */
export function pixelRatio(): number {
  return softwareWebGL() ? 1 : Math.min(globalThis.devicePixelRatio ?? 1, 2);
}
