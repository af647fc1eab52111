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
import { STALL_SECONDS } from '../model/fetch-body';
import { fetchRuntime, runtimeMissing } from './ort-runtime';
import { checkFeeds, type ExecutionProvider, type Feeds, type SessionSpec } from './onnx-spec';
import { getRuntimeStallSeconds, markRequested, ortRoot, ortThreads, OrtWorker, sessionOptions, setRuntimeStallSeconds, WorkerRunner, type Outputs, type Runner } from './ort-worker-client';
export { sessionsRequested } from './ort-worker-client';

export type { ExecutionProvider } from './onnx-spec';

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
/** Builds whose load failed since the last startOrt(). */
const failedBuilds = new Set<OrtBuild>();
/** Whether the page has said that onnxruntime's worker failed and the sessions run in the page. */
let warnedWorkerFailure = false;

/**
 * onnxruntime-web in the page: the WebGPU-capable build, or the plain one where its worker cannot run (OrtWorker).
 * Either build's WebAssembly is fetched here, with the load's stallSeconds, as onnx-worker.ts does in the worker
 * (ort-runtime.ts). A failed load is kept for the rest of the engine's load (its other sessions do not fetch it again,
 * one after another, before they give way to the next provider), and forgotten at the next (startOrt).
 */
function loadOrt(build: OrtBuild): Promise<typeof Ort> {
  ortModules[build] ??= (build === 'jsep' ? import('onnxruntime-web') : import('onnxruntime-web/wasm')).then(async (ort) => {
    ort.env.wasm.numThreads = ortThreads();
    // onnxruntime reports node placement notes as warnings through console.error; keep real errors only.
    ort.env.logLevel = 'error';
    const root = `${ortRoot()}${ort.env.versions.web}/`;
    ort.env.wasm.wasmPaths = root;
    ort.env.wasm.wasmBinary = await fetchRuntime(root, getRuntimeStallSeconds(), build).catch((e: Error) => {
      throw new ModelLoadError(`onnxruntime's runtime ${e.message}${runtimeMissing(e.message) ? '' : '; reload or try again'}`);
    });
    return ort;
  }).catch((e: unknown) => {
    failedBuilds.add(build);
    throw e;
  });
  return ortModules[build];
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
 * Start loading onnxruntime for `providers` now, before any model file has arrived: its worker (the wasm provider), or
 * its script in the page (the WebGPU provider, or where no worker can run).
 */
export function startOrt(providers: readonly ExecutionProvider[], stallSeconds = STALL_SECONDS): void {
  setRuntimeStallSeconds(stallSeconds);
  for (const failed of failedBuilds) delete ortModules[failed]; // a new load tries a runtime that failed before
  failedBuilds.clear();
  const build = ortBuildFor(providers);
  if (build === 'jsep' || !OrtWorker.get()) void loadOrt(build).catch(() => undefined); // (its error is met again at session creation)
}

/** A session plus a queue: `run` calls are executed one after another. */
export class OnnxModel {
  private queue: Promise<unknown> = Promise.resolve();
  private released: Promise<void> | null = null;

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

  /**
   * The session on the first of `providers` that creates it. One that fails for any reason, its runtime included (the
   * WebGPU build, 28 MB, is more than some static hosts serve), gives way to the next; a model file that does not
   * match this build fails at once. With one failure, its own error (what to do); with more, all of them.
   */
  static async create(spec: SessionSpec, providers: ExecutionProvider[] = PROVIDER_PRIORITY): Promise<OnnxModel> {
    const errors: Error[] = [];
    for (const provider of providers) {
      let runner: Runner;
      try {
        runner = await OnnxModel.runner(spec, provider);
      } catch (e) {
        errors.push(e as Error);
        if (provider !== providers.at(-1)) console.warn(`${spec.name}: the ${provider} provider failed (${(e as Error).message}); trying the next`);
        continue;
      }
      const missing = Object.keys(spec.inputs).filter((n) => !runner.inputNames.includes(n));
      if (missing.length) throw new ModelLoadError(`${spec.name}: the model file has no input ${missing.join(', ')} (inputs: ${runner.inputNames.join(', ')}); models/ does not match this build`);
      return new OnnxModel(spec.name, runner, provider, spec.inputs);
    }
    if (errors.length === 1 && errors[0] instanceof ModelLoadError) throw errors[0];
    throw new ModelLoadError(`could not load ${spec.name} with any execution provider (${errors.map((e, i) => `${providers[i]}: ${e.message}`).join('; ')})`);
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
        // The runtime itself (ort-wasm-*.wasm) did not load: a failed or damaged download, or a page whose
        // Content-Security-Policy forbids compiling WebAssembly (which no reload mends). A later load tries anew.
        const why = (e as Error).message.split('\n')[0];
        const error = new ModelLoadError(/unsafe-eval|Content Security Policy/i.test(why)
          ? `the page's Content-Security-Policy does not let onnxruntime compile its WebAssembly: add 'wasm-unsafe-eval' to its script-src (${why})`
          : `onnxruntime's WebAssembly runtime (ort-wasm-simd-threaded.mjs and .wasm under ${ortRoot()}<version>/) could not be loaded${runtimeMissing(why) ? '' : '; reload or try again'} (${why})`);
        OrtWorker.discard(worker, error);
        throw error;
      }
      if (!worker.failed) throw e; // the model's own error (the page would give the same)
      if (!warnedWorkerFailure) console.warn(`onnxruntime's worker failed (${(e as Error).message}); the encoders run in the page`);
      warnedWorkerFailure = true; // once, not once per session
      return PageRunner.create(spec, provider);
    }
  }

  /** Run with float32 / int64 feeds given as (data, shape); shapes are checked against the manifest first. */
  run(feeds: Feeds): Promise<Record<string, { data: Float32Array; dims: readonly number[] }>> {
    if (this.released) return Promise.reject(new Error(`${this.name}: the session was released (the engine was disposed)`));
    checkFeeds(this.name, this.inputs, feeds);
    const job = this.queue.then(() => this.runner.run(feeds));
    // One failed run must not stop the next.
    this.queue = job.catch(() => undefined); // deliberate: the caller gets the error through `job`; the queue only orders runs
    return job;
  }

  /** Free the session (after the runs already asked for); a run asked for later is refused. Once is enough. */
  release(): Promise<void> {
    this.released ??= this.queue.then(() => this.runner.release());
    return this.released;
  }
}
