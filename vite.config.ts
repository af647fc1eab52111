import { defineConfig, type Plugin } from 'vite';
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
const MIME: Record<string, string> = {
  '.json': 'application/json',
  '.onnx': 'application/octet-stream',
  '.bin': 'application/octet-stream',
  '.safetensors': 'application/octet-stream',
};

/** Serve models/ at /models/ in dev and preview, and copy it into the build: the exported artefacts live in one place. */
function modelsDir(): Plugin {
  const middleware = (req: { url?: string }, res: import('node:http').ServerResponse, next: () => void) => {
    const url = decodeURIComponent((req.url ?? '').split('?')[0]);
    if (!url.startsWith('/models/')) return next();
    const file = normalize(resolve(MODELS_DIR, '.' + url.slice('/models'.length)));
    if (!file.startsWith(MODELS_DIR + sep) || !existsSync(file) || !statSync(file).isFile()) {
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
    },
  };
}

export default defineConfig({
  plugins: [modelsDir()],
  server: { headers: isolationHeaders, port: 5173, strictPort: false },
  preview: { headers: isolationHeaders, port: 4173, strictPort: false },
  build: { target: 'es2022', sourcemap: true, chunkSizeWarningLimit: 1024 },
  optimizeDeps: { exclude: ['onnxruntime-web'] },
});
