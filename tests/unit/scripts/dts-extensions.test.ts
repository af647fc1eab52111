/** The declarations' relative imports name their files (scripts/dts-extensions.ts), for node16 / nodenext projects. */
import { describe, expect, it } from 'vitest';
import { withExtensions } from '../../../scripts/dts-extensions';

describe('withExtensions', () => {
  const files = new Set(['/t/engine/engine.d.ts', '/t/index.d.ts', '/t/component/index.d.ts', '/t/audio/decode.d.ts']);
  const exists = (p: string) => files.has(p);
  it('adds .js to a file and /index.js to a folder, in imports, exports, import types and module augmentations', () => {
    const src = [
      "import { A } from '../engine/engine';",
      "export * from '../index';",
      "export { B } from './index';",
      "type C = import('../audio/decode').DecodedAudio;",
      "import type * as T from 'three';",
      "import './already.js';",
      "export { D } from '../component';",
      "declare module './index' {",
    ].join('\n');
    expect(withExtensions(src, '/t/component', exists)).toBe([
      "import { A } from '../engine/engine.js';",
      "export * from '../index.js';",
      "export { B } from './index.js';",
      "type C = import('../audio/decode.js').DecodedAudio;",
      "import type * as T from 'three';",
      "import './already.js';",
      "export { D } from '../component/index.js';",
      "declare module './index.js' {",
    ].join('\n'));
  });
});
