/**
 * The library's declarations (dist/lib/types, emitted by tsc for a bundler's resolution) made usable under
 * `moduleResolution: node16 / nodenext` too: every relative import, export and module augmentation in them names its file, `./x.js` for
 * x.d.ts, `./x/index.js` for a folder. Without it such a project saw none of the library's exports (TS2834, TS2305).
 *
 *   tsx scripts/dts-extensions.ts dist/lib/types        (npm run build runs it)
 */
import { existsSync, readdirSync, readFileSync, statSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

/** `source` (a .d.ts in `dir`) with each relative module specifier naming its file, as `exists` finds them. */
export function withExtensions(source: string, dir: string, exists: (path: string) => boolean = existsSync): string {
  return source.replace(/(\bfrom\s*|\bimport\s*\(\s*|\bimport\s+|\bdeclare\s+module\s+)(['"])(\.{1,2}\/[^'"]*)\2/g, (all, lead: string, q: string, spec: string) => {
    if (/\.(m?js|json)$/.test(spec)) return all;
    const target = resolve(dir, spec);
    if (exists(`${target}.d.ts`)) return `${lead}${q}${spec}.js${q}`;
    if (exists(join(target, 'index.d.ts'))) return `${lead}${q}${spec}/index.js${q}`;
    return all;
  });
}

function* declarations(dir: string): Generator<string> {
  for (const name of readdirSync(dir)) {
    const path = join(dir, name);
    if (statSync(path).isDirectory()) yield* declarations(path);
    else if (name.endsWith('.d.ts')) yield path;
  }
}

if (process.argv[1] && fileURLToPath(import.meta.url) === resolve(process.argv[1])) {
  const root = process.argv[2];
  if (!root || !existsSync(root)) {
    console.error('usage: tsx scripts/dts-extensions.ts DIR   (the declarations tsc wrote, e.g. dist/lib/types)');
    process.exit(2);
  }
  let changed = 0;
  for (const file of declarations(resolve(root))) {
    const before = readFileSync(file, 'utf8');
    const after = withExtensions(before, dirname(file));
    if (after !== before) [changed] = [changed + 1, writeFileSync(file, after)];
  }
  console.log(`dts-extensions: ${changed} declaration files now name their imports' files`);
}
