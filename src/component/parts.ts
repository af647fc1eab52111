/** <talking-face>'s shadow DOM: its style, the canvas a view draws on, the status line. */
import { CAMERA_KEYS_TEXT } from '../render/camera-keys';

export const STYLE = `
:host { display: block; position: relative; width: 100%; aspect-ratio: 4 / 3; min-height: 160px; background: #15181d; border-radius: 8px; overflow: hidden; contain: content; }
:host([hidden]) { display: none; }
canvas { display: block; width: 100%; height: 100%; outline: none; }
canvas:focus-visible { outline: 3px solid #7ab8ff; outline-offset: -3px; }
.status { position: absolute; left: 0; right: 0; bottom: 0; margin: 0; padding: 4px 8px; font: 12px/1.4 system-ui, sans-serif; color: #dfe6ee; background: rgba(0, 0, 0, 0.45);
  text-align: start; text-transform: none; text-indent: 0; letter-spacing: normal; word-spacing: normal; white-space: normal; } /* not the page's */
.status.error { color: #ffd2d2; background: rgba(120, 0, 0, 0.6); }
:host([hide-status]:not([hide-status="false" i])) .status:not(.error) { display: none; } /* the announcer still speaks */
.announce { position: absolute; width: 1px; height: 1px; overflow: hidden; clip-path: inset(50%); white-space: nowrap; }
`;

/**
 * A canvas for a view. Each view gets a new one: a second WebGL renderer on a canvas whose context a first one used
 * inherits that context's state (pixel-store flags three.js believes unset), and uploads fail.
 */
export function newCanvas(host: Element): HTMLCanvasElement {
  // The element's own name, where the page gave it one (two faces on a page are told apart).
  const name = host.getAttribute('aria-label') || 'Animated 3D face';
  const canvas = document.createElement('canvas');
  canvas.setAttribute('part', 'canvas');
  canvas.tabIndex = 0;
  canvas.setAttribute('role', 'application'); // the arrow keys are its own (camera-keys.ts), not a screen reader's
  canvas.setAttribute('aria-roledescription', '3D face viewer');
  canvas.setAttribute('aria-label', `${name}. ${CAMERA_KEYS_TEXT}.`);
  return canvas;
}

/**
 * The style, a canvas, the status line and, for screen readers, a polite live region that hears of changes of state
 * only (loading, ready, playing, stopped, errors): the status line's progress ("frame 96 of 480") would be spoken
 * at every chunk.
 */
export function shadowParts(host: HTMLElement): { canvas: HTMLCanvasElement; status: StatusLine } {
  const root = host.attachShadow({ mode: 'open' });
  // A group by default, so that a page may name the element (aria-label, which its canvas also takes).
  const internals = host.attachInternals?.();
  if (internals) internals.role = 'group';
  const canvas = newCanvas(host);
  const status = document.createElement('p');
  status.className = 'status';
  status.setAttribute('part', 'status');
  status.setAttribute('aria-hidden', 'true'); // the announcer says it once
  const announcer = document.createElement('span');
  // The element speaks English, left to right, whatever the page's language and direction (a screen reader's voice).
  for (const own of [status, announcer]) [own.lang, own.dir] = ['en', 'ltr'];
  announcer.className = 'announce';
  announcer.setAttribute('role', 'status');
  announcer.setAttribute('aria-live', 'polite');
  root.append(canvas, status, announcer);
  adoptStyle(root);
  return { canvas, status: new StatusLine(status, announcer) };
}

/** The status line, and the live region that says its changes of state to screen readers. */
export class StatusLine {
  constructor(private readonly line: HTMLParagraphElement, private readonly announcer: HTMLElement) {}

  /** Show `text`; `announce`: a change of state that screen readers hear too (not progress). */
  set(text: string, isError = false, announce = true): void {
    this.line.textContent = text;
    this.line.classList.toggle('error', isError);
    if (announce && this.announcer.textContent !== text) this.announcer.textContent = text;
  }
}

let sheet: CSSStyleSheet | null = null;

/**
 * The element's style as a constructed stylesheet, one for every instance: a page's Content-Security-Policy without
 * 'unsafe-inline' in style-src blocks a <style> element, not this. A <style> where the browser cannot construct one.
 */
function adoptStyle(root: ShadowRoot): void {
  if (typeof CSSStyleSheet !== 'undefined' && 'replaceSync' in CSSStyleSheet.prototype && 'adoptedStyleSheets' in root) {
    if (!sheet) {
      sheet = new CSSStyleSheet();
      sheet.replaceSync(STYLE);
    }
    root.adoptedStyleSheets = [sheet];
    return;
  }
  const style = document.createElement('style');
  style.textContent = STYLE;
  root.prepend(style);
}
