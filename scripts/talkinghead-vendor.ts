/**
 * TalkingHead (@met4citizen/talkinghead, a devDependency) for examples/talkinghead.html: its modules and the
 * three.js it depends on, copied into dist/examples/vendor/ by the library build (vite.lib.config.ts), so the page
 * loads them from its own origin through an import map (three, three/addons/, @met4citizen/talkinghead), the way
 * TalkingHead's README loads them from a CDN. The three.js is TalkingHead's own as npm resolves it (1.7.0 asks for
 * ^0.180.0, so npm nests 0.180 under it; this project's 0.187 stays inside the library's bundle). Of three's
 * addons, only those TalkingHead imports and what they import are copied. Both licences (MIT) go along.
 *
 *   vendor/talkinghead/modules/talkinghead.mjs, dynamicbones.mjs, lipsync-*.mjs, playback-worklet.js, LICENSE
 *   vendor/three/build/three.module.js, three.core.js, LICENSE
 *   vendor/three/examples/jsm/loaders/GLTFLoader.js, ... (the addons' own layout: they import each other relatively)
 */
import { cpSync, existsSync, mkdirSync, readFileSync, readdirSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join, relative, resolve } from 'node:path';

/** The package folders of TalkingHead and of the three.js it resolves. */
export function talkingHeadPackages(): { talkinghead: string; three: string } {
  const require = createRequire(import.meta.url);
  let manifest: string;
  try {
    manifest = require.resolve('@met4citizen/talkinghead/package.json');
  } catch (e) {
    throw new Error(`examples/talkinghead.html needs @met4citizen/talkinghead (a devDependency): run npm install (${(e as Error).message})`);
  }
  const talkinghead = dirname(manifest);
  // three's exports name no package.json: its CommonJS entry is build/three.cjs.
  const three = dirname(dirname(createRequire(manifest).resolve('three')));
  return { talkinghead, three };
}

/**
 * Specifiers of a module's static imports and re-exports (statements that start a line: `import ... from '...'`,
 * `export ... from '...'`, `import '...'`; not the examples in its comments).
 */
function importsOf(file: string): string[] {
  const source = readFileSync(file, 'utf8');
  const out: string[] = [];
  for (const m of source.matchAll(/^\s*(?:import|export)\b[^;'"]*?\bfrom\s*['"]([^'"]+)['"]|^\s*import\s*['"]([^'"]+)['"]/gm)) out.push(m[1] ?? m[2]);
  return out;
}

/** Copy TalkingHead and its three.js into `vendorDir` (created); returns the files copied, relative to it. */
export function vendorTalkingHead(vendorDir: string): string[] {
  const { talkinghead, three } = talkingHeadPackages();
  const copied: string[] = [];
  const copy = (from: string, to: string) => {
    mkdirSync(dirname(to), { recursive: true });
    cpSync(from, to, { preserveTimestamps: true });
    copied.push(relative(vendorDir, to));
  };
  const modules = join(talkinghead, 'modules');
  for (const f of readdirSync(modules)) copy(join(modules, f), join(vendorDir, 'talkinghead/modules', f));
  copy(join(talkinghead, 'LICENSE'), join(vendorDir, 'talkinghead/LICENSE'));
  for (const f of ['build/three.module.js', 'build/three.core.js', 'LICENSE']) copy(join(three, f), join(vendorDir, 'three', f));

  // three's addons that TalkingHead's modules import, and theirs, transitively.
  const jsm = join(three, 'examples/jsm');
  const pending = readdirSync(modules).filter((f) => f.endsWith('.mjs')).flatMap((f) => importsOf(join(modules, f)))
    .filter((s) => s.startsWith('three/addons/')).map((s) => join(jsm, s.slice('three/addons/'.length)));
  const seen = new Set<string>();
  while (pending.length) {
    const file = pending.pop()!;
    if (seen.has(file)) continue;
    seen.add(file);
    if (!existsSync(file)) throw new Error(`TalkingHead imports ${relative(three, file)}, which three.js at ${three} does not have`);
    copy(file, join(vendorDir, 'three/examples/jsm', relative(jsm, file)));
    for (const s of importsOf(file)) {
      if (s.startsWith('.')) pending.push(resolve(dirname(file), s));
      else if (s.startsWith('three/addons/')) pending.push(join(jsm, s.slice('three/addons/'.length)));
      else if (s !== 'three') throw new Error(`${relative(three, file)} imports ${s}: the import map has no entry for it`);
    }
  }
  return copied;
}
