/**
 * fetchBody (src/model/fetch-body.ts): no download the page makes can hang. Headers that never come, a body that
 * stops, a fetch that ignores its abort signal: each fails once nothing has arrived for stallSeconds; a slow body
 * that keeps coming is waited for. And the callers name what stalled (the manifest, the template).
 */
import { describe, expect, it } from 'vitest';
import { fetchBody, StalledError } from '../../../src/model/fetch-body';
import { fetchArtefacts, fetchManifest, ModelLoadError } from '../../../src/model/artefacts';
import { loadTemplate, TemplateFormatError } from '../../../src/template/face-template';

const never = () => new Promise<never>(() => undefined);

/** A response whose body sends `chunks` chunks of 100 bytes, `gapMs` apart, then stops (`end`) or never ends. */
function streaming(chunks: number, gapMs: number, end: boolean): Response {
  let sent = 0;
  return new Response(new ReadableStream<Uint8Array>({
    async pull(c) {
      if (sent === chunks) return end ? c.close() : never();
      await new Promise((r) => setTimeout(r, gapMs));
      sent += 1;
      c.enqueue(new Uint8Array(100).fill(sent));
    },
  }));
}

const served = (r: () => Response | Promise<Response>): typeof fetch => (async () => r()) as typeof fetch;

describe('fetchBody', () => {
  it('gives the whole body of a download that keeps coming, however slowly', async () => {
    const body = await fetchBody('http://test/a', { fetch: served(() => streaming(8, 40, true)), stallSeconds: 0.1 });
    expect(body.ok).toBe(true);
    expect(new Uint8Array(body.bytes)).toEqual(Uint8Array.from({ length: 800 }, (_, i) => 1 + Math.floor(i / 100)));
  });

  it('fails once a body stops coming', async () => {
    const t0 = Date.now();
    await expect(fetchBody('http://test/a', { fetch: served(() => streaming(2, 0, false)), stallSeconds: 0.1 })).rejects.toThrow(StalledError);
    expect(Date.now() - t0).toBeLessThan(2000);
  });

  it('never times out with stallSeconds Infinity (or longer than a timer can wait); refuses one that is no positive number', async () => {
    for (const stallSeconds of [Infinity, 3e6]) {
      const body = await fetchBody('http://test/a', { fetch: served(() => streaming(2, 30, true)), stallSeconds });
      expect(body.bytes.byteLength, `stallSeconds ${stallSeconds}`).toBe(200); // (a timer past 2^31 ms fired at once)
    }
    for (const stallSeconds of [0, -1, NaN, '30']) {
      await expect(fetchBody('http://test/a', { fetch: served(() => streaming(1, 0, true)), stallSeconds: stallSeconds as number })).rejects.toThrow(RangeError);
    }
    // The public loaders say so as it is, not as a download that failed (nothing was fetched).
    const unfetched = (() => { throw new Error('fetched'); }) as unknown as typeof fetch;
    await expect(loadTemplate('http://test/t.json', unfetched, 0)).rejects.toThrow(RangeError);
    await expect(fetchManifest('http://test/m.json', unfetched, -1)).rejects.toThrow(RangeError);
    await expect(fetchArtefacts({ manifestUrl: 'http://test/m.json', fetch: unfetched, stallSeconds: NaN })).rejects.toThrow(RangeError);
  });

  it('fails when the headers never come, even from a fetch that ignores its abort signal', async () => {
    await expect(fetchBody('http://test/a', { fetch: (() => never()) as typeof fetch, stallSeconds: 0.1 })).rejects.toThrow('nothing arrived for 0.1 s');
    const aborting: typeof fetch = (_url, init) => new Promise((_, reject) => init!.signal!.addEventListener('abort', () => reject(new DOMException('aborted', 'AbortError'))));
    await expect(fetchBody('http://test/a', { fetch: aborting, stallSeconds: 0.1 })).rejects.toThrow(StalledError);
  });

  it('is cancelled by its signal at once, whether the headers or the body are awaited, with the signal\'s reason', async () => {
    for (const fetchFn of [(() => never()) as unknown as typeof fetch, served(() => streaming(2, 0, false))]) {
      const stop = new AbortController();
      const fetching = fetchBody('http://test/a', { fetch: fetchFn, stallSeconds: 30, signal: stop.signal });
      setTimeout(() => stop.abort(new DOMException('stopped', 'AbortError')), 20);
      const t0 = Date.now();
      await expect(fetching).rejects.toThrow('stopped');
      expect(Date.now() - t0).toBeLessThan(1000);
    }
    const gone = new AbortController();
    gone.abort();
    await expect(fetchBody('http://test/a', { fetch: served(() => streaming(1, 0, true)), signal: gone.signal })).rejects.toMatchObject({ name: 'AbortError' });
  });

  it('says an HTTP error without reading its body, and passes fetch\'s own errors on', async () => {
    const missing = await fetchBody('http://test/a', { fetch: served(() => new Response('gone', { status: 404 })) });
    expect([missing.ok, missing.status, missing.bytes.byteLength]).toEqual([false, 404, 0]);
    await expect(fetchBody('http://test/a', { fetch: (() => Promise.reject(new TypeError('Failed to fetch'))) as typeof fetch })).rejects.toThrow('Failed to fetch');
  });
});

describe('what stalled is named', () => {
  it('the manifest', async () => {
    const manifestUrl = 'http://test/models/manifest.json';
    await expect(fetchManifest(manifestUrl, (() => never()) as typeof fetch, 0.1)).rejects.toThrow(ModelLoadError);
    await expect(fetchArtefacts({ manifestUrl, fetch: (() => never()) as typeof fetch, stallSeconds: 0.1 }))
      .rejects.toThrow(/could not fetch the model manifest http:\/\/test\/models\/manifest\.json: nothing arrived for 0\.1 s; check the connection/);
  });

  it('the template, its header or its binary', async () => {
    const header = JSON.stringify({ binary: 'template.bin' });
    const stallBinary: typeof fetch = (async (url: RequestInfo | URL) => (String(url).endsWith('.json') ? new Response(header) : streaming(1, 0, false))) as typeof fetch;
    await expect(loadTemplate('http://test/t/template.json', stallBinary, 0.1)).rejects.toThrow(TemplateFormatError);
    await expect(loadTemplate('http://test/t/template.json', stallBinary, 0.1)).rejects.toThrow(/template\.bin: nothing arrived for 0\.1 s/);
    await expect(loadTemplate('http://test/t/template.json', (() => never()) as typeof fetch, 0.1)).rejects.toThrow(/template\.json: nothing arrived/);
  });
});
