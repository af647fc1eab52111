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
 *
 * The project's own three.js goes beside it (vendorProjectThree), for examples/own-scene.html: vendor/three-project/;
 * and @pixiv/three-vrm (vendorThreeVrm, a devDependency), which that page loads for a .vrm avatar: vendor/three-vrm/.
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
  const modules = join(talkinghead, 'modules');
  for (const f of readdirSync(modules)) copied.push(copyInto(vendorDir, join(modules, f), join(vendorDir, 'talkinghead/modules', f)));
  copied.push(copyInto(vendorDir, join(talkinghead, 'LICENSE'), join(vendorDir, 'talkinghead/LICENSE')));
  // three's addons that TalkingHead's modules import, and theirs, transitively.
  const addons = readdirSync(modules).filter((f) => f.endsWith('.mjs')).flatMap((f) => importsOf(join(modules, f)));
  return [...copied, ...vendorThree(three, addons, vendorDir, 'three', 'TalkingHead')];
}

/**
 * The project's own three.js (the version the library is built and tested with, its peer dependency) into
 * `vendorDir`/three-project/, with the addons the library's sources import (static or dynamic): for
 * examples/own-scene.html, whose import map gives the package's build for bundlers (dist/lib/npm/) this three.js.
 */
export function vendorProjectThree(vendorDir: string, root: string): string[] {
  const three = dirname(dirname(createRequire(join(root, 'package.json')).resolve('three')));
  const addons: string[] = [];
  const walk = (dir: string) => {
    for (const e of readdirSync(dir, { withFileTypes: true })) {
      if (e.isDirectory()) walk(join(dir, e.name));
      else if (e.name.endsWith('.ts')) for (const m of readFileSync(join(dir, e.name), 'utf8').matchAll(/['"](three\/addons\/[^'"]+)['"]/g)) addons.push(m[1]);
    }
  };
  walk(join(root, 'src'));
  return vendorThree(three, addons, vendorDir, 'three-project', 'the library');
}

/** three.js's build and licence from the package folder `three`, and the addons among `imports` with theirs, transitively, into `vendorDir`/`folder`/. */
function vendorThree(three: string, imports: string[], vendorDir: string, folder: string, user: string): string[] {
  const copied = ['build/three.module.js', 'build/three.core.js', 'LICENSE'].map((f) => copyInto(vendorDir, join(three, f), join(vendorDir, folder, f)));
  const jsm = join(three, 'examples/jsm');
  const pending = imports.filter((s) => s.startsWith('three/addons/')).map((s) => join(jsm, s.slice('three/addons/'.length)));
  const seen = new Set<string>();
  while (pending.length) {
    const file = pending.pop()!;
    if (seen.has(file)) continue;
    seen.add(file);
    if (!existsSync(file)) throw new Error(`${user} imports ${relative(three, file)}, which three.js at ${three} does not have`);
    copied.push(copyInto(vendorDir, file, join(vendorDir, folder, 'examples/jsm', relative(jsm, file))));
    for (const s of importsOf(file)) {
      if (s.startsWith('.')) pending.push(resolve(dirname(file), s));
      else if (s.startsWith('three/addons/')) pending.push(join(jsm, s.slice('three/addons/'.length)));
      else if (s !== 'three') throw new Error(`${relative(three, file)} imports ${s}: the import map has no entry for it`);
    }
  }
  return copied;
}

/** Copy one file (its folder made); returns its path relative to `vendorDir`. */
function copyInto(vendorDir: string, from: string, to: string): string {
  mkdirSync(dirname(to), { recursive: true });
  cpSync(from, to, { preserveTimestamps: true });
  return relative(vendorDir, to);
}

/**
 * @pixiv/three-vrm's module build (one file; it imports only `three`, the page's) and its licence (MIT) into
 * `vendorDir`/three-vrm/: examples/own-scene.html loads it for a .vrm avatar through its import map.
 */
export function vendorThreeVrm(vendorDir: string, root: string): string[] {
  let manifest: string;
  try {
    manifest = createRequire(join(root, 'package.json')).resolve('@pixiv/three-vrm/package.json');
  } catch (e) {
    throw new Error(`examples/own-scene.html needs @pixiv/three-vrm (a devDependency) for .vrm avatars: run npm install (${(e as Error).message})`);
  }
  const from = dirname(manifest), module = join(from, 'lib/three-vrm.module.min.js');
  const foreign = importsOf(module).concat([...readFileSync(module, 'utf8').matchAll(/from"([^"]+)"/g)].map((m) => m[1])).filter((s) => s !== 'three');
  if (foreign.length) throw new Error(`${module} imports ${foreign.join(', ')}: the import map has no entry for it`);
  return [module, join(from, 'LICENSE')].map((f) => copyInto(vendorDir, f, join(vendorDir, 'three-vrm', f === module ? 'three-vrm.module.js' : 'LICENSE')));
}
