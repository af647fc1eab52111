/**
 * The inference engine, the library's entry: loads the exported model, then turns audio samples into posed face
 * frames, offline (animate), streaming (createStream) or live from a microphone (listen), in bounded memory.
 * The stages live in their own folders (docs/architecture.md); this file only wires them together:
 *
 *   model/artefacts (fetch, hash checks) -> encoders/ (content, pose) + engine/backends (attention decoder)
 *   -> engine/pipeline (one chunk) -> engine/stream, engine/live
 *
 * Library code: no DOM.
 */
import { fetchArtefacts } from '../model/artefacts';
import type { AnimateOptions, EngineOptions } from './options';
import type { Manifest } from '../model/manifest';
import { parseSafetensors } from '../model/safetensors';
import { sessionsRequested, startOrt, type ExecutionProvider } from '../encoders/onnx-model';
import { ContentEncoder } from '../encoders/content';
import { PoseEncoder } from '../encoders/pose';
import { ReferenceDecoder, decoderWeights, type AttentionMaps, type DecoderWeights } from '../attention/reference';
import { HeadMotion, checkedScale, headMotionParams } from '../pose/head-motion';
import { detectWebGPU, isHardwareAdapter } from '../gpu/capabilities';
import type { FaceTemplate } from '../template/face-template';
import { DecoderBackends, EngineDisposedError, type Backend } from './backends';
import type { AvatarWeights } from '../avatar/weights';
import { DEFAULT_CHUNK_FRAMES, Pipeline } from './pipeline';
import { StreamSession } from './stream';
import { LiveSession, type LiveOptions } from './live';
import { emptyBlendshapes, setBlendshapes, yieldToEventLoop, type Animation, type Frames, type StageTimes } from './frames';
import { speechFound } from '../encoders/voice-activity';
import { levels, SILENT_PEAK } from '../audio/decode';
import { checkedBackend, checkedChunk, checkedFrame, checkedLayer, checkedSamples, checkedSeed, checkedStallSeconds, checkedWorkers } from './checks';
import { ortThreads } from '../encoders/ort-worker-client';
import { allOrFree } from '../model/all-or-free';

export type { Backend } from './backends';
export type { Animation, Frames, StageTimes } from './frames';
export { StreamSession } from './stream';
export { ModelLoadError } from '../model/artefacts';
export { MAX_HEAD_MOTION_SCALE } from '../pose/head-motion';
export { EngineDisposedError } from './backends';
export type { EngineOptions, AnimateOptions } from './options';

let markSessionsRequested: () => void = () => undefined;

/** What `backend: 'cpu'` loads with instead of asking for a WebGPU adapter: no GPU for the decoder or the encoders. */
const CPU_ASKED = { available: false, description: 'not asked for (backend cpu)', adapter: null, info: null };

export class TalkingFaceEngine {
  /**
   * Resolves once load() has asked onnxruntime for every session of the model (or has failed: nothing more is asked):
   * where the page can start a worker, onnxruntime creates them there, and the page's main thread is free meanwhile.
   */
  static readonly sessionsRequested: Promise<void> = new Promise((resolve) => (markSessionsRequested = resolve));

  private reference: ReferenceDecoder | null = null;

  private constructor(private readonly pipeline: Pipeline) {}

  static load(options: EngineOptions = {}): Promise<TalkingFaceEngine> {
    const loading = TalkingFaceEngine.loaded(options);
    loading.catch(() => markSessionsRequested()); // failed: nothing more is asked (the caller gets the error from `loading`)
    return loading;
  }

  private static async loaded(options: EngineOptions): Promise<TalkingFaceEngine> {
    if (options.backend !== undefined) checkedBackend(options.backend);
    if (options.cpuWorkers !== undefined) checkedWorkers(options.cpuWorkers);
    if (options.headMotionSeed !== undefined) checkedSeed(options.headMotionSeed); // (before anything is loaded for nothing)
    if (options.headMotionScale !== undefined) checkedScale(options.headMotionScale);
    if (options.stallSeconds !== undefined) checkedStallSeconds(options.stallSeconds);
    // onnxruntime starts loading as soon as the providers are known, and each ONNX session is requested as soon as its
    // file has arrived, while the others are still on their way: the model is ready sooner than if every file were awaited first.
    // (Both awaited together: a file that fails while the adapter is being asked for is then still handled below.)
    // Asked for the CPU: no adapter is asked for either (where there is none, the request logs a console warning).
    const gpu = (options.backend === 'cpu' ? Promise.resolve(CPU_ASKED) : detectWebGPU()).then((support) => {
      const hardwareGpu = isHardwareAdapter(support);
      const providers: ExecutionProvider[] = options.onnxProviders ?? (hardwareGpu ? ['webgpu', 'wasm'] : ['wasm']);
      startOrt(providers, options.stallSeconds); // onnxruntime (its worker, or its script) loads while the files arrive
      return { support, providers };
    });
    const [{ support, providers }, { manifest, template, files }] = await Promise.all([gpu, fetchArtefacts(options)]);
    const m = manifest.model.config;
    void sessionsRequested(manifest.runtime_files.filter((k) => manifest.onnx[k]).length).then(markSessionsRequested);
    // The decoder's weights and the head's own motion come from the same file.
    const weights = files.decoder_weights.then((bytes) => {
      const tensors = parseSafetensors(bytes).tensors;
      return { decoder: decoderWeights(tensors, m, manifest.model.layer_norm_eps), head: headMotionParams(tensors, m) };
    });
    const decoders = Promise.all([template, weights]).then(([t, w]) => DecoderBackends.create(w.decoder, t.adjacency, m, support, DEFAULT_CHUNK_FRAMES, options));
    const [content, pose, decoder, face, { head }] = await allOrFree([ // (a part failing frees the others: sessions, workers)
      ContentEncoder.create(manifest, files, providers),
      PoseEncoder.create(manifest, files, providers),
      decoders,
      template,
      weights,
    ]);
    const pipeline = new Pipeline(manifest, face, content, pose, decoder, head && new HeadMotion(head, m.d_model));
    const engine = new TalkingFaceEngine(pipeline);
    if (options.headMotionSeed !== undefined) engine.headMotionSeed = options.headMotionSeed; // checked as the setter checks
    if (options.headMotionScale !== undefined) engine.headMotionScale = options.headMotionScale;
    return engine;
  }

  get manifest(): Manifest {
    return this.pipeline.manifest;
  }

  get template(): FaceTemplate { return this.pipeline.template; }

  /** Milliseconds per stage since resetTimes(). */
  get times(): StageTimes {
    return this.pipeline.times;
  }

  get backend(): Backend {
    return this.pipeline.decoders.backend;
  }

  /** Why the backend is what it is, for the status line. */
  get backendReason(): string {
    return this.pipeline.decoders.reason;
  }

  /** The decoder's weights (shared by the CPU and WebGPU decoders). */
  get decoderWeights(): DecoderWeights {
    return this.pipeline.decoders.weights;
  }

  /** onnxruntime's threads per session: 1 where the page is not cross-origin isolated (then it cannot start threads). */
  get encoderThreads(): number {
    return ortThreads();
  }

  /** CPU decoder threads: the workers' count, or 1 when decoding in the page's thread. */
  get cpuThreads(): number {
    return this.pipeline.decoders.cpuThreads;
  }

  /** The CPU decoder's arithmetic: 'wasm-simd' (WebAssembly SIMD) or 'js' (TypeScript, where SIMD is missing). */
  get cpuKernel(): string {
    return this.pipeline.decoders.cpuKernel;
  }

  /** Whether the model has the head's own motion (a model exported before it has only the mean pose). */
  get hasHeadMotion(): boolean {
    return this.pipeline.headMotion !== null;
  }

  /** The seed the head's own motion is drawn with for new animations and streams; null: the mean pose alone. */
  get headMotionSeed(): number | null {
    return this.pipeline.headSeed;
  }

  set headMotionSeed(seed: number | null) {
    this.pipeline.headSeed = checkedSeed(seed);
  }

  /** How far the head's own motion turns the head in new animations and streams (1: as fitted). */
  get headMotionScale(): number {
    return this.pipeline.headScale;
  }

  set headMotionScale(scale: number) {
    this.pipeline.headScale = checkedScale(scale)!;
  }

  /** Template units per mm (the model works in mm; poses carry mm translations). */
  get unitsPerMm(): number {
    return 1 / this.pipeline.mmPerUnit;
  }

  get fps(): number { return this.pipeline.fps; }

  /** Frames produced for `samples` samples: round(duration * fps). */
  frameCount(samples: number): number {
    return this.pipeline.frameCount(samples);
  }

  /** Samples a frame needs before it can be computed exactly (its receptive field's last sample, exclusive). */
  samplesNeeded(frame: number): number {
    return this.pipeline.samplesNeeded(frame);
  }

  /** The whole clip, chunk by chunk. `samples` must be mono at manifest.audio.sample_rate. */
  async animate(samples: Float32Array, options: AnimateOptions = {}): Promise<Animation> {
    checkedSamples(samples, 'animate');
    const n = this.template.vertexCount;
    const F = this.frameCount(samples.length);
    const chunk = checkedChunk(options.chunkFrames ?? DEFAULT_CHUNK_FRAMES);
    const keep = options.keep ?? true;
    const vertices = keep ? new Float32Array(F * n * 3) : new Float32Array(0);
    const pose = new Float32Array(F * 6);
    const unposed = options.unposed ? new Float32Array(F * n * 3) : undefined;
    const phones = new Uint8Array(F);
    const blendshapes = options.blendshapes ? emptyBlendshapes(F) : undefined;
    const tongue = new Float32Array(F);
    const speech = new Float32Array(F);
    const state = this.pipeline.newState({ blendshapes: options.blendshapes, headMotionScale: checkedScale(options.headMotionScale) });
    for (let f0 = 0; f0 < F; f0 += chunk) {
      if (f0 > 0) await yieldToEventLoop(); // keep the page responsive through a long clip
      options.signal?.throwIfAborted();
      const f1 = Math.min(F, f0 + chunk);
      const out = await this.pipeline.produce(state, f0, f1, samples, 0, samples.length);
      options.signal?.throwIfAborted(); // aborted during the chunk: no progress or frames after it (nor a result)
      pose.set(out.pose, f0 * 6);
      if (keep) vertices.set(out.vertices, f0 * n * 3);
      unposed?.set(out.unposed, f0 * n * 3);
      phones.set(out.phones, f0);
      if (blendshapes) setBlendshapes(blendshapes, out.blendshapes!, f0);
      tongue.set(out.tongue, f0);
      speech.set(out.speech, f0);
      options.onFrames?.(f0, out.vertices, out.pose, out);
      options.onProgress?.(f1, F);
    }
    return { fps: this.fps, frames: F, vertices, pose, unposed, phones, tongue, speech, blendshapes };
  }

  /**
   * The decoder's attention at one frame of a clip (layer 0-based; default the last, as the paper's
   * Fig. 7 reads the third): the pose token's weights over the vertices, and each vertex's over its
   * 1-ring. Computed by the reference decoder from exactly the tokens the animation used.
   */
  async attentionAt(samples: Float32Array, frame: number, layer = this.manifest.model.config.layers - 1): Promise<AttentionMaps> {
    const F = this.frameCount(checkedSamples(samples, 'attentionAt').length);
    const f = checkedFrame(frame, F);
    checkedLayer(layer, this.manifest.model.config.layers);
    const inputs: { tokens?: Float32Array; poseToken?: Float32Array } = {};
    await this.pipeline.produce(this.pipeline.newState(), f, f + 1, samples, 0, samples.length, inputs);
    this.reference ??= new ReferenceDecoder(this.decoderWeights, this.template.adjacency, this.manifest.model.config);
    return this.reference.attention(inputs.tokens!, inputs.poseToken!, layer);
  }

  /**
   * Streaming: push audio as it arrives, get frames as soon as their look-ahead has arrived. `blendshapes`: the
   * frames also carry ARKit weights, visemes and head rotations (as animate's option).
   */
  createStream(onFrames: (first: number, frames: Frames) => void,
    options: { maxLagFrames?: number; blendshapes?: boolean; headMotionScale?: number } = {}): StreamSession {
    return new StreamSession(this.pipeline, onFrames, options.maxLagFrames,
      { blendshapes: options.blendshapes, headMotionScale: checkedScale(options.headMotionScale) });
  }

  /** Live: animate a MediaStream (e.g. from openMicrophone()) while it plays; stop() returns the take. */
  async listen(media: MediaStream, onFrames: (first: number, frames: Frames) => void, options?: LiveOptions): Promise<LiveSession> {
    if (this.pipeline.disposed) throw new EngineDisposedError(); // (the microphone's capture not started; a bad option rejects too, not throws)
    const stream = this.createStream(onFrames,
      { maxLagFrames: LiveSession.maxLag(options), blendshapes: options?.blendshapes, headMotionScale: options?.headMotionScale });
    return LiveSession.start(stream, media, options);
  }

  /** The ARKit basis and solver the `blendshapes` option uses (built on first use), e.g. to build an avatar from. */
  get avatarWeights(): AvatarWeights {
    return this.pipeline.avatarWeights;
  }

  /** Switch decoders at run time (the numbers are the same; only speed differs). The latest call wins
   * (DecoderBackends.set). */
  setBackend(backend: 'auto' | Backend): Promise<void> {
    return this.pipeline.decoders.set(checkedBackend(backend));
  }

  /** The face the model makes in silence (I + O in the template's units, the last frame of a second of silence):
   * what a face shows before and between speech, instead of the template, whose mouth was opened for the lips
   * to part. Computed once. */
  restFace(): Promise<Float32Array> {
    return this.pipeline.restFace().then((r) => r.slice()); // a copy: the cached face stays as computed
  }

  /** The 52 ARKit weights (ARKIT_NAMES order) of the face at rest, what frames of silence get: an avatar's rest. */
  restArkit(): Promise<Float32Array> {
    return this.pipeline.restArkit().then((w) => w.slice());
  }

  /** Whether a clip holds speech (encoders/voice-activity.ts): speech-like frames, and more than one steady sound. */
  hasSpeech(animation: Animation): boolean {
    return speechFound(animation.speech, animation.phones, animation.fps);
  }

  /**
   * A clip a person chose, to be shown: a silent one (peak below SILENT_PEAK) is the face at rest throughout, made
   * without running the model (a long silent file is ready at once); any other is animate()'s,
   * held at rest where no speech is found (restUnlessSpeech). `speech`: whether it held speech. What the demo and
   * <talking-face> do with every offline take.
   */
  async animateSpeech(samples: Float32Array, options: AnimateOptions = {}): Promise<{ animation: Animation; speech: boolean }> {
    if (!options.onFrames && levels(checkedSamples(samples, 'animateSpeech')).peak < SILENT_PEAK) {
      options.signal?.throwIfAborted();
      const F = this.frameCount(samples.length);
      const animation = await this.pipeline.restAnimation(F, options);
      options.signal?.throwIfAborted(); // (aborted while it was made: no result, as animate's)
      options.onProgress?.(F, F);
      return { animation, speech: false };
    }
    const animation = await this.animate(samples, options);
    const speech = await this.restUnlessSpeech(animation);
    options.signal?.throwIfAborted(); // aborted while held at rest: no result, as animate's
    return { animation, speech };
  }

  /**
   * Whether `animation` holds speech (hasSpeech); where it does not (noise, music, a tone, which the model would
   * otherwise mouth as if it were speech), its face is held at rest first (holdRest).
   */
  async restUnlessSpeech(animation: Animation): Promise<boolean> {
    const speech = this.hasSpeech(animation);
    if (!speech) await this.holdRest(animation);
    return speech;
  }

  /**
   * The face at rest on every frame of `animation` (its head poses kept), in place; with blend shapes, the ARKit
   * weights of the rest (restArkit) and the visemes at viseme_sil.
   */
  holdRest(animation: Animation): Promise<void> {
    return this.pipeline.holdRest(animation);
  }

  resetTimes(): void {
    for (const k of Object.keys(this.times) as (keyof StageTimes)[]) this.times[k] = 0;
  }

  /**
   * Free what the engine holds: its ONNX sessions (onnxruntime's worker ends with the last session in it), the CPU
   * decoder's workers, its WebGPU buffers. Work under way stops at its next step with EngineDisposedError, as does
   * every later call that runs the model. Safe to call more than once.
   */
  dispose(): Promise<void> {
    return this.pipeline.dispose();
  }
}
