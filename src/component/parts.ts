/** <talking-face>'s shadow DOM: its style, the canvas a view draws on, the status line. */

export const STYLE = `
:host { display: block; position: relative; width: 100%; aspect-ratio: 4 / 3; min-height: 160px; background: #15181d; border-radius: 8px; overflow: hidden; contain: content; }
canvas { display: block; width: 100%; height: 100%; outline: none; }
canvas:focus-visible { box-shadow: inset 0 0 0 3px #7ab8ff; }
.status { position: absolute; left: 0; right: 0; bottom: 0; margin: 0; padding: 4px 8px; font: 12px/1.4 system-ui, sans-serif; color: #dfe6ee; background: rgba(0, 0, 0, 0.45); }
.status.error { color: #ffd2d2; background: rgba(120, 0, 0, 0.6); }
:host([hide-status]) .status:not(.error) { display: none; }
`;

/**
 * A canvas for a view. Each view gets a new one: a second WebGL renderer on a canvas whose context a first one used
 * inherits that context's state (pixel-store flags three.js believes unset), and uploads fail.
 */
export function newCanvas(): HTMLCanvasElement {
  const canvas = document.createElement('canvas');
  canvas.setAttribute('part', 'canvas');
  canvas.tabIndex = 0;
  canvas.setAttribute('role', 'img');
  canvas.setAttribute('aria-label', 'Animated 3D face. Drag to orbit, scroll to zoom.');
  return canvas;
}

/** The style, a canvas and the status line (a polite live region) in a new shadow root. */
export function shadowParts(host: HTMLElement): { canvas: HTMLCanvasElement; status: HTMLParagraphElement } {
  const root = host.attachShadow({ mode: 'open' });
  const style = document.createElement('style');
  style.textContent = STYLE;
  const canvas = newCanvas();
  const status = document.createElement('p');
  status.className = 'status';
  status.setAttribute('part', 'status');
  status.setAttribute('role', 'status');
  status.setAttribute('aria-live', 'polite');
  root.append(style, canvas, status);
  return { canvas, status };
}
