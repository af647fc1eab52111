import { defineConfig, defaultClientConditions, type Plugin } from 'vite';
import { createReadStream, existsSync, statSync, cpSync, readFileSync } from 'node:fs';
import { basename, resolve, normalize, sep, extname } from 'node:path';
import { ISOLATION_HEADERS, MIME, precompress, serveBuild } from './scripts/hosting.ts';
import { captureWorkletFile } from './scripts/worklet-file.ts';

/**
 * Cross-origin isolation (ISOLATION_HEADERS) lets onnxruntime-web use threads (SharedArrayBuffer).
 * An embedding page may not set these; the library then runs single-threaded.
 */
const MODELS_DIR = resolve(import.meta.dirname, 'models');
// onnxruntime-web's runtime (wasm + its Emscripten glue), served as plain files at /ort/<version>/ and loaded through
// ort.env.wasm.wasmPaths: its thread workers then import that glue, never a bundled chunk of the app. The version in
// the path lets browsers keep them for a year (scripts/hosting.ts). The plain WebAssembly build is what the encoders
// use on the wasm provider; the JSEP build (WebGPU-capable, twice the size) only where the WebGPU provider is used.
const ORT_DIST = resolve(import.meta.dirname, 'node_modules/onnxruntime-web/dist');
const ORT_VERSION = JSON.parse(readFileSync(resolve(ORT_DIST, '../package.json'), 'utf8')).version as string;
const ORT_FILES = ['ort-wasm-simd-threaded.mjs', 'ort-wasm-simd-threaded.wasm', 'ort-wasm-simd-threaded.jsep.mjs', 'ort-wasm-simd-threaded.jsep.wasm'];

/**
 * The demo's first load (issue 18): the files the page will fetch first, named in its HTML so that the browser asks
 * for them together with the app's script instead of one after another (manifest -> template header -> template
 * binary, and the model files only once the script has run). The list comes from models/manifest.json, the one
 * place that names them; each link matches the page's own fetch() (same origin, crossorigin), so nothing is
 * fetched twice.
 */
function modelPreloads(): { tag: string; attrs: Record<string, string | boolean>; injectTo: 'head' }[] {
  const manifest = JSON.parse(readFileSync(resolve(MODELS_DIR, 'manifest.json'), 'utf8')) as {
    files: Record<string, string>; runtime_files: string[]; template: { path: string };
  };
  const template = JSON.parse(readFileSync(resolve(MODELS_DIR, manifest.template.path), 'utf8')) as { binary: string };
  const templateDir = manifest.template.path.replace(/[^/]*$/, '');
  const paths = ['manifest.json', manifest.template.path, templateDir + template.binary, ...manifest.runtime_files.map((k) => manifest.files[k])];
  return paths.map((p) => ({ tag: 'link', attrs: { rel: 'preload', href: `/models/${p}`, as: 'fetch', crossorigin: true }, injectTo: 'head' }));
}

/**
 * Serve models/ at /models/ and onnxruntime-web's files at /ort/<version>/ in dev, copy both into the build, and
 * serve the build in preview as a static host should (scripts/hosting.ts: precompressed files, cache headers).
 */
function modelsDir(): Plugin {
  const devMiddleware = (req: { url?: string }, res: import('node:http').ServerResponse, next: () => void) => {
    const url = decodeURIComponent((req.url ?? '').split('?')[0]);
    const ortPrefix = `/ort/${ORT_VERSION}/`;
    let file: string;
    if (url.startsWith('/models/')) {
      file = normalize(resolve(MODELS_DIR, '.' + url.slice('/models'.length)));
      if (!file.startsWith(MODELS_DIR + sep)) file = '';
    } else if (url.startsWith(ortPrefix) && ORT_FILES.includes(url.slice(ortPrefix.length))) {
      file = resolve(ORT_DIST, url.slice(ortPrefix.length));
    } else return next();
    if (!file || !existsSync(file) || !statSync(file).isFile()) {
      res.statusCode = 404;
      res.end(`not found: ${url}`);
      return;
    }
    res.setHeader('Content-Type', MIME[extname(file)] ?? 'application/octet-stream');
    for (const [k, v] of Object.entries(ISOLATION_HEADERS)) res.setHeader(k, v);
    createReadStream(file).pipe(res);
  };
  let outDir = 'dist';
  return {
    name: 'talking-face-models',
    configResolved(config) {
      outDir = resolve(config.root, config.build.outDir);
    },
    configureServer(server) {
      server.middlewares.use(devMiddleware);
    },
    configurePreviewServer(server) {
      server.middlewares.use(serveBuild(outDir));
    },
    transformIndexHtml: { order: 'post', handler: (_html, ctx) => (ctx.path === '/index.html' ? modelPreloads() : []) },
    closeBundle() {
      // (not an export's staging folder, .export-*, that a killed export left behind)
      cpSync(MODELS_DIR, resolve(outDir, 'models'), { recursive: true, preserveTimestamps: true, filter: (from) => !basename(from).startsWith('.export-') });
      for (const f of ORT_FILES) cpSync(resolve(ORT_DIST, f), resolve(outDir, 'ort', ORT_VERSION, f), { preserveTimestamps: true });
      precompress(outDir);
    },
  };
}

/**
 * `vite build` builds the app (index.html) into dist/. `vite build --mode test` (npm run build:test, after it) adds
 * the test-only pages under dist/dev/ (parity, bench, live, long, environment, ort-start): the tests and `npm run bench` use them; the
 * shipped app does not carry them.
 */
export default defineConfig(({ mode }) => {
  const testPages = mode === 'test';
  const page = (name: string) => resolve(import.meta.dirname, name);
  return {
    plugins: [modelsDir(), captureWorkletFile()],
    server: { headers: ISOLATION_HEADERS, port: 5173, strictPort: false },
    preview: { headers: ISOLATION_HEADERS, port: 4173, strictPort: false },
    build: {
      target: 'es2022',
      sourcemap: true,
      chunkSizeWarningLimit: 1024,
      emptyOutDir: !testPages,
      rolldownOptions: {
        input: (testPages
          ? { parity: page('dev/parity.html'), bench: page('dev/bench.html'), live: page('dev/live.html'), long: page('dev/long.html'), environment: page('dev/environment.html'),
            ortStart: page('dev/ort-start.html') }
          : { main: page('index.html') }) as Record<string, string>,
      },
    },
    optimizeDeps: { exclude: ['onnxruntime-web'] },
    // The "extern wasm" build of onnxruntime-web (see ORT_FILES above) instead of the one with the wasm glue inlined:
    // inlined, its thread workers import the bundle's chunk, which here imports a page entry ("document is not defined").
    resolve: { conditions: ['onnxruntime-web-use-extern-wasm', ...defaultClientConditions] },
  };
});
