/**
 * onnxruntime's WebAssembly runtime, fetched by this project rather than by onnxruntime, whose loader falls back to
 * a synchronous request when its fetch fails, which waits forever on a stalled connection: by its worker
 * (onnx-worker.ts), and by the page for the WebGPU build or where no worker can run (onnx-model.ts, loadOrt).
 */
import { fetchBody } from '../model/fetch-body';

/** The plain build's runtime and the WebGPU-capable (JSEP) one (vite.config.ts copies both under ort/<version>/). */
export const RUNTIME_FILES = { wasm: 'ort-wasm-simd-threaded.wasm', jsep: 'ort-wasm-simd-threaded.jsep.wasm' } as const;

/**
 * The runtime's bytes from `root` (ort/<version>/), the plain build's unless `build` says otherwise; an Error naming
 * its URL when they cannot be had within stallSeconds.
 */
export async function fetchRuntime(root: string, stallSeconds: number, build: keyof typeof RUNTIME_FILES = 'wasm'): Promise<Uint8Array> {
  const url = `${root}${RUNTIME_FILES[build]}`;
  const failed = (why: string) => new Error(`${url} could not be downloaded (${why})`);
  const r = await fetchBody(url, { stallSeconds }).catch((e: Error) => {
    throw failed(e.message);
  });
  const elsewhere = `serve the build's ort/ folder (dist/ort) there, or tell the library where it is: setRuntimeBase(url)`;
  if (!r.ok) throw failed(r.status === 404 ? `HTTP 404, not there: ${elsewhere}` : `HTTP ${r.status}`);
  const bytes = new Uint8Array(r.bytes);
  // Every WebAssembly module begins with \0asm; a host that answers a missing file with its index page sends HTML.
  if (!(bytes[0] === 0 && bytes[1] === 0x61 && bytes[2] === 0x73 && bytes[3] === 0x6d)) {
    throw failed(`what came back is not WebAssembly${bytes[0] === 0x3c ? ' but an HTML page, as a host sends for a missing file' : ''}: ${elsewhere}`);
  }
  return bytes;
}

/** Whether a runtime download failed for good (not there), where trying again would not help. */
export const runtimeMissing = (message: string): boolean => message.includes('setRuntimeBase(');
