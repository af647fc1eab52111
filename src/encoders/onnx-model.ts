/**
 * The one module that owns onnxruntime-web: session creation, execution-provider choice, input checks,
 * and serialised runs (onnxruntime-web sessions must not run concurrently).
 *
 * onnxruntime-web is imported dynamically: a static import plus numThreads > 1 in a production build
 * makes its worker load the whole app bundle and fail ("document is not defined"; platform.md).
 * Threads need cross-origin isolation (COOP/COEP); an embedding page may not have it, so the
 * sessions then run single-threaded.
 */
import type * as Ort from 'onnxruntime-web';
import { ModelLoadError } from '../model/artefacts';
import type { Manifest } from '../model/manifest';

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

export function loadOrt(build: OrtBuild): Promise<typeof Ort> {
  ortModules[build] ??= (build === 'jsep' ? import('onnxruntime-web') : import('onnxruntime-web/wasm')).then((ort) => {
    const isolated = Boolean((globalThis as { crossOriginIsolated?: boolean }).crossOriginIsolated);
    const cores = (globalThis.navigator as Navigator | undefined)?.hardwareConcurrency ?? 1;
    ort.env.wasm.numThreads = isolated ? Math.max(1, Math.min(4, cores)) : 1;
    // onnxruntime reports node placement notes as warnings through console.error; keep real errors only.
    ort.env.logLevel = 'error';
    // The runtime files are served next to the app (vite.config.ts copies them to ort/<version>/): in a build,
    // ort/ is the sibling of the folder holding this code (assets/ for the app, lib/ for the library),
    // so an embedding page finds them wherever it hosts the build; in dev, at the server root. The version in
    // the path lets a browser keep them for good (docs/embedding.md).
    const folder = `ort/${ort.env.versions.web}/`;
    const sibling = `../${folder}`; // (a variable: Vite would turn a template literal in new URL() into a glob of assets)
    ort.env.wasm.wasmPaths = import.meta.env.DEV
      ? new URL(`${import.meta.env.BASE_URL}${folder}`, globalThis.location?.href ?? 'file:///').href
      : new URL(sibling, import.meta.url).href;
    return ort;
  });
  return ortModules[build];
}

export interface SessionSpec {
  name: string;
  bytes: ArrayBuffer;
  /** Expected input names with their shapes ("K"-style strings are free dimensions). */
  inputs: Record<string, (number | string)[]>;
}

/** The session spec of runtime file `key` as the manifest describes it (manifest.onnx[key].inputs). */
export function specOf(manifest: Manifest, key: string, bytes: ArrayBuffer): SessionSpec {
  return { name: key, bytes, inputs: manifest.onnx[key].inputs };
}

/** A dimension's fixed size, or null for a free one ("K", "ceil(K / content_stride)"); "1" is fixed. */
function fixedSize(dim: number | string): number | null {
  if (typeof dim === 'number') return dim;
  return /^\d+$/.test(dim) ? Number(dim) : null;
}

/** A session plus a queue: `run` calls are executed one after another. */
export class OnnxModel {
  private queue: Promise<unknown> = Promise.resolve();

  private constructor(
    readonly name: string,
    readonly session: Ort.InferenceSession,
    readonly provider: ExecutionProvider,
    private readonly ort: typeof Ort,
    private readonly inputs: Record<string, (number | string)[]>,
  ) {}

  static async create(spec: SessionSpec, providers: ExecutionProvider[] = PROVIDER_PRIORITY): Promise<OnnxModel> {
    const ort = await loadOrt(ortBuildFor(providers));
    const errors: string[] = [];
    for (const provider of providers) {
      try {
        const session = await ort.InferenceSession.create(new Uint8Array(spec.bytes), { executionProviders: [provider], graphOptimizationLevel: 'all', logSeverityLevel: 3 });
        const missing = Object.keys(spec.inputs).filter((n) => !session.inputNames.includes(n));
        if (missing.length) throw new ModelLoadError(`${spec.name}: the model file has no input ${missing.join(', ')} (inputs: ${session.inputNames.join(', ')}); models/ does not match this build`);
        return new OnnxModel(spec.name, session, provider, ort, spec.inputs);
      } catch (e) {
        if (e instanceof ModelLoadError) throw e;
        errors.push(`${provider}: ${(e as Error).message}`);
      }
    }
    throw new ModelLoadError(`could not load ${spec.name} with any execution provider (${errors.join('; ')})`);
  }

  /** Run with float32 / int64 feeds given as (data, shape); shapes are checked against the manifest first. */
  run(feeds: Record<string, { data: Float32Array | BigInt64Array; shape: number[] }>): Promise<Record<string, { data: Float32Array; dims: readonly number[] }>> {
    for (const [name, want] of Object.entries(this.inputs)) {
      const got = feeds[name];
      if (!got) throw new RangeError(`${this.name}: missing input ${name}`);
      const bad = want.length !== got.shape.length || want.some((w, i) => fixedSize(w) !== null && fixedSize(w) !== got.shape[i]);
      if (bad) throw new RangeError(`${this.name}: input ${name} has shape [${got.shape}], expected [${want}]`);
      const count = got.shape.reduce((a, b) => a * b, 1);
      if (count !== got.data.length) throw new RangeError(`${this.name}: input ${name} has ${got.data.length} values for shape [${got.shape}]`);
    }
    const job = this.queue.then(async () => {
      const ortFeeds: Record<string, Ort.Tensor> = {};
      for (const [name, f] of Object.entries(feeds)) {
        ortFeeds[name] = new this.ort.Tensor(f.data instanceof BigInt64Array ? 'int64' : 'float32', f.data, f.shape);
      }
      const out = await this.session.run(ortFeeds);
      const result: Record<string, { data: Float32Array; dims: readonly number[] }> = {};
      for (const [name, t] of Object.entries(out)) {
        result[name] = { data: (await t.getData()) as Float32Array, dims: t.dims };
        t.dispose();
      }
      return result;
    });
    // Deliberate: the caller receives the job's error through `job`; the queue only orders runs, and one failed
    // run must not stop the next.
    this.queue = job.catch(() => undefined); // the caller gets the error through `job`; the queue only orders runs
    return job;
  }

  release(): Promise<void> {
    return this.session.release();
  }
}
