import { defineConfig, defaultClientConditions, type Plugin } from 'vite';
import { createReadStream, existsSync, statSync, cpSync } from 'node:fs';
import { resolve, normalize, sep, extname } from 'node:path';

/**
 * Cross-origin isolation lets onnxruntime-web use threads (SharedArrayBuffer).
 * An embedding page may not set these; the library then runs single-threaded.
 */
const isolationHeaders = {
  'Cross-Origin-Opener-Policy': 'same-origin',
  'Cross-Origin-Embedder-Policy': 'require-corp',
};

const MODELS_DIR = resolve(import.meta.dirname, 'models');
// onnxruntime-web's runtime (wasm + its Emscripten glue), served as plain files at /ort/ and loaded through
// ort.env.wasm.wasmPaths: its thread workers then import that glue, never a bundled chunk of the app.
const ORT_DIST = resolve(import.meta.dirname, 'node_modules/onnxruntime-web/dist');
const ORT_FILES = ['ort-wasm-simd-threaded.jsep.mjs', 'ort-wasm-simd-threaded.jsep.wasm', 'ort-wasm-simd-threaded.mjs', 'ort-wasm-simd-threaded.wasm'];
const MIME: Record<string, string> = {
  '.json': 'application/json',
  '.onnx': 'application/octet-stream',
  '.bin': 'application/octet-stream',
  '.safetensors': 'application/octet-stream',
  '.mjs': 'text/javascript',
  '.wasm': 'application/wasm',
};

/** Serve models/ at /models/ in dev and preview, and copy it into the build: the exported artefacts live in one place. */
function modelsDir(): Plugin {
  const middleware = (req: { url?: string }, res: import('node:http').ServerResponse, next: () => void) => {
    const url = decodeURIComponent((req.url ?? '').split('?')[0]);
    let file: string;
    if (url.startsWith('/models/')) {
      file = normalize(resolve(MODELS_DIR, '.' + url.slice('/models'.length)));
      if (!file.startsWith(MODELS_DIR + sep)) file = '';
    } else if (url.startsWith('/ort/') && ORT_FILES.includes(url.slice('/ort/'.length))) {
      file = resolve(ORT_DIST, url.slice('/ort/'.length));
    } else return next();
    if (!file || !existsSync(file) || !statSync(file).isFile()) {
      res.statusCode = 404;
      res.end(`not found: ${url}`);
      return;
    }
    res.setHeader('Content-Type', MIME[extname(file)] ?? 'application/octet-stream');
    for (const [k, v] of Object.entries(isolationHeaders)) res.setHeader(k, v);
    createReadStream(file).pipe(res);
  };
  let outDir = 'dist';
  return {
    name: 'talking-face-models',
    configResolved(config) {
      outDir = resolve(config.root, config.build.outDir);
    },
    configureServer(server) {
      server.middlewares.use(middleware);
    },
    configurePreviewServer(server) {
      server.middlewares.use(middleware);
    },
    closeBundle() {
      cpSync(MODELS_DIR, resolve(outDir, 'models'), { recursive: true });
      for (const f of ORT_FILES) cpSync(resolve(ORT_DIST, f), resolve(outDir, 'ort', f));
    },
  };
}

/**
 * `vite build` builds the app (index.html) into dist/. `vite build --mode test` (npm run build:test, after it) adds
 * the test-only pages under dist/dev/ (parity, bench, live, long): the tests and `npm run bench` use them; the
 * shipped app does not carry them.
 */
export default defineConfig(({ mode }) => {
  const testPages = mode === 'test';
  const page = (name: string) => resolve(import.meta.dirname, name);
  return {
    plugins: [modelsDir()],
    server: { headers: isolationHeaders, port: 5173, strictPort: false },
    preview: { headers: isolationHeaders, port: 4173, strictPort: false },
    build: {
      target: 'es2022',
      sourcemap: true,
      chunkSizeWarningLimit: 1024,
      emptyOutDir: !testPages,
      rolldownOptions: {
        input: (testPages
          ? { parity: page('dev/parity.html'), bench: page('dev/bench.html'), live: page('dev/live.html'), long: page('dev/long.html') }
          : { main: page('index.html') }) as Record<string, string>,
      },
    },
    optimizeDeps: { exclude: ['onnxruntime-web'] },
    // The "extern wasm" build of onnxruntime-web (see ORT_FILES above) instead of the one with the wasm glue inlined:
    // inlined, its thread workers import the bundle's chunk, which here imports a page entry ("document is not defined").
    resolve: { conditions: ['onnxruntime-web-use-extern-wasm', ...defaultClientConditions] },
  };
});
