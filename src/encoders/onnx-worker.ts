/**
 * onnxruntime-web's WebAssembly build in a worker of its own (onnx-model.ts, OrtWorker): the sessions are created and
 * run here, off the page's main thread, which meanwhile builds and draws the face (issue 18, first load). Jobs run
 * one after another, as onnxruntime-web needs. Every message the page sends is answered with its id.
 *
 *   page -> worker  { type: 'init', ortRoot, numThreads, stallSeconds }   -> { type: 'started' }   (first, once)
 *                   { type: 'create', id, bytes, options }               -> { id, inputNames }
 *                   { type: 'run', id, session, feeds }                  -> { id, outputs }       (data transferred back)
 *                   { type: 'release', id, session }                     -> { id }
 *   worker -> page  { id, error } where a job failed.
 */
import * as ort from 'onnxruntime-web/wasm';
import { fetchRuntime } from './ort-runtime';

type Feed = { type: 'float32' | 'int64'; data: Float32Array | BigInt64Array; dims: number[] };
type Message =
  | { type: 'init'; ortRoot: string; numThreads: number; stallSeconds: number }
  | { type: 'create'; id: number; bytes: ArrayBuffer; options: ort.InferenceSession.SessionOptions }
  | { type: 'run'; id: number; session: number; feeds: Record<string, Feed> }
  | { type: 'release'; id: number; session: number };

const sessions = new Map<number, ort.InferenceSession>();
let queue: Promise<unknown> = Promise.resolve();
/** Its download, started by 'init': sessions are created once it is in. */
let runtime: Promise<void> = Promise.resolve();

async function handle(m: Exclude<Message, { type: 'init' }>): Promise<{ reply: Record<string, unknown>; transfer: Transferable[] }> {
  if (m.type === 'create') {
    await runtime;
    const session = await ort.InferenceSession.create(new Uint8Array(m.bytes), m.options);
    sessions.set(m.id, session);
    return { reply: { id: m.id, inputNames: session.inputNames }, transfer: [] };
  }
  const session = sessions.get(m.session);
  if (!session) throw new Error(`no session ${m.session} in onnxruntime's worker`);
  if (m.type === 'release') {
    sessions.delete(m.session);
    await session.release();
    return { reply: { id: m.id }, transfer: [] };
  }
  const feeds = Object.fromEntries(Object.entries(m.feeds).map(([name, f]) => [name, new ort.Tensor(f.type, f.data, f.dims)]));
  const out = await session.run(feeds);
  const outputs: Record<string, { data: Float32Array; dims: readonly number[] }> = {};
  for (const [name, t] of Object.entries(out)) {
    outputs[name] = { data: (await t.getData()) as Float32Array, dims: t.dims };
    t.dispose();
  }
  return { reply: { id: m.id, outputs }, transfer: Object.values(outputs).map((o) => o.data.buffer) };
}

self.onmessage = (e: MessageEvent<Message>) => {
  const m = e.data;
  if (m.type === 'init') {
    // ortRoot: the page's ort/ folder (onnx-model.ts); the runtime's files are under its version there.
    const root = `${m.ortRoot}${ort.env.versions.web}/`;
    ort.env.wasm.wasmPaths = root;
    ort.env.wasm.numThreads = m.numThreads;
    ort.env.logLevel = 'error';
    // The runtime's WebAssembly is fetched here, not by onnxruntime (ort-runtime.ts): a download that fails or
    // stalls fails the sessions' creation, naming the runtime (onnx-model.ts reads "no available backend").
    runtime = fetchRuntime(root, m.stallSeconds).then((bytes) => {
      ort.env.wasm.wasmBinary = bytes;
    }, (e: Error) => {
      throw new Error(`no available backend: ${e.message}`);
    });
    runtime.catch(() => undefined); // deliberate: read by the first session's creation
    // The reply proves that the page's messages reach this worker (until the page's thread has had a turn after
    // the worker started, they may wait there): the page sends its sessions after it.
    self.postMessage({ type: 'started' });
    return;
  }
  // Every job is answered, its reply's own failure included (an output that cannot be sent): its caller never waits
  // for ever, and the queue goes on to the next job.
  queue = queue.then(() => handle(m)).then(({ reply, transfer }) => self.postMessage(reply, { transfer }))
    .catch((err: unknown) => self.postMessage({ id: m.id, error: err instanceof Error ? err.message : String(err) }));
};
