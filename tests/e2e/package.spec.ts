import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { test, expect } from '@playwright/test';

/**
 * The package as another project installs it (package.json `files` and `exports`, vite.lib.config.ts `--mode npm`,
 * scripts/dts-extensions.ts), on the build the suite serves: what `npm pack` puts in it, an import where there is no
 * DOM, three.js left to the project, and the declarations under node16 resolution. The package imports itself by
 * name from inside its folder (Node's self-reference through `exports`), as a project that installed it would.
 */
const ROOT = resolve(import.meta.dirname, '../..');
const run = (cmd: string, args: string[], cwd = ROOT) => execFileSync(cmd, args, { cwd, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

test('npm pack holds the library, its declarations, the runtime and the model, and no training files', () => {
  test.setTimeout(120_000);
  const [pack] = JSON.parse(run('npm', ['pack', '--dry-run', '--json', '--ignore-scripts'])) as { files: { path: string }[] }[];
  const files = new Set(pack.files.map((f) => f.path));
  const exported = JSON.parse(readFileSync(join(ROOT, 'package.json'), 'utf8')).exports as Record<string, Record<string, string>>;
  for (const entry of Object.values(exported)) for (const target of Object.values(entry)) expect(files, target).toContain(target.replace(/^\.\//, ''));
  const manifest = JSON.parse(readFileSync(join(ROOT, 'dist/models/manifest.json'), 'utf8')) as { files: Record<string, string>; runtime_files: string[] };
  for (const key of manifest.runtime_files) expect(files, manifest.files[key]).toContain(`dist/models/${manifest.files[key]}`);
  expect([...files].some((f) => f.startsWith('dist/ort/') && f.endsWith('ort-wasm-simd-threaded.wasm'))).toBe(true);
  expect([...files].filter((f) => /checkpoint\.pt|fixtures|samples\/|^training\/|^tests\/|^src\//.test(f))).toEqual([]);
  // Nor the precompressed copies the build writes for hosting it (.br, .gz: 24 MB): a project's own host compresses.
  expect([...files].filter((f) => /\.(br|gz)$/.test(f))).toEqual([]);
});

test('imports where there is no DOM, with three.js its importer\'s', () => {
  const out = run('node', ['--input-type=module', '-e',
    "const m = await import('talking-face'); console.log([typeof m.TalkingFaceEngine.load, typeof m.setRuntimeBase, String(globalThis.customElements === undefined), m.TalkingFaceElement.name].join(' '))"]);
  // (the class keeps its name, not minified away, for errors and devtools: the project's bundler minifies)
  expect(out.trim()).toBe('function function true TalkingFaceElement');
  const code = readFileSync(join(ROOT, 'dist/lib/npm/talking-face.js'), 'utf8');
  expect(code).toMatch(/from\s*"three"/);
  expect(code).not.toContain('__THREE__'); // three.js's own code, which the standalone build carries
});

test('needs nothing installed beside it but its peers: its code and its declarations import only three.js (and React\'s, Vue\'s and Svelte\'s types, opt-in)', () => {
  const pkg = JSON.parse(readFileSync(join(ROOT, 'package.json'), 'utf8')) as { dependencies?: object; peerDependencies: object; exports: Record<string, Record<string, string>> };
  expect(pkg.dependencies ?? {}, 'dependencies (onnxruntime-web is bundled into the code, its runtime into dist/ort)').toEqual({});
  // A peer's specifier, or its types' (@types/react is what 'react' names in the declarations of talking-face/jsx).
  const peers = Object.keys(pkg.peerDependencies).map((p) => p.replace(/^@types\//, ''));
  const peer = (specifier: string) => peers.some((p) => specifier === p || specifier.startsWith(`${p}/`));
  // Every file reachable from an export, through relative imports; the bare ones it names.
  const bare = new Map<string, string>(), visited = new Set<string>();
  for (const entry of Object.values(pkg.exports)) {
    for (const start of Object.values(entry)) {
      const pending = [resolve(ROOT, start)], seen = new Set<string>();
      while (pending.length) {
        const file = pending.pop()!;
        if (seen.has(file)) continue;
        seen.add(file);
        visited.add(file.slice(ROOT.length + 1));
        // A statement's `import ... from "x"` / `export ... from "x"` / `import "x"`, and `import("x")`: what a module imports.
        const imports = /^\s*(?:import|export)\b[^;"']*?\bfrom\s*["']([^"'\s]+)["']|^\s*import\s*["']([^"'\s]+)["']|\bimport\s*\(\s*["']([^"'\s]+)["']/gm;
        for (const m of readFileSync(file, 'utf8').matchAll(imports)) {
          const s = m[1] ?? m[2] ?? m[3];
          if (!s.startsWith('.')) bare.set(s, file.slice(ROOT.length + 1));
          else if (s.endsWith('.js') || s.endsWith('.d.ts')) pending.push(s.endsWith('.js') && file.endsWith('.d.ts') ? resolve(dirname(file), s.replace(/\.js$/, '.d.ts')) : resolve(dirname(file), s));
        }
      }
    }
  }
  expect([...bare].filter(([s]) => !peer(s)).map(([s, f]) => `${s} (${f})`)).toEqual([]);
  expect([...bare.keys()]).toContain('three');
  // The walk went deep: the encoders' declarations, which named onnxruntime-web's types before.
  expect([...visited]).toContain('dist/lib/types/encoders/onnx-model.d.ts');
});

test('talking-face/engine is the library without the element and without the face\'s renderer', () => {
  const out = run('node', ['--input-type=module', '-e', [
    "const m = await import('talking-face/engine');",
    "console.log([typeof m.TalkingFaceEngine.load, typeof m.AvatarDriver, typeof m.GltfAvatar.bind, String('TalkingFaceElement' in m), String('defineTalkingFace' in m)].join(' '))",
  ].join(' ')]);
  expect(out.trim()).toBe('function function function false false');
  // What importing it loads: engine.js and the chunks it imports, none of them holding the element (its definition,
  // its attributes) or the views that draw (their camera controls, the head's teeth): names a minifier keeps.
  const dir = join(ROOT, 'dist/lib/npm');
  const loaded = new Set<string>(), pending = ['engine.js'];
  while (pending.length) {
    const file = pending.pop()!;
    if (loaded.has(file)) continue;
    loaded.add(file);
    for (const m of readFileSync(join(dir, file), 'utf8').matchAll(/(?:from|import)\s*"\.\/([^"]+\.js)"/g)) pending.push(m[1]);
  }
  expect(loaded.has('talking-face.js'), [...loaded].join(', ')).toBe(false);
  for (const file of loaded) {
    const code = readFileSync(join(dir, file), 'utf8');
    expect(code, file).not.toMatch(/customElements\.define|observedAttributes|OrbitControls|RoundedBoxGeometry/);
  }
});

/** Type-check `files` (name -> source) as a project with these compiler options; tsc's output ('' when none). */
function typecheck(files: Record<string, string>, options: object): string {
  const dir = mkdtempSync(join(ROOT, 'dist/consumer-'));
  try {
    for (const [name, source] of Object.entries(files)) writeFileSync(join(dir, name), source);
    writeFileSync(join(dir, 'tsconfig.json'), JSON.stringify({ compilerOptions: { strict: true, noEmit: true, ...options }, files: Object.keys(files) }));
    try {
      run(join(ROOT, 'node_modules/.bin/tsc'), ['-p', dir]);
      return '';
    } catch (e) {
      return String((e as { stdout?: string }).stdout ?? e);
    }
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

test('talking-face/jsx types the element in React\'s JSX: its attributes, and a ref as TalkingFaceElement', () => {
  test.setTimeout(120_000);
  const use = [
    "import type {} from 'talking-face/jsx';",
    "import type { TalkingFaceElement } from 'talking-face';",
    "import { useRef } from 'react';",
    'export function Face() {',
    '  const ref = useRef<TalkingFaceElement>(null);',
    '  return (<>',
    '    <talking-face ref={ref} src="/hello.wav" autoplay backend="cpu" head-motion={1.5} avatar="/me.glb" avatar-head-bone="Head" hide-status className="face"',
    '      onframe={(e) => { const n: number = e.detail.frame; console.log(n); }} onerror={(e) => console.log(e.detail.stage)} onended={() => undefined} />',
    '    {/* @ts-expect-error: React\'s onError is for media and images: never called on this element */}',
    '    <talking-face onError={() => undefined} />',
    '    {/* @ts-expect-error: not one of its backends */}',
    '    <talking-face backend="gpu" />',
    '    {/* @ts-expect-error: no such attribute */}',
    '    <talking-face srcc="/hello.wav" />',
    '  </>);',
    '}',
    'export const stop = (face: TalkingFaceElement | null) => face?.stop();',
  ].join('\n');
  const options = { target: 'es2022', module: 'esnext', moduleResolution: 'bundler', jsx: 'react-jsx', lib: ['es2022', 'dom'], types: [] };
  expect(typecheck({ 'use.tsx': use }, options)).toBe('');
  // A plain import (not import type) types the same, and resolves to a module that holds nothing.
  expect(typecheck({ 'use.tsx': use.replace("import type {} from 'talking-face/jsx';", "import 'talking-face/jsx';") }, options)).toBe('');
  expect(run('node', ['--input-type=module', '-e', "console.log(String(Object.keys(await import('talking-face/jsx')).length))"]).trim()).toBe('0');
  // Without the opt-in, React's JSX does not know the element.
  expect(typecheck({ 'use.tsx': use.replace("import type {} from 'talking-face/jsx';", '') }, options)).toMatch(/Property 'talking-face' does not exist on type 'JSX\.IntrinsicElements'/);
});

test('talking-face/vue and talking-face/svelte type the element\'s attributes and events for Vue and Svelte 5', () => {
  test.setTimeout(120_000);
  const options = { target: 'es2022', module: 'esnext', moduleResolution: 'bundler', lib: ['es2022', 'dom', 'dom.iterable'], types: [] };
  // Vue: what vue-tsc checks a template's <talking-face> against (GlobalComponents; `@frame` is the prop onFrame, and
  // `:hide-status` the prop hideStatus).
  const vue = [
    "import type {} from 'talking-face/vue';",
    "import type { GlobalComponents } from 'vue';",
    "type Props = InstanceType<GlobalComponents['talking-face']>['$props'];",
    "export const ok: Props = { src: null, backend: 'cpu', autoplay: false, avatar: '/me.vrm', headMotion: 1.5, hideStatus: true, avatarFacing: '-z',",
    "  onFrame: (e) => { const n: number = e.detail.frame; console.log(n); }, onError: (e) => console.log(e.detail.stage), onEnded: () => undefined };",
    '// @ts-expect-error: not one of its backends',
    "export const bad: Props = { backend: 'gpu' };",
    '// @ts-expect-error: the ready detail has no such field',
    'export const wrong: Props = { onReady: (e) => e.detail.nonexistent };',
    "// @ts-expect-error: vue-tsc reads a template's head-motion as headMotion",
    "export const kebab: Props = { 'head-motion': 1 };",
  ].join('\n');
  expect(typecheck({ 'use.ts': vue }, options)).toBe('');
  expect(typecheck({ 'use.ts': vue.replace("import type {} from 'talking-face/vue';", '') }, options)).toMatch(/Property 'talking-face' does not exist on type 'GlobalComponents'/);
  // Svelte 5: its elements' attributes (`onframe={...}` is an event attribute; `bind:this` gets TalkingFaceElement).
  const svelte = [
    "import type {} from 'talking-face/svelte';",
    "import type { SvelteHTMLElements } from 'svelte/elements';",
    "type Attributes = SvelteHTMLElements['talking-face'];",
    "export const ok: Attributes = { src: null, backend: 'cpu', 'hide-status': true, 'avatar-facing': '-z', class: 'face',",
    "  onframe: (e) => { const n: number = e.detail.frame; console.log(n); }, onerror: (e) => console.log(e.detail.stage) };",
    '// @ts-expect-error: not one of its backends',
    "export const bad: Attributes = { backend: 'gpu' };",
  ].join('\n');
  expect(typecheck({ 'use.ts': svelte }, options)).toBe('');
  // Without the opt-in, Svelte takes any attribute on an element it does not know: the expected error is missing.
  expect(typecheck({ 'use.ts': svelte.replace("import type {} from 'talking-face/svelte';", '') }, options)).toMatch(/Unused '@ts-expect-error' directive/);
  for (const entry of ['vue', 'svelte']) {
    expect(run('node', ['--input-type=module', '-e', `console.log(String(Object.keys(await import('talking-face/${entry}')).length))`]).trim(), entry).toBe('0');
  }
});

test('its declarations type a project that resolves modules as Node does (node16)', () => {
  test.setTimeout(120_000);
  const use = [
    "import 'talking-face';",
    "import { TalkingFaceEngine, setRuntimeBase, type TalkingFaceElement } from 'talking-face';",
    "import { AvatarDriver, type DrivenFrames } from 'talking-face/engine';",
    "export const show = (d: AvatarDriver, f: DrivenFrames): void => d.show(f, 0);",
    "setRuntimeBase('/ort/');",
    "const face = document.createElement('talking-face') as TalkingFaceElement;",
    "face.addEventListener('frame', (e) => { const n: number = e.detail.frame; console.log(n); });",
    "export const load: typeof TalkingFaceEngine.load = TalkingFaceEngine.load;",
  ].join('\n');
  expect(typecheck({ 'use.ts': use }, { target: 'es2022', module: 'node16', moduleResolution: 'node16', lib: ['es2022', 'dom', 'dom.iterable'], types: [] })).toBe('');
});
