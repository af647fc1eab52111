/**
 * The page's side of onnxruntime's worker (onnx-worker.ts): starting it, its messages and their replies, the sessions
 * created in it; and what the page's own sessions (onnx-model.ts) share with it: where onnxruntime's files are, its
 * threads, its session options, the count of sessions asked for.
 */
import { STALL_SECONDS } from '../model/fetch-body';
import type { ExecutionProvider, Feeds, SessionSpec } from './onnx-spec';

/**
 * Where onnxruntime's files are served: vite.config.ts copies them to ort/<version>/. In a build, ort/ is the sibling
 * of the folder holding this code (assets/ for the app, lib/ for the library), so an embedding page finds them
 * wherever it hosts the build; in dev, at the server root. The version in the path lets a browser keep them for good
 * (docs/embedding.md).
 */
export function ortRoot(): string {
  if (runtimeBase) return runtimeBase;
  const sibling = '../ort/'; // (a variable: Vite would turn a literal in new URL() into a glob of assets)
  return import.meta.env.DEV
    ? folderUrl(`${import.meta.env.BASE_URL}ort/`, globalThis.location?.href ?? 'file:///')
    : folderUrl(sibling, import.meta.url);
}

let runtimeBase: string | null = null;

/**
 * Where onnxruntime's runtime (the `ort/` folder of the build: `<version>/` in it) is served, for a page whose bundler
 * moved the library's code away from it (a project that installs the package and bundles it: Vite, webpack, a
 * framework); relative URLs are resolved against the page. Call it before the first model loads; null goes back to
 * the default, the `ort/` beside the folder that holds the library's code.
 */
export function setRuntimeBase(url: string | URL | null): void {
  runtimeBase = url === null ? null : folderUrl(String(url), globalThis.location?.href ?? 'file:///');
}

/**
 * `path` resolved against `base`, as a folder: ending in a slash. A consumer's Vite dev server rewrites the library's
 * `new URL('../ort/', import.meta.url)` to `new URL('/node_modules/talking-face/dist/ort', ...)`, without the slash,
 * and the runtime's files were then looked for at `.../dist/ort1.30.0/`.
 */
export function folderUrl(path: string, base: string): string {
  const href = new URL(path, base).href;
  return href.endsWith('/') ? href : `${href}/`;
}

/** onnxruntime's threads: up to 4 where the page is cross-origin isolated (SharedArrayBuffer) and has workers, else 1. */
export function ortThreads(): number {
  const isolated = Boolean((globalThis as { crossOriginIsolated?: boolean }).crossOriginIsolated) && typeof Worker !== 'undefined';
  const cores = (globalThis.navigator as Navigator | undefined)?.hardwareConcurrency ?? 1;
  return isolated ? Math.max(1, Math.min(4, cores)) : 1;
}

export type Outputs = Record<string, { data: Float32Array; dims: readonly number[] }>;

/** A created session wherever it runs: in the page, or in onnxruntime's worker. */
export interface Runner {
  readonly inputNames: readonly string[];
  run(feeds: Feeds): Promise<Outputs>;
  release(): Promise<void>;
}

/**
 * onnxruntime-web's plain WebAssembly build in a worker of its own (onnx-worker.ts): creating the encoders' sessions
 * (about half a second of graph work on a busy CPU) and every run leave the page's main thread to the face, which
 * is built and drawn meanwhile (issue 18, first load). Each request is one message: nothing waits on a reply from
 * the page's thread but the result itself. One worker per page, started with the engine's load.
 */
/** How long onnxruntime's worker may take to answer its first message before the sessions go to the page instead. */
const WORKER_START_MS = 15_000;

export class OrtWorker {
  private static shared: OrtWorker | null = null;
  /** Resolves when the worker has answered its first message; rejects if it could not start. */
  readonly started: Promise<void>;
  private readonly pending = new Map<number, { resolve: (m: Record<string, unknown>) => void; reject: (e: Error) => void }>();
  private nextId = 0;
  private failure: Error | null = null;
  /** Sessions created in it and not yet released: the worker ends when the last one is released. */
  private sessions = 0;

  private constructor(private readonly worker: Worker) {
    let onStarted: () => void = () => undefined;
    this.started = new Promise<void>((resolve, reject) => {
      const timer = setTimeout(() => {
        this.fail(new Error(`onnxruntime's worker did not start within ${WORKER_START_MS / 1000} s`));
        reject(this.failure);
      }, WORKER_START_MS);
      onStarted = () => {
        clearTimeout(timer);
        resolve();
      };
      worker.onerror = (e) => {
        e.preventDefault();
        clearTimeout(timer);
        this.fail(new Error(e.message || "onnxruntime's worker could not start"));
        reject(this.failure);
      };
    });
    // Deliberate: the outcome is read where a session is asked for (OnnxModel.runner); a worker that fails before
    // then must not be an unhandled rejection.
    this.started.catch(() => undefined); // read where a session is asked for
    worker.onmessage = (e: MessageEvent<{ type?: string; id?: number; error?: string }>) => {
      const m = e.data;
      if (m.type === 'started') return onStarted();
      const p = this.pending.get(m.id!);
      if (!p) return;
      this.pending.delete(m.id!);
      if (m.error !== undefined) p.reject(new Error(m.error));
      else p.resolve(m as Record<string, unknown>);
    };
    worker.postMessage({ type: 'init', ortRoot: ortRoot(), numThreads: ortThreads(), stallSeconds: runtimeStallSeconds });
  }

  /** The page's worker, started on the first call; null where the page cannot start one (then sessions run in the page). */
  static get(): OrtWorker | null {
    if (typeof Worker === 'undefined') return null;
    if (!OrtWorker.shared) {
      try {
        OrtWorker.shared = new OrtWorker(new Worker(new URL('./onnx-worker.ts', import.meta.url), { type: 'module', name: 'onnxruntime' }));
      } catch (e) {
        console.warn(`onnxruntime's worker could not be created (${(e as Error).message}); the encoders run in the page`);
        return null;
      }
    }
    return OrtWorker.shared.failure ? null : OrtWorker.shared;
  }

  call(message: Record<string, unknown>, transfer: Transferable[] = []): Promise<Record<string, unknown>> {
    if (this.failure) return Promise.reject(this.failure);
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject });
      this.worker.postMessage({ ...message, id }, transfer);
    });
  }

  private fail(e: Error): void {
    this.failure = e;
    for (const p of this.pending.values()) p.reject(e);
    this.pending.clear();
    this.worker.terminate();
  }

  get failed(): boolean {
    return this.failure !== null;
  }

  /** A session was created in this worker. */
  opened(): void {
    this.sessions++;
  }

  /**
   * A session was released: once none is left and nothing is asked of it, the worker ends (its runtime's memory
   * with it), and the next session asked for starts a new one.
   */
  closed(): void {
    this.sessions--;
    if (this.sessions > 0 || this.pending.size > 0) return;
    if (OrtWorker.shared === this) OrtWorker.shared = null;
    this.fail(new Error("onnxruntime's worker was ended: every session in it was released"));
  }

  /**
   * Give up on `w`, whose onnxruntime could not load its runtime (onnxruntime remembers a failed set-up for the
   * worker's life): the next session asked for starts a new worker, which fetches the runtime again.
   */
  static discard(w: OrtWorker, why: Error): void {
    if (OrtWorker.shared === w) OrtWorker.shared = null;
    w.fail(why);
  }
}

/** A session in onnxruntime's worker. */
export class WorkerRunner implements Runner {
  private constructor(private readonly worker: OrtWorker, private readonly id: number, readonly inputNames: readonly string[]) {}

  static async create(worker: OrtWorker, spec: SessionSpec, provider: ExecutionProvider): Promise<WorkerRunner> {
    // A copy travels: the caller's bytes stay usable (a failed worker falls back to the page with them).
    const creating = worker.call({ type: 'create', bytes: spec.bytes.slice(0), options: sessionOptions(provider) });
    markRequested();
    const reply = (await creating) as { id: number; inputNames: string[] };
    worker.opened();
    return new WorkerRunner(worker, reply.id, reply.inputNames);
  }

  async run(feeds: Feeds): Promise<Outputs> {
    const sent: Record<string, { type: string; data: Float32Array | BigInt64Array; dims: number[] }> = {};
    for (const [name, f] of Object.entries(feeds)) sent[name] = { type: f.data instanceof BigInt64Array ? 'int64' : 'float32', data: f.data, dims: f.shape };
    return ((await this.worker.call({ type: 'run', session: this.id, feeds: sent })) as { outputs: Outputs }).outputs;
  }

  async release(): Promise<void> {
    try {
      if (!this.worker.failed) await this.worker.call({ type: 'release', session: this.id });
    } finally {
      this.worker.closed();
    }
  }
}

let requested = 0;
const requestWaiters: { count: number; resolve: () => void }[] = [];

/** Count one session asked of onnxruntime (sessionsRequested). */
export function markRequested(): void {
  requested++;
  for (const w of requestWaiters.filter((x) => x.count <= requested)) {
    requestWaiters.splice(requestWaiters.indexOf(w), 1);
    w.resolve();
  }
}

/**
 * Resolves once `count` sessions have been asked of onnxruntime (and its worker, where it has one, has started):
 * they are then being created off the page's main thread, which a page with heavy work of its own (building and
 * drawing the face) can start on without holding them up (src/app/main.ts).
 */
export function sessionsRequested(count: number): Promise<void> {
  if (requested >= count) return Promise.resolve();
  return new Promise((resolve) => requestWaiters.push({ count, resolve }));
}

/** How long onnxruntime's worker waits on its runtime's download bringing nothing (load's `stallSeconds`). */
let runtimeStallSeconds = STALL_SECONDS;

export function setRuntimeStallSeconds(seconds: number): void {
  runtimeStallSeconds = seconds;
}

export function getRuntimeStallSeconds(): number {
  return runtimeStallSeconds;
}

/**
 * The options every session is created with (onnxruntime's InferenceSession.SessionOptions; typed by what it holds,
 * so that the package's declarations do not name onnxruntime-web, which the package bundles and does not depend on).
 */
export function sessionOptions(provider: ExecutionProvider) {
  return { executionProviders: [provider], graphOptimizationLevel: 'all' as const, logSeverityLevel: 3 as const };
}
