/**
 * The one module that owns onnxruntime-web (with its worker, onnx-worker.ts): session creation, execution-provider
 * choice, input checks, and serialised runs (onnxruntime-web sessions must not run concurrently). The wasm
 * provider's sessions live in onnxruntime's own worker where the page can start one, else in the page.
 *
 * In the page onnxruntime-web is imported dynamically: a static import plus numThreads > 1 in a production build
 * makes its worker load the whole app bundle and fail ("document is not defined"; platform.md). The worker's own
 * chunk imports it statically: that chunk holds nothing of the page.
 * Threads need cross-origin isolation (COOP/COEP); an embedding page may not have it, so the
 * sessions then run single-threaded.
 */
import type * as Ort from 'onnxruntime-web';
import { ModelLoadError } from '../model/artefacts';
import { checkFeeds, type Feeds, type SessionSpec } from './onnx-spec';

export type ExecutionProvider = 'webgpu' | 'wasm';

/** Tried in this order; the first that creates every session wins. */
export const PROVIDER_PRIORITY: ExecutionProvider[] = ['webgpu', 'wasm'];

/**
 * onnxruntime-web comes in two builds: the plain WebAssembly one (14 MB of wasm, about 2.6 MB compressed) and
 * JSEP, which adds the WebGPU provider (28 MB). A page downloads only the one its providers need: JSEP when the
 * WebGPU provider is asked for, the plain build otherwise (the encoders run on the wasm provider unless there is a
 * hardware GPU: engine.ts).
 */
export type OrtBuild = 'wasm' | 'jsep';

export function ortBuildFor(providers: readonly ExecutionProvider[]): OrtBuild {
  return providers.includes('webgpu') ? 'jsep' : 'wasm';
}

const ortModules: Partial<Record<OrtBuild, Promise<typeof Ort>>> = {};

/**
 * Where onnxruntime's files are served: vite.config.ts copies them to ort/<version>/. In a build, ort/ is the sibling
 * of the folder holding this code (assets/ for the app, lib/ for the library), so an embedding page finds them
 * wherever it hosts the build; in dev, at the server root. The version in the path lets a browser keep them for good
 * (docs/embedding.md).
 */
function ortRoot(): string {
  const sibling = '../ort/'; // (a variable: Vite would turn a literal in new URL() into a glob of assets)
  return import.meta.env.DEV
    ? new URL(`${import.meta.env.BASE_URL}ort/`, globalThis.location?.href ?? 'file:///').href
    : new URL(sibling, import.meta.url).href;
}

/** onnxruntime's threads: up to 4 where the page is cross-origin isolated (SharedArrayBuffer) and has workers, else 1. */
function ortThreads(): number {
  const isolated = Boolean((globalThis as { crossOriginIsolated?: boolean }).crossOriginIsolated) && typeof Worker !== 'undefined';
  const cores = (globalThis.navigator as Navigator | undefined)?.hardwareConcurrency ?? 1;
  return isolated ? Math.max(1, Math.min(4, cores)) : 1;
}

/** onnxruntime-web in the page: the WebGPU-capable build, or the plain one where its worker cannot run (OrtWorker). */
export function loadOrt(build: OrtBuild): Promise<typeof Ort> {
  ortModules[build] ??= (build === 'jsep' ? import('onnxruntime-web') : import('onnxruntime-web/wasm')).then((ort) => {
    ort.env.wasm.numThreads = ortThreads();
    // onnxruntime reports node placement notes as warnings through console.error; keep real errors only.
    ort.env.logLevel = 'error';
    ort.env.wasm.wasmPaths = `${ortRoot()}${ort.env.versions.web}/`;
    return ort;
  });
  return ortModules[build];
}

type Outputs = Record<string, { data: Float32Array; dims: readonly number[] }>;

/** A created session wherever it runs: in the page, or in onnxruntime's worker. */
interface Runner {
  readonly inputNames: readonly string[];
  run(feeds: Feeds): Promise<Outputs>;
  release(): Promise<void>;
}

/** A session in the page's thread. */
class PageRunner implements Runner {
  private constructor(private readonly ort: typeof Ort, private readonly session: Ort.InferenceSession) {}

  static async create(spec: SessionSpec, provider: ExecutionProvider): Promise<PageRunner> {
    const ort = await loadOrt(ortBuildFor([provider]));
    markRequested();
    return new PageRunner(ort, await ort.InferenceSession.create(new Uint8Array(spec.bytes), sessionOptions(provider)));
  }

  get inputNames(): readonly string[] {
    return this.session.inputNames;
  }

  async run(feeds: Feeds): Promise<Outputs> {
    const ortFeeds: Record<string, Ort.Tensor> = {};
    for (const [name, f] of Object.entries(feeds)) {
      ortFeeds[name] = new this.ort.Tensor(f.data instanceof BigInt64Array ? 'int64' : 'float32', f.data, f.shape);
    }
    const out = await this.session.run(ortFeeds);
    const result: Outputs = {};
    for (const [name, t] of Object.entries(out)) {
      result[name] = { data: (await t.getData()) as Float32Array, dims: t.dims };
      t.dispose();
    }
    return result;
  }

  release(): Promise<void> {
    return this.session.release();
  }
}

/**
 * onnxruntime-web's plain WebAssembly build in a worker of its own (onnx-worker.ts): creating the encoders' sessions
 * (about half a second of graph work on a busy CPU) and every run leave the page's main thread to the face, which
 * is built and drawn meanwhile (issue 18, first load). Each request is one message: nothing waits on a reply from
 * the page's thread but the result itself. One worker per page, started with the engine's load.
 */
/** How long onnxruntime's worker may take to answer its first message before the sessions go to the page instead. */
const WORKER_START_MS = 15_000;

class OrtWorker {
  private static shared: OrtWorker | null = null;
  /** Resolves when the worker has answered its first message; rejects if it could not start. */
  readonly started: Promise<void>;
  private readonly pending = new Map<number, { resolve: (m: Record<string, unknown>) => void; reject: (e: Error) => void }>();
  private nextId = 0;
  private failure: Error | null = null;

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
    worker.postMessage({ type: 'init', ortRoot: ortRoot(), numThreads: ortThreads() });
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
class WorkerRunner implements Runner {
  private constructor(private readonly worker: OrtWorker, private readonly id: number, readonly inputNames: readonly string[]) {}

  static async create(worker: OrtWorker, spec: SessionSpec, provider: ExecutionProvider): Promise<WorkerRunner> {
    // A copy travels: the caller's bytes stay usable (a failed worker falls back to the page with them).
    const creating = worker.call({ type: 'create', bytes: spec.bytes.slice(0), options: sessionOptions(provider) });
    markRequested();
    const reply = (await creating) as { id: number; inputNames: string[] };
    return new WorkerRunner(worker, reply.id, reply.inputNames);
  }

  async run(feeds: Feeds): Promise<Outputs> {
    const sent: Record<string, { type: string; data: Float32Array | BigInt64Array; dims: number[] }> = {};
    for (const [name, f] of Object.entries(feeds)) sent[name] = { type: f.data instanceof BigInt64Array ? 'int64' : 'float32', data: f.data, dims: f.shape };
    return ((await this.worker.call({ type: 'run', session: this.id, feeds: sent })) as { outputs: Outputs }).outputs;
  }

  async release(): Promise<void> {
    await this.worker.call({ type: 'release', session: this.id });
  }
}

let requested = 0;
const requestWaiters: { count: number; resolve: () => void }[] = [];

/** Count one session asked of onnxruntime (sessionsRequested). */
function markRequested(): void {
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

/**
 * Start loading onnxruntime for `providers` now, before any model file has arrived: its worker (the wasm provider), or
 * its script in the page (the WebGPU provider, or where no worker can run).
 */
export function startOrt(providers: readonly ExecutionProvider[]): void {
  const build = ortBuildFor(providers);
  if (build === 'jsep' || !OrtWorker.get()) void loadOrt(build).catch(() => undefined); // (its error is met again at session creation)
}

function sessionOptions(provider: ExecutionProvider): Ort.InferenceSession.SessionOptions {
  return { executionProviders: [provider], graphOptimizationLevel: 'all', logSeverityLevel: 3 };
}

/** A session plus a queue: `run` calls are executed one after another. */
export class OnnxModel {
  private queue: Promise<unknown> = Promise.resolve();

  private constructor(
    readonly name: string,
    private readonly runner: Runner,
    readonly provider: ExecutionProvider,
    private readonly inputs: Record<string, (number | string)[]>,
  ) {}

  /** Names of the session's inputs (from the model file). */
  get inputNames(): readonly string[] {
    return this.runner.inputNames;
  }

  static async create(spec: SessionSpec, providers: ExecutionProvider[] = PROVIDER_PRIORITY): Promise<OnnxModel> {
    const errors: string[] = [];
    for (const provider of providers) {
      try {
        const runner = await OnnxModel.runner(spec, provider);
        const missing = Object.keys(spec.inputs).filter((n) => !runner.inputNames.includes(n));
        if (missing.length) throw new ModelLoadError(`${spec.name}: the model file has no input ${missing.join(', ')} (inputs: ${runner.inputNames.join(', ')}); models/ does not match this build`);
        return new OnnxModel(spec.name, runner, provider, spec.inputs);
      } catch (e) {
        if (e instanceof ModelLoadError) throw e;
        errors.push(`${provider}: ${(e as Error).message}`);
      }
    }
    throw new ModelLoadError(`could not load ${spec.name} with any execution provider (${errors.join('; ')})`);
  }

  /** The wasm provider in onnxruntime's worker where there is one; the page's thread otherwise, or if the worker fails. */
  private static async runner(spec: SessionSpec, provider: ExecutionProvider): Promise<Runner> {
    const worker = provider === 'wasm' ? OrtWorker.get() : null;
    if (!worker) return PageRunner.create(spec, provider);
    try {
      await worker.started;
      return await WorkerRunner.create(worker, spec, provider);
    } catch (e) {
      if (!worker.failed && /no available backend/i.test((e as Error).message)) {
        // The runtime itself (ort-wasm-*.wasm) did not load: a failed or damaged download. A later load tries anew.
        const error = new ModelLoadError(`onnxruntime's WebAssembly runtime (ort-wasm-*.wasm under ${ortRoot()}) could not be loaded; ` +
          `reload or try again (${(e as Error).message.split('\n')[0]})`);
        OrtWorker.discard(worker, error);
        throw error;
      }
      if (!worker.failed) throw e; // the model's own error (the page would give the same)
      console.warn(`onnxruntime's worker failed (${(e as Error).message}); ${spec.name} runs in the page`);
      return PageRunner.create(spec, provider);
    }
  }

  /** Run with float32 / int64 feeds given as (data, shape); shapes are checked against the manifest first. */
  run(feeds: Feeds): Promise<Record<string, { data: Float32Array; dims: readonly number[] }>> {
    checkFeeds(this.name, this.inputs, feeds);
    const job = this.queue.then(() => this.runner.run(feeds));
    // One failed run must not stop the next.
    this.queue = job.catch(() => undefined); // deliberate: the caller gets the error through `job`; the queue only orders runs
    return job;
  }

  release(): Promise<void> {
    return this.runner.release();
  }
}
