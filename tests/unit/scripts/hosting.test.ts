/** How the build is served (scripts/hosting.ts): cache headers by path, precompressed copies, ETags, 404s. */
import { createServer, request, type IncomingHttpHeaders, type Server } from 'node:http';
import { mkdtempSync, mkdirSync, rmSync, writeFileSync, existsSync, utimesSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { brotliDecompressSync } from 'node:zlib';
import { cacheControlFor, precompress, serveBuild, IMMUTABLE, REVALIDATE } from '../../../scripts/hosting';

describe('cacheControlFor', () => {
  it('keeps hashed names and versioned runtime files for a year, revalidates the rest', () => {
    expect(cacheControlFor('/assets/main-C8B9G2VA.js')).toBe(IMMUTABLE);
    expect(cacheControlFor('/lib/ort.min-D05h4OOJ.js')).toBe(IMMUTABLE);
    expect(cacheControlFor('/ort/1.30.0/ort-wasm-simd-threaded.wasm')).toBe(IMMUTABLE);
    for (const p of ['/', '/index.html', '/lib/talking-face.js', '/models/manifest.json', '/models/content_encoder.onnx', '/ort/ort-wasm-simd-threaded.wasm']) {
      expect(cacheControlFor(p), p).toBe(REVALIDATE);
    }
  });
});

/** A GET that keeps the body as sent (fetch would decompress it). */
function get(url: string, headers: Record<string, string>): Promise<{ status: number; headers: IncomingHttpHeaders; body: Buffer }> {
  return new Promise((resolve, reject) => {
    request(url, { headers }, (res) => {
      const chunks: Buffer[] = [];
      res.on('data', (c: Buffer) => chunks.push(c));
      res.on('end', () => resolve({ status: res.statusCode ?? 0, headers: res.headers, body: Buffer.concat(chunks) }));
    }).on('error', reject).end();
  });
}

describe('serveBuild', () => {
  const root = mkdtempSync(join(tmpdir(), 'hosting-'));
  const text = 'console.log("hello");\n'.repeat(200);
  let server: Server;
  let base = '';
  beforeAll(async () => {
    mkdirSync(join(root, 'assets'));
    writeFileSync(join(root, 'assets/app-abcdEF12.js'), text);
    writeFileSync(join(root, 'index.html'), '<!doctype html><title>t</title>');
    precompress(root);
    server = createServer((req, res) => serveBuild(root)(req, res, () => {
      res.statusCode = 418; // the next middleware
      res.end();
    }));
    await new Promise<void>((r) => server.listen(0, '127.0.0.1', () => r()));
    const a = server.address();
    base = `http://127.0.0.1:${typeof a === 'object' && a ? a.port : 0}`;
  });
  afterAll(() => {
    server.close();
    rmSync(root, { recursive: true, force: true });
  });

  it('writes .br and .gz beside what compresses', () => {
    expect(existsSync(join(root, 'assets/app-abcdEF12.js.br'))).toBe(true);
    expect(existsSync(join(root, 'assets/app-abcdEF12.js.gz'))).toBe(true);
    expect(existsSync(join(root, 'index.html.br')), 'too small to compress').toBe(false);
  });

  it('sends the brotli copy with its headers, and a 304 for a matching ETag', async () => {
    const res = await get(`${base}/assets/app-abcdEF12.js`, { 'accept-encoding': 'br, gzip' });
    expect(res.headers['content-encoding']).toBe('br');
    expect(res.headers['cache-control']).toBe(IMMUTABLE);
    expect(res.headers['cross-origin-embedder-policy']).toBe('require-corp');
    expect(res.headers.vary).toBe('Accept-Encoding');
    const body = res.body;
    expect(body.length).toBeLessThan(text.length / 4);
    const again = await get(`${base}/assets/app-abcdEF12.js`, { 'accept-encoding': 'br', 'if-none-match': String(res.headers.etag) });
    expect(again.status).toBe(304);
    expect(brotliDecompressSync(body).toString()).toBe(text);
  });

  it('sends a file replaced after the build as it is now, not its older compressed copy', async () => {
    const replaced = 'console.log("replaced");\n'.repeat(200);
    writeFileSync(join(root, 'assets/late.js'), text);
    precompress(root);
    const old = new Date(Date.now() - 60_000);
    utimesSync(join(root, 'assets/late.js.br'), old, old);
    utimesSync(join(root, 'assets/late.js.gz'), old, old);
    writeFileSync(join(root, 'assets/late.js'), replaced);
    const res = await get(`${base}/assets/late.js`, { 'accept-encoding': 'br, gzip' });
    expect(res.headers['content-encoding']).toBeUndefined();
    expect(res.body.toString()).toBe(replaced);
  });

  it('sends the file as is where no encoding is accepted, serves / as index.html, and 404s a missing file', async () => {
    const plain = await fetch(`${base}/assets/app-abcdEF12.js`, { headers: { 'accept-encoding': 'identity' } });
    expect(plain.headers.get('content-encoding')).toBeNull();
    expect(await plain.text()).toBe(text);
    const index = await fetch(`${base}/`);
    expect(index.headers.get('cache-control')).toBe(REVALIDATE);
    expect(await index.text()).toContain('<title>t</title>');
    expect((await fetch(`${base}/models/missing.onnx`)).status).toBe(404);
    expect((await fetch(`${base}/some/page`)).status, 'a page goes on to the fallbacks').toBe(418);
  });
});
