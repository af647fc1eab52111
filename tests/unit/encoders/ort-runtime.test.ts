/**
 * onnxruntime's runtime download (src/encoders/ort-runtime.ts): WebAssembly comes back as bytes; a missing file, or
 * the HTML page a host sends in its place, is named as not there, with where to serve it or how to say where it is.
 */
import { afterEach, describe, expect, it, vi } from 'vitest';
import { fetchRuntime, runtimeMissing } from '../../../src/encoders/ort-runtime';

const answer = (body: BodyInit, status = 200) => vi.stubGlobal('fetch', vi.fn(async () => new Response(body, { status })));
afterEach(() => vi.unstubAllGlobals());

describe('fetchRuntime', () => {
  it('gives the WebAssembly it fetched', async () => {
    answer(new Uint8Array([0, 0x61, 0x73, 0x6d, 1, 0, 0, 0]));
    expect(Array.from(await fetchRuntime('https://h/ort/1.30.0/', 5))).toEqual([0, 0x61, 0x73, 0x6d, 1, 0, 0, 0]);
  });

  it('says a missing runtime is not there, and how to point at it', async () => {
    answer('not found', 404);
    const e = await fetchRuntime('https://h/ort/1.30.0/', 5).catch((x: Error) => x);
    expect((e as Error).message).toMatch(/ort-wasm-simd-threaded\.wasm could not be downloaded \(HTTP 404, not there: serve the build's ort\/ folder/);
    expect(runtimeMissing((e as Error).message)).toBe(true);
  });

  it('says an HTML page in its place is not WebAssembly', async () => {
    answer('<!doctype html><html></html>');
    const e = await fetchRuntime('https://h/ort/1.30.0/', 5).catch((x: Error) => x);
    expect((e as Error).message).toMatch(/not WebAssembly but an HTML page/);
    expect(runtimeMissing((e as Error).message)).toBe(true);
  });

  it('leaves a passing failure to be tried again', async () => {
    answer('busy', 503);
    const e = await fetchRuntime('https://h/ort/1.30.0/', 5).catch((x: Error) => x);
    expect((e as Error).message).toMatch(/HTTP 503/);
    expect(runtimeMissing((e as Error).message)).toBe(false);
  });
});
