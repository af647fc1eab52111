/** The library build's entry (dist/lib/talking-face.js): defines <talking-face> and exports the library API. */
import { TalkingFaceElement } from './talking-face';
import type { TalkingFaceEventMap } from './events';

export * from '../index';
export { TalkingFaceElement, DEFAULT_MODEL, type ReadyDetail, type FrameDetail, type TalkingFaceErrorDetail } from './talking-face';
export { TalkingFaceError, type TalkingFaceEventMap } from './events';

/** Define the element under `name` (importing the library defines `talking-face`); nothing where there is no DOM. */
export function defineTalkingFace(name = 'talking-face'): void {
  if (typeof customElements === 'undefined') return; // a server rendering the page: the browser defines it
  if (!customElements.get(name)) customElements.define(name, name === 'talking-face' ? TalkingFaceElement : class extends TalkingFaceElement {});
}

// Typed listeners for the element's own events: `e.detail` is the event's detail (an `error` is its CustomEvent).
declare module './talking-face' {
  interface TalkingFaceElement {
    addEventListener<K extends keyof TalkingFaceEventMap>(type: K, listener: (this: TalkingFaceElement, ev: TalkingFaceEventMap[K]) => unknown, options?: boolean | AddEventListenerOptions): void;
    addEventListener(type: string, listener: EventListenerOrEventListenerObject, options?: boolean | AddEventListenerOptions): void;
    removeEventListener<K extends keyof TalkingFaceEventMap>(type: K, listener: (this: TalkingFaceElement, ev: TalkingFaceEventMap[K]) => unknown, options?: boolean | EventListenerOptions): void;
    removeEventListener(type: string, listener: EventListenerOrEventListenerObject, options?: boolean | EventListenerOptions): void;
  }
}

declare global {
  interface HTMLElementTagNameMap {
    'talking-face': TalkingFaceElement;
  }
}

defineTalkingFace();
