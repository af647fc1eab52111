/**
 * The capture's AudioWorklet as a file beside the code that loads it (src/audio/capture.ts: new URL(WORKLET_FILE,
 * import.meta.url)), in both builds: the same-origin script a strict Content-Security-Policy lets in, where it refuses
 * the blob: URL the capture tries first. (Vite would inline it as a data: URL, which such a policy refuses too, and
 * always does in a library build.)
 */
import { readFileSync } from 'node:fs';
import { posix, resolve } from 'node:path';
import type { Plugin } from 'vite';

/** The name capture.ts gives it (WORKLET_FILE there: src/ cannot import the build's scripts, nor they its ?raw import). */
const WORKLET_FILE = 'capture-worklet.js';

export function captureWorkletFile(): Plugin {
  return {
    name: 'talking-face-capture-worklet',
    generateBundle(_, bundle) {
      const source = readFileSync(resolve(import.meta.dirname, '../src/audio', WORKLET_FILE), 'utf8');
      const beside = new Set<string>();
      for (const chunk of Object.values(bundle)) {
        if (chunk.type === 'chunk' && chunk.code.includes(WORKLET_FILE)) beside.add(posix.join(posix.dirname(chunk.fileName), WORKLET_FILE));
      }
      for (const fileName of beside) this.emitFile({ type: 'asset', fileName, source });
    },
  };
}
