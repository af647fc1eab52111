/**
 * How the build is served (issue 18): which files may be cached for how long, precompressed copies of what a
 * browser downloads, and the preview server's static middleware that serves both. docs/embedding.md gives the
 * same rules for a static host to copy.
 *
 *   hashed names (Vite's [name]-[hash].js under assets/ and lib/) and ort/<version>/   cached for a year, immutable
 *   everything else (HTML, lib/talking-face.js, models/)                              revalidated (no-cache + ETag)
 */
import { brotliCompressSync, constants, gzipSync } from 'node:zlib';
import { existsSync, mkdirSync, readFileSync, readdirSync, statSync, writeFileSync, createReadStream } from 'node:fs';
import { createHash } from 'node:crypto';
import { extname, join, normalize, resolve, sep } from 'node:path';
import type { IncomingMessage, ServerResponse } from 'node:http';

export const ISOLATION_HEADERS = {
  'Cross-Origin-Opener-Policy': 'same-origin',
  'Cross-Origin-Embedder-Policy': 'require-corp',
};

export const IMMUTABLE = 'public, max-age=31536000, immutable';
export const REVALIDATE = 'no-cache';

export const MIME: Record<string, string> = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript',
  '.mjs': 'text/javascript',
  '.css': 'text/css',
  '.json': 'application/json',
  '.svg': 'image/svg+xml',
  '.wav': 'audio/wav',
  '.onnx': 'application/octet-stream',
  '.bin': 'application/octet-stream',
  '.safetensors': 'application/octet-stream',
  '.wasm': 'application/wasm',
};

/** Compressed with brotli at the highest quality (text) or a quicker one (large binaries: seconds, not minutes). */
const TEXT = new Set(['.html', '.js', '.mjs', '.css', '.json', '.svg']);
const BINARY = new Set(['.wasm', '.onnx', '.bin', '.safetensors']);

/** The Cache-Control for a URL path of the build. */
export function cacheControlFor(path: string): string {
  if (/^\/ort\/\d+\.\d+\.\d+[^/]*\//.test(path)) return IMMUTABLE; // onnxruntime-web's files, under its version
  if (/^\/(assets|lib)\/.*-[\w-]{8}\.(js|css)$/.test(path)) return IMMUTABLE; // Vite's content-hashed names
  return REVALIDATE;
}

function* filesUnder(dir: string): Generator<string> {
  for (const e of readdirSync(dir, { withFileTypes: true })) {
    const p = join(dir, e.name);
    if (e.isDirectory()) yield* filesUnder(p);
    else if (e.isFile()) yield p;
  }
}

/** Compressed copies already made, by content: a rebuild (or the next build of the same files) reuses them. */
const CACHE = resolve(import.meta.dirname, '../node_modules/.cache/talking-face-precompressed');

/**
 * Write `.br` and `.gz` beside every file under `dir` that a browser downloads and that compresses (1 KiB or
 * more, and smaller by a twentieth at least).
 */
export function precompress(dir: string): void {
  mkdirSync(CACHE, { recursive: true });
  for (const file of filesUnder(dir)) {
    const ext = extname(file);
    if ((!TEXT.has(ext) && !BINARY.has(ext)) || statSync(file).size < 1024) continue;
    const bytes = readFileSync(file);
    const quality = TEXT.has(ext) ? constants.BROTLI_MAX_QUALITY : 9;
    const cached = join(CACHE, `${createHash('sha256').update(bytes).digest('hex')}-q${quality}`);
    if (!existsSync(`${cached}.br`)) {
      const br = brotliCompressSync(bytes, { params: { [constants.BROTLI_PARAM_QUALITY]: quality, [constants.BROTLI_PARAM_SIZE_HINT]: bytes.length } });
      writeFileSync(`${cached}.gz`, br.length > 0.95 * bytes.length ? Buffer.alloc(0) : gzipSync(bytes, { level: 9 }));
      writeFileSync(`${cached}.br`, br.length > 0.95 * bytes.length ? Buffer.alloc(0) : br); // empty: not worth compressing
    }
    const br = readFileSync(`${cached}.br`);
    if (!br.length) continue;
    writeFileSync(`${file}.br`, br);
    writeFileSync(`${file}.gz`, readFileSync(`${cached}.gz`));
  }
}

const ENCODINGS: [token: string, suffix: string][] = [['br', '.br'], ['gzip', '.gz']];

/**
 * A compressed copy to serve for `file`: there, and not older than the file by more than a copy of the build takes
 * between the two (`cp -r` gives each the time it was copied). A file replaced in a build (a model exported over
 * dist/models/) is served as it is now, not as its stale copy said it was.
 */
function fresh(file: string, copy: string): boolean {
  return existsSync(copy) && statSync(copy).mtimeMs >= statSync(file).mtimeMs - 2000;
}

/**
 * Serve the files of the build under `root` (GET and HEAD): the precompressed copy the browser accepts, its
 * Cache-Control, an ETag (a 304 when it matches), and the cross-origin isolation headers. A missing file is a 404;
 * a missing page and a Range request go on to the next middleware.
 */
export function serveBuild(root: string) {
  return (req: IncomingMessage, res: ServerResponse, next: () => void): void => {
    if ((req.method !== 'GET' && req.method !== 'HEAD') || req.headers.range) return next();
    let path = decodeURIComponent((req.url ?? '/').split('?')[0]);
    if (path.endsWith('/')) path += 'index.html';
    const file = normalize(resolve(root, '.' + path));
    if (!file.startsWith(root + sep) || !existsSync(file) || !statSync(file).isFile()) {
      if (!/\.\w+$/.test(path) || path.endsWith('.html')) return next(); // a page: the server's fallbacks
      res.statusCode = 404; // a missing file (a model, a script) is missing, never the HTML of a fallback page
      res.end(`not found: ${path}`);
      return;
    }
    const accept = String(req.headers['accept-encoding'] ?? '');
    const [encoding, suffix] = ENCODINGS.find(([token, sfx]) => new RegExp(`\\b${token}\\b`).test(accept) && fresh(file, file + sfx)) ?? ['', ''];
    const served = file + suffix;
    const st = statSync(served);
    const etag = `"${st.size.toString(36)}-${Math.floor(st.mtimeMs).toString(36)}${encoding ? `-${encoding}` : ''}"`;
    res.setHeader('Content-Type', MIME[extname(file)] ?? 'application/octet-stream');
    res.setHeader('Cache-Control', cacheControlFor(path));
    res.setHeader('ETag', etag);
    if (BINARY.has(extname(file)) || TEXT.has(extname(file))) res.setHeader('Vary', 'Accept-Encoding');
    if (encoding) res.setHeader('Content-Encoding', encoding);
    for (const [k, v] of Object.entries(ISOLATION_HEADERS)) res.setHeader(k, v);
    if (req.headers['if-none-match'] === etag) {
      res.statusCode = 304;
      res.end();
      return;
    }
    res.setHeader('Content-Length', st.size);
    if (req.method === 'HEAD') {
      res.end();
      return;
    }
    createReadStream(served).pipe(res);
  };
}
