/** Size a renderer's drawing buffer and its camera's aspect to the canvas's displayed size (the face and avatar views). */
import type * as THREE from 'three';
import { pixelRatio } from './software-gl';

export function fitToCanvas(canvas: HTMLCanvasElement, renderer: THREE.WebGLRenderer, camera: THREE.PerspectiveCamera): void {
  const w = Math.max(1, canvas.clientWidth);
  const h = Math.max(1, canvas.clientHeight);
  renderer.setPixelRatio(pixelRatio()); // the screen's now: the page zoomed, or moved to another screen
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}

/**
 * What a view's canvas needs watched (the face and avatar views):
 * - its displayed size, and the screen's pixel ratio, which zooming the page or moving the window to another screen
 *   changes without changing the CSS size: `resize` then (else the face is drawn blurred, or at too many pixels);
 * - whether any of it is on screen (IntersectionObserver), for its frame loop: scrolled out of view or in a
 *   `display: none` container, a view draws nothing (the browser already stops a hidden tab's animation frames),
 *   and `redraw` asks for a frame when it comes back. `shown` is true until the first report, so the first frame is
 *   not held up;
 * - a lost WebGL context given back: what was drawn is gone, so `redraw` (a view at rest draws only when asked).
 */
export class CanvasWatch {
  shown = true;
  private readonly resizes: ResizeObserver;
  private readonly onScreen: IntersectionObserver;
  private ratio: MediaQueryList | null = null;
  private readonly ratioChanged = (): void => {
    this.watchRatio();
    this.resize();
  };
  private readonly restored: () => void;

  constructor(private readonly canvas: HTMLCanvasElement, private readonly resize: () => void, redraw: () => void) {
    this.resizes = new ResizeObserver(() => resize());
    this.resizes.observe(canvas);
    this.onScreen = new IntersectionObserver((entries) => {
      this.shown = entries[entries.length - 1].isIntersecting;
      if (this.shown) redraw();
    });
    this.onScreen.observe(canvas);
    this.restored = redraw;
    canvas.addEventListener('webglcontextrestored', redraw);
    this.watchRatio();
  }

  /** A media query that holds at the present ratio only: its change is the next change of ratio. */
  private watchRatio(): void {
    this.ratio?.removeEventListener('change', this.ratioChanged);
    this.ratio = globalThis.matchMedia?.(`(resolution: ${globalThis.devicePixelRatio ?? 1}dppx)`) ?? null;
    this.ratio?.addEventListener('change', this.ratioChanged);
  }

  disconnect(): void {
    this.resizes.disconnect();
    this.onScreen.disconnect();
    this.ratio?.removeEventListener('change', this.ratioChanged);
    this.canvas.removeEventListener('webglcontextrestored', this.restored);
  }
}
