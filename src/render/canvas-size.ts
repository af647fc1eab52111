/** Size a renderer's drawing buffer and its camera's aspect to the canvas's displayed size (the face and avatar views). */
import type * as THREE from 'three';

export function fitToCanvas(canvas: HTMLCanvasElement, renderer: THREE.WebGLRenderer, camera: THREE.PerspectiveCamera): void {
  const w = Math.max(1, canvas.clientWidth);
  const h = Math.max(1, canvas.clientHeight);
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}

/**
 * Whether any of a view's canvas is on screen (IntersectionObserver), for its frame loop: scrolled out of view or in a
 * `display: none` container, a view draws nothing (the browser already stops a hidden tab's animation frames), and
 * `onShown` asks for a frame when it comes back. True until the first report, so the first frame is not held up.
 */
export class OnScreen {
  shown = true;
  private readonly observer: IntersectionObserver;

  constructor(canvas: HTMLCanvasElement, onShown: () => void) {
    this.observer = new IntersectionObserver((entries) => {
      this.shown = entries[entries.length - 1].isIntersecting;
      if (this.shown) onShown();
    });
    this.observer.observe(canvas);
  }

  disconnect(): void {
    this.observer.disconnect();
  }
}
