/**
 * onnxruntime's plain WebAssembly runtime, fetched by this project rather than by onnxruntime, whose loader falls
 * back to a synchronous request when its fetch fails, which waits forever on a stalled connection: by its worker
 * (onnx-worker.ts) and by the page where no worker can run (onnx-model.ts, loadOrt).
 */
import { fetchBody } from '../model/fetch-body';

/** The plain build's runtime (vite.config.ts copies it under ort/<version>/). */
export const RUNTIME_FILE = 'ort-wasm-simd-threaded.wasm';

/** The runtime's bytes from `root` (ort/<version>/); an Error naming its URL when they cannot be had within stallSeconds. */
export async function fetchRuntime(root: string, stallSeconds: number): Promise<Uint8Array> {
  const url = `${root}${RUNTIME_FILE}`;
  const failed = (why: string) => new Error(`${url} could not be downloaded (${why})`);
  const r = await fetchBody(url, { stallSeconds }).catch((e: Error) => {
    throw failed(e.message);
  });
  if (!r.ok) throw failed(`HTTP ${r.status}`);
  return new Uint8Array(r.bytes);
}
