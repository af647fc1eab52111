/**
 * The library's entry (src/component/index.ts) imports where there is no DOM, as a framework rendering pages on its
 * server does: nothing is defined there, and the engine's API is all there.
 */
import { describe, expect, it } from 'vitest';

describe('the library entry without a DOM', () => {
  it('imports, defines nothing and exports the API', async () => {
    expect(typeof HTMLElement).toBe('undefined'); // Node: no DOM
    const lib = await import('../../../src/component/index');
    expect(typeof lib.TalkingFaceEngine.load).toBe('function');
    expect(typeof lib.decodeAudio).toBe('function');
    expect(typeof lib.TalkingFaceElement).toBe('function');
    expect(() => lib.defineTalkingFace('other-face')).not.toThrow();
    expect(lib.DEFAULT_CHUNK_FRAMES).toBeGreaterThan(0);
  });
});
