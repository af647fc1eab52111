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
  if (!r.ok) throw failed(`HTTP ${r.status}`);
  return new Uint8Array(r.bytes);
}
