/** Where onnxruntime's files are looked for (src/encoders/ort-worker-client.ts): always a folder. */
import { describe, expect, it } from 'vitest';
import { folderUrl, ortRoot, setRuntimeBase } from '../../../src/encoders/ort-worker-client';

describe('folderUrl', () => {
  it('keeps a folder a folder, also where a bundler dropped its slash', () => {
    expect(folderUrl('../ort/', 'https://example.org/site/lib/talking-face.js')).toBe('https://example.org/site/ort/');
    // A consumer's Vite dev server rewrites new URL('../ort/', import.meta.url) to this, without the slash.
    expect(folderUrl('/node_modules/talking-face/dist/ort', 'http://127.0.0.1:5173/node_modules/.vite/deps/talking-face.js'))
      .toBe('http://127.0.0.1:5173/node_modules/talking-face/dist/ort/');
  });
});

describe('setRuntimeBase', () => {
  it('moves where the runtime is looked for, and back', () => {
    const before = ortRoot();
    setRuntimeBase('https://cdn.example.org/talking-face/ort');
    expect(ortRoot()).toBe('https://cdn.example.org/talking-face/ort/');
    setRuntimeBase(null);
    expect(ortRoot()).toBe(before);
  });
});
