/**
 * CanvasWatch (src/render/canvas-size.ts): a change of the screen's pixel ratio (the page zoomed, the window moved to
 * another screen) resizes the view though its CSS size stays; a WebGL context given back asks for a frame; disconnect
 * leaves nothing listening. The browser's observers and media queries are stood in for (Node has none).
 */
import { afterEach, describe, expect, it, vi } from 'vitest';
import { CanvasWatch } from '../../../src/render/canvas-size';

class Query extends EventTarget {
  constructor(readonly media: string) { super(); }
}

function browser(): { queries: Query[]; observers: { disconnected: boolean }[]; setRatio: (r: number) => void } {
  const queries: Query[] = [];
  const observers: { disconnected: boolean }[] = [];
  class Observer {
    disconnected = false;
    constructor() { observers.push(this); }
    observe(): void {}
    disconnect(): void { this.disconnected = true; }
  }
  vi.stubGlobal('ResizeObserver', Observer);
  vi.stubGlobal('IntersectionObserver', Observer);
  vi.stubGlobal('devicePixelRatio', 1);
  vi.stubGlobal('matchMedia', (media: string) => {
    const q = new Query(media);
    queries.push(q);
    return q;
  });
  return {
    queries, observers,
    setRatio: (r) => {
      const before = queries.at(-1)!;
      vi.stubGlobal('devicePixelRatio', r);
      before.dispatchEvent(new Event('change'));
    },
  };
}

afterEach(() => vi.unstubAllGlobals());

describe('CanvasWatch', () => {
  it('resizes at each change of the pixel ratio, watching for the next one from the new ratio', () => {
    const b = browser();
    const resize = vi.fn();
    const watch = new CanvasWatch(new EventTarget() as HTMLCanvasElement, resize, () => undefined);
    expect(b.queries.map((q) => q.media)).toEqual(['(resolution: 1dppx)']);
    b.setRatio(2);
    expect(resize).toHaveBeenCalledTimes(1);
    b.setRatio(1.5);
    expect(resize).toHaveBeenCalledTimes(2);
    expect(b.queries.map((q) => q.media)).toEqual(['(resolution: 1dppx)', '(resolution: 2dppx)', '(resolution: 1.5dppx)']);
    b.queries[0].dispatchEvent(new Event('change')); // an old query no longer counts
    expect(resize).toHaveBeenCalledTimes(2);
    watch.disconnect();
    b.setRatio(3);
    expect(resize).toHaveBeenCalledTimes(2);
  });

  it('asks for a frame when a lost WebGL context is given back, and not once disconnected', () => {
    const b = browser();
    const canvas = new EventTarget() as HTMLCanvasElement;
    const redraw = vi.fn();
    const watch = new CanvasWatch(canvas, () => undefined, redraw);
    canvas.dispatchEvent(new Event('webglcontextrestored'));
    expect(redraw).toHaveBeenCalledTimes(1);
    watch.disconnect();
    canvas.dispatchEvent(new Event('webglcontextrestored'));
    expect(redraw).toHaveBeenCalledTimes(1);
    expect(b.observers.every((o) => o.disconnected)).toBe(true);
  });
});
