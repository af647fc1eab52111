/**
 * The inference engine: audio samples in, posed face frames out, in bounded memory.
 *
 *   samples (mono, manifest rate) -> log-Mel (meyda) -> content encoder (ONNX) -> windows of phone
 *   posteriors -> hierarchical tokens (ONNX) ; log-Mel -> pose conv + LSTM (ONNX, state carried)
 *   -> GAVA decoder (WGSL, or the fast TypeScript decoder on the CPU) -> y = R (I + O) + t  -> frames in the template's units
 *
 * Frames are produced in chunks; every chunk recomputes the Mel and content frames it needs with
 * enough context on each side that the result equals the whole-clip computation exactly, so memory
 * holds one chunk of intermediates whatever the clip's length. Library code: no DOM.
 */
import { checkManifest, frameToMelIndex, type Manifest } from '../model/manifest';
import { parseSafetensors } from '../model/safetensors';
import { OnnxModel, type ExecutionProvider, ModelLoadError } from '../model/onnx-sessions';
import { contentWindows, softmaxRows } from '../model/windows';
import { logMelFrames, melFrameCount } from '../audio/mel';
import { ReferenceDecoder, applyPose, decoderWeights, type AttentionMaps, type DecodeResult, type DecoderWeights } from '../attention/reference';
import { FastDecoder } from '../attention/fast-decoder';
import { DecoderPool } from '../attention/decoder-pool';
import { GpuDecoder } from '../attention/gpu-decoder';
import { LiveSession, type LiveOptions } from './live';
import { detectWebGPU, requestSharedDevice } from '../gpu/capabilities';
import { MM_PER_UNIT, loadTemplate, type FaceTemplate } from '../template/face-template';

export type Backend = 'webgpu' | 'cpu';

export interface EngineOptions {
  /** URL of models/manifest.json (default: /models/manifest.json). */
  manifestUrl?: string | URL;
  /**
   * 'auto' (default): WebGPU on a hardware adapter, else the CPU decoder. A software fallback adapter
   * (SwiftShader) computes the same numbers, more slowly than the CPU path; ask for 'webgpu' to use it anyway.
   */
  backend?: 'auto' | Backend;
  /** URL of the face template (default: the manifest's). It must be the template the model was trained on. */
  templateUrl?: string | URL;
  /**
   * Web Workers for the CPU decoder (default: one per core, up to 4; 0 or 1 decodes in the page's
   * thread). Each chunk's frames are split between them; the numbers are the same either way.
   */
  cpuWorkers?: number;
  /** Execution providers for the ONNX encoders, in order of preference (default: webgpu then wasm on a hardware adapter, else wasm). */
  onnxProviders?: ExecutionProvider[];
  fetch?: typeof fetch;
}

export interface AnimateOptions {
  /** Frames per chunk (default 96). */
  chunkFrames?: number;
  /** Called after each chunk with the frames done so far. */
  onProgress?: (done: number, total: number) => void;
  /** Receives each chunk's frames instead of (or as well as) the returned buffer. */
  onFrames?: (first: number, vertices: Float32Array, pose: Float32Array) => void;
  /** false: do not keep all frames (use onFrames); memory then stays one chunk. Default true. */
  keep?: boolean;
  /** Also keep the unposed face I + O per frame (what a renderer that poses the head itself wants). */
  unposed?: boolean;
  signal?: AbortSignal;
}

export interface Animation {
  fps: number;
  frames: number;
  /** (frames x N x 3) posed vertices in the template's units, or empty when keep = false. */
  vertices: Float32Array;
  /** (frames x 6): axis-angle (rad), translation (mm). */
  pose: Float32Array;
  /** (frames x N x 3) I + O in the template's units, when asked for. */
  unposed?: Float32Array;
  /** (frames): the content class the encoder heard most at each frame (names: manifest.content_phones). */
  phones: Uint8Array;
}

export interface StageTimes {
  mel: number;
  content: number;
  hierarchical: number;
  pose: number;
  decoder: number;
  posing: number;
}

/** Mel frames of context around a chunk: at least the convolutions' reach (manifest.receptive_field). */
const MEL_CONTEXT = 16;

/** Mel frames of context before a chunk's first content frame: the content encoder's look-back, at least
 * MEL_CONTEXT, rounded up to a whole content frame so the strided convolution lines up with the whole clip. */
function contentContextBack(manifest: Manifest): number {
  const stride = manifest.model.config.content_stride;
  return Math.ceil(Math.max(MEL_CONTEXT, manifest.receptive_field.content_mel_frames_back) / stride) * stride;
}

/** The most probable content class at each frame's content position (`post` holds content frames from cLo). */
function heardPhones(post: Float32Array, melIndex: number[], stride: number, classes: number, cLo: number): Uint8Array {
  return Uint8Array.from(melIndex, (k) => {
    const row = (Math.floor(k / stride) - cLo) * classes;
    let best = 0;
    for (let j = 1; j < classes; j++) if (post[row + j] > post[row + best]) best = j;
    return best;
  });
}

/** Frames of one chunk: posed vertices and I + O in the template's units, poses (axis-angle, mm). */
export interface Frames {
  count: number;
  vertices: Float32Array;
  unposed: Float32Array;
  pose: Float32Array;
  /** (count): the content class heard most at each frame (manifest.content_phones). */
  phones: Uint8Array;
}

/** What carries from one chunk to the next: the pose LSTM's state and the pose features still needed. */
export interface ProducerState {
  h: Float32Array;
  c: Float32Array;
  lstmDone: number;
  poseFeatures: Float32Array;
  poseFeaturesStart: number;
}

/** Resolve on a new task (not a microtask): lets the browser handle input, rendering and timers. */
export function yieldToEventLoop(): Promise<void> {
  return new Promise((resolve) => {
    const channel = new MessageChannel();
    channel.port1.onmessage = () => {
      channel.port1.close();
      resolve();
    };
    channel.port2.postMessage(null);
  });
}

function newProducerState(channels: number): ProducerState {
  return { h: new Float32Array(channels), c: new Float32Array(channels), lstmDone: 0, poseFeatures: new Float32Array(0), poseFeaturesStart: 0 };
}

export class TalkingFaceEngine {
  readonly times: StageTimes = { mel: 0, content: 0, hierarchical: 0, pose: 0, decoder: 0, posing: 0 };
  private gpu: GpuDecoder | null;
  private readonly cpu: FastDecoder;
  private reference: ReferenceDecoder | null = null;
  private pool: DecoderPool | null = null;
  private readonly templateMm: Float32Array;
  private readonly mmPerUnit: number;
  backend: Backend;
  /** Why the backend is what it is, for the status line. */
  backendReason: string;

  private constructor(
    readonly manifest: Manifest,
    readonly template: FaceTemplate,
    private readonly content: OnnxModel,
    private readonly hierarchical: OnnxModel,
    private readonly poseConv: OnnxModel,
    private readonly poseLstm: OnnxModel,
    cpu: FastDecoder,
    gpu: GpuDecoder | null,
    backendReason: string,
  ) {
    this.cpu = cpu;
    this.gpu = gpu;
    this.backend = gpu ? 'webgpu' : 'cpu';
    this.backendReason = backendReason;
    this.mmPerUnit = MM_PER_UNIT[template.units];
    this.templateMm = Float32Array.from(template.positions, (v) => v * this.mmPerUnit);
  }

  static async load(options: EngineOptions = {}): Promise<TalkingFaceEngine> {
    const fetchFn = options.fetch ?? fetch.bind(globalThis);
    const manifestUrl = new URL(String(options.manifestUrl ?? '/models/manifest.json'), globalThis.location?.href ?? 'file:///');
    const res = await fetchFn(manifestUrl).catch((e: Error) => {
      throw new ModelLoadError(`could not fetch the model manifest ${manifestUrl}: ${e.message}`);
    });
    if (!res.ok) throw new ModelLoadError(`could not fetch the model manifest ${manifestUrl}: HTTP ${res.status}`);
    let manifest: Manifest;
    try {
      manifest = checkManifest(await res.json());
    } catch (e) {
      throw new ModelLoadError(`the model manifest ${manifestUrl} is unreadable: ${(e as Error).message}`);
    }
    const file = async (key: string): Promise<ArrayBuffer> => {
      const url = new URL(manifest.files[key], manifestUrl);
      const r = await fetchFn(url);
      if (!r.ok) throw new ModelLoadError(`model file ${manifest.files[key]} is missing (HTTP ${r.status} for ${url})`);
      const bytes = await r.arrayBuffer();
      const digest = Array.from(new Uint8Array(await crypto.subtle.digest('SHA-256', bytes)), (b) => b.toString(16).padStart(2, '0')).join('');
      if (digest !== manifest.sha256[key]) throw new ModelLoadError(`model file ${manifest.files[key]} is corrupt or from another export (SHA-256 mismatch)`);
      return bytes;
    };
    const m = manifest.model.config;
    const a = manifest.audio;
    const [template, contentBytes, hierBytes, convBytes, lstmBytes, weightBytes] = await Promise.all([
      loadTemplate(options.templateUrl ? new URL(String(options.templateUrl), globalThis.location?.href ?? manifestUrl) : new URL(manifest.template.path, manifestUrl), fetchFn).catch((e: Error) => {
        throw new ModelLoadError(`the face template could not be loaded: ${e.message}`);
      }),
      file('content_encoder'), file('hierarchical'), file('pose_conv'), file('pose_lstm'), file('decoder_weights'),
    ]);
    if (template.id !== manifest.template.id) throw new ModelLoadError(`the model was trained on the face template "${manifest.template.id}" and cannot drive "${template.id}" (every template needs its own trained model)`);
    const support = await detectWebGPU();
    const hardwareGpu = Boolean(support.adapter && !support.info?.isFallbackAdapter);
    const providers = options.onnxProviders ?? (hardwareGpu ? ['webgpu', 'wasm'] : ['wasm']);
    const [content, hierarchical, poseConv, poseLstm] = await Promise.all([
      OnnxModel.create({ name: 'content_encoder', bytes: contentBytes, inputs: { mel: [1, 'K', a.n_mels] } }, providers),
      OnnxModel.create({ name: 'hierarchical', bytes: hierBytes, inputs: { windows: ['F', m.window, m.content_classes] } }, providers),
      OnnxModel.create({ name: 'pose_conv', bytes: convBytes, inputs: { mel: [1, 'K', a.n_mels] } }, providers),
      OnnxModel.create({ name: 'pose_lstm', bytes: lstmBytes, inputs: { conv: [1, 'K', m.pose_channels], h0: [1, 1, m.pose_channels], c0: [1, 1, m.pose_channels] } }, providers),
    ]);
    const weights = decoderWeights(parseSafetensors(weightBytes).tensors, m);
    const cpu = new FastDecoder(weights, template.adjacency, m);
    let gpu: GpuDecoder | null = null;
    let reason = 'CPU decoder chosen';
    const wantGpu = options.backend === 'webgpu' || ((options.backend ?? 'auto') === 'auto' && hardwareGpu);
    if (support.adapter && !hardwareGpu && options.backend !== 'webgpu') {
      reason = `the WebGPU adapter (${support.description}) is software, slower than the CPU path; using the CPU decoder`;
    }
    if (wantGpu) {
      if (support.adapter) {
        try {
          const device = await requestSharedDevice();
          gpu = new GpuDecoder(device, weights, template.adjacency, m, 96);
          reason = `WebGPU: ${support.description}`;
        } catch (e) {
          reason = `WebGPU device request failed (${(e as Error).message}); using the CPU decoder`;
        }
      } else {
        reason = `no WebGPU (${support.description}); using the CPU decoder`;
      }
      if (options.backend === 'webgpu' && !gpu) throw new ModelLoadError(`WebGPU was requested but is not available: ${reason}`);
    }
    const engine = new TalkingFaceEngine(manifest, template, content, hierarchical, poseConv, poseLstm, cpu, gpu, reason);
    const cores = globalThis.navigator?.hardwareConcurrency ?? 1;
    engine.pool = await DecoderPool.create(options.cpuWorkers ?? Math.min(4, cores), weights, template.adjacency, m);
    if (!engine.pool && cores > 1 && options.cpuWorkers === undefined) engine.backendReason += `; CPU decoder in the page's thread (${DecoderPool.lastFailure})`;
    gpu?.device.lost.then((info) => engine.deviceLost(gpu, info));
    return engine;
  }

  /** The decoder's weights (shared by the CPU and WebGPU decoders). */
  get decoderWeights(): DecoderWeights {
    return this.cpu.weights;
  }

  /** Template units per mm (the model works in mm; poses carry mm translations). */
  get unitsPerMm(): number {
    return 1 / this.mmPerUnit;
  }

  get fps(): number {
    return this.manifest.audio.fps;
  }

  /** Frames produced for `samples` samples: round(duration * fps). */
  frameCount(samples: number): number {
    return Math.max(1, Math.round((samples / this.manifest.audio.sample_rate) * this.fps));
  }

  /** The whole clip, chunk by chunk. `samples` must be mono at manifest.audio.sample_rate. */
  async animate(samples: Float32Array, options: AnimateOptions = {}): Promise<Animation> {
    const n = this.template.vertexCount;
    const F = this.frameCount(samples.length);
    const chunk = Math.max(1, options.chunkFrames ?? 96);
    const keep = options.keep ?? true;
    const vertices = keep ? new Float32Array(F * n * 3) : new Float32Array(0);
    const pose = new Float32Array(F * 6);
    const unposed = options.unposed ? new Float32Array(F * n * 3) : undefined;
    const phones = new Uint8Array(F);
    const state = newProducerState(this.manifest.model.config.pose_channels);
    for (let f0 = 0; f0 < F; f0 += chunk) {
      if (f0 > 0) await yieldToEventLoop(); // keep the page responsive through a long clip
      options.signal?.throwIfAborted();
      const f1 = Math.min(F, f0 + chunk);
      const out = await this.produce(state, f0, f1, samples, 0, samples.length);
      pose.set(out.pose, f0 * 6);
      if (keep) vertices.set(out.vertices, f0 * n * 3);
      unposed?.set(out.unposed, f0 * n * 3);
      phones.set(out.phones, f0);
      options.onFrames?.(f0, out.vertices, out.pose);
      options.onProgress?.(f1, F);
    }
    return { fps: this.fps, frames: F, vertices, pose, unposed, phones };
  }

  /**
   * The decoder's attention at one frame of a clip (layer 0-based; default the last, as the paper's
   * Fig. 7 reads the third): the pose token's weights over the vertices, and each vertex's over its
   * 1-ring. Computed by the reference decoder from exactly the tokens the animation used.
   */
  async attentionAt(samples: Float32Array, frame: number, layer = this.manifest.model.config.layers - 1): Promise<AttentionMaps> {
    const F = this.frameCount(samples.length);
    const f = Math.min(Math.max(0, Math.floor(frame)), F - 1);
    const inputs: { tokens?: Float32Array; poseToken?: Float32Array } = {};
    await this.produce(newProducerState(this.manifest.model.config.pose_channels), f, f + 1, samples, 0, samples.length, inputs);
    this.reference ??= new ReferenceDecoder(this.cpu.weights, this.template.adjacency, this.manifest.model.config);
    return this.reference.attention(inputs.tokens!, inputs.poseToken!, layer);
  }

  /** Streaming: push audio as it arrives, get frames as soon as their look-ahead has arrived. */
  createStream(onFrames: (first: number, frames: Frames) => void, options: { maxLagFrames?: number } = {}): StreamSession {
    return new StreamSession(this, onFrames, options.maxLagFrames);
  }

  /** Live: animate a MediaStream (e.g. from openMicrophone()) while it plays; stop() returns the take. */
  listen(media: MediaStream, onFrames: (first: number, frames: Frames) => void, options?: LiveOptions): Promise<LiveSession> {
    return LiveSession.start(this, media, onFrames, options);
  }

  /** Samples a frame needs before it can be computed exactly (its receptive field's last sample, exclusive). */
  samplesNeeded(frame: number): number {
    const a = this.manifest.audio;
    const m = this.manifest.model.config;
    const r = this.manifest.receptive_field;
    const mel = frameToMelIndex(frame, a);
    const lastContent = Math.floor(mel / m.content_stride) + m.window_future;
    const lastMel = Math.max(lastContent * m.content_stride + r.content_mel_frames, mel + r.pose_mel_frames);
    return lastMel * a.hop + a.frame_size / 2;
  }

  /**
   * Frames [f0, f1) of a signal of `total` samples (Infinity while streaming), of which `samples` holds
   * [offset, offset + samples.length). Exact whenever the samples cover every frame's receptive field.
   * @internal
   */
  async produce(state: ProducerState, f0: number, f1: number, samples: Float32Array, offset: number, total: number,
    inputs?: { tokens?: Float32Array; poseToken?: Float32Array }): Promise<Frames> {
    const a = this.manifest.audio;
    const m = this.manifest.model.config;
    const C = m.pose_channels;
    const K = Number.isFinite(total) ? melFrameCount(total, a) : Infinity;
    const Kc = Math.ceil(K / m.content_stride);
    const melIndex = Array.from({ length: f1 - f0 }, (_, i) => Math.min(frameToMelIndex(f0 + i, a), K - 1));
    // Content frames the windows need, and the Mel frames (with context) that produce them.
    const cLo = Math.max(0, Math.floor(melIndex[0] / m.content_stride) - (m.window - 1 - m.window_future));
    const cHi = Math.min(Kc, Math.floor(melIndex[melIndex.length - 1] / m.content_stride) + m.window_future + 1);
    const melLo = Math.max(0, cLo * m.content_stride - contentContextBack(this.manifest));
    const melHi = Math.min(K, Math.max(cHi * m.content_stride, melIndex[melIndex.length - 1] + 1) + MEL_CONTEXT);
    const signalEnd = Number.isFinite(total) ? total : offset + samples.length;
    let t = performance.now();
    const mel = logMelFrames(samples, a, melLo, melHi - melLo, undefined, offset, signalEnd);
    this.times.mel += performance.now() - t;

    t = performance.now();
    const logits = (await this.content.run({ mel: { data: mel, shape: [1, melHi - melLo, a.n_mels] } })).logits.data;
    // Content frame j of this run is the clip's content frame melLo / stride + j: melLo is 0 or a multiple
    // of the stride, so the strided convolution lines up with the whole-clip computation.
    const runOffset = melLo / m.content_stride;
    const post = softmaxRows(logits.slice((cLo - runOffset) * m.content_classes, (cHi - runOffset) * m.content_classes), m.content_classes);
    const windows = contentWindows(post, melIndex, m, cLo, Number.isFinite(Kc) ? Kc : undefined);
    const phones = heardPhones(post, melIndex, m.content_stride, m.content_classes, cLo);
    this.times.content += performance.now() - t;

    t = performance.now();
    const tokens = (await this.hierarchical.run({ windows: { data: windows, shape: [melIndex.length, m.window, m.content_classes] } })).tokens.data;
    this.times.hierarchical += performance.now() - t;

    // Pose: the LSTM advances over every Mel frame up to this chunk's last one, exactly once.
    t = performance.now();
    const need = melIndex[melIndex.length - 1] + 1;
    if (need > state.lstmDone) {
      const ctxLo = Math.max(0, state.lstmDone - MEL_CONTEXT);
      const ctxHi = Math.min(K, need + MEL_CONTEXT);
      const melPose = ctxLo >= melLo && ctxHi <= melHi
        ? mel.subarray((ctxLo - melLo) * a.n_mels, (ctxHi - melLo) * a.n_mels)
        : logMelFrames(samples, a, ctxLo, ctxHi - ctxLo, undefined, offset, signalEnd);
      const conv = (await this.poseConv.run({ mel: { data: melPose, shape: [1, ctxHi - ctxLo, a.n_mels] } })).conv.data;
      const fresh = conv.slice((state.lstmDone - ctxLo) * C, (need - ctxLo) * C);
      const out = await this.poseLstm.run({
        conv: { data: fresh, shape: [1, need - state.lstmDone, C] },
        h0: { data: state.h, shape: [1, 1, C] },
        c0: { data: state.c, shape: [1, 1, C] },
      });
      state.h = out.hn.data.slice();
      state.c = out.cn.data.slice();
      // Keep only the pose features this and later chunks can still ask for: from this chunk's first
      // Mel frame, or from where the LSTM stopped if that is earlier (new features start there).
      const keepFrom = Math.min(melIndex[0], state.lstmDone);
      const old = state.poseFeatures.subarray((keepFrom - state.poseFeaturesStart) * m.d_model);
      const merged = new Float32Array(old.length + out.pose_features.data.length);
      merged.set(old);
      merged.set(out.pose_features.data, old.length);
      state.poseFeaturesStart = keepFrom;
      state.poseFeatures = merged;
      state.lstmDone = need;
    }
    const poseToken = new Float32Array(melIndex.length * m.d_model);
    const pf = state.poseFeatures;
    melIndex.forEach((k, i) => poseToken.set(pf.subarray((k - state.poseFeaturesStart) * m.d_model, (k - state.poseFeaturesStart + 1) * m.d_model), i * m.d_model));
    this.times.pose += performance.now() - t;

    if (inputs) {
      inputs.tokens = tokens;
      inputs.poseToken = poseToken;
    }
    t = performance.now();
    const decoded = await this.decode(tokens, poseToken, melIndex.length);
    this.times.decoder += performance.now() - t;

    t = performance.now();
    const n3 = this.template.vertexCount * 3;
    const y = applyPose(this.templateMm, decoded.offsets, decoded.pose, melIndex.length);
    const unposed = new Float32Array(decoded.offsets.length);
    for (let i = 0; i < y.length; i++) {
      y[i] /= this.mmPerUnit;
      unposed[i] = (this.templateMm[i % n3] + decoded.offsets[i]) / this.mmPerUnit;
    }
    this.times.posing += performance.now() - t;
    return { count: melIndex.length, vertices: y, unposed, pose: decoded.pose, phones };
  }

  private async decode(tokens: Float32Array, poseToken: Float32Array, frames: number): Promise<DecodeResult> {
    if (this.gpu) {
      try {
        const out: DecodeResult = { offsets: new Float32Array(frames * this.template.vertexCount * 3), pose: new Float32Array(frames * 6) };
        const step = this.gpu.maxFrames;
        const n = this.template.vertexCount;
        const d = this.manifest.model.config.d_model;
        for (let i = 0; i < frames; i += step) {
          const j = Math.min(frames, i + step);
          const r = await this.gpu.decode(tokens.subarray(i * n * d, j * n * d), poseToken.subarray(i * d, j * d), j - i);
          out.offsets.set(r.offsets, i * n * 3);
          out.pose.set(r.pose, i * 6);
        }
        return out;
      } catch (e) {
        // The animation goes on: switch to the CPU decoder for this and every later chunk.
        this.gpu.destroy();
        this.gpu = null;
        this.backend = 'cpu';
        this.backendReason = `WebGPU failed (${(e as Error).message}); using the CPU decoder`;
      }
    }
    if (this.pool && frames > 1) {
      try {
        return await this.pool.decode(tokens, poseToken, frames);
      } catch (e) {
        // A crashed worker: decode in this thread from now on (same numbers), and say so.
        this.pool.terminate();
        this.pool = null;
        this.backendReason += `; the decoder workers failed (${(e as Error).message}), decoding in the page's thread`;
      }
    }
    return this.cpu.decode(tokens, poseToken, frames);
  }

  /** CPU decoder threads: the workers' count, or 1 when decoding in the page's thread. */
  get cpuThreads(): number {
    return this.pool?.size ?? 1;
  }

  /** The CPU decoder's arithmetic: 'wasm-simd' (WebAssembly SIMD) or 'js' (TypeScript, where SIMD is missing). */
  get cpuKernel(): string {
    return this.pool?.kernel ?? this.cpu.kernelName;
  }

  /** A lost device (driver reset, GPU process crash): carry on with the CPU decoder. */
  private deviceLost(decoder: GpuDecoder, info: GPUDeviceLostInfo): void {
    if (this.gpu !== decoder) return;
    this.gpu = null;
    this.backend = 'cpu';
    this.backendReason = `WebGPU device lost (${info.message || info.reason}); using the CPU decoder`;
  }

  /** Switch decoders at run time (the numbers are the same; only speed differs). */
  async setBackend(backend: Backend): Promise<void> {
    if (backend === this.backend) return;
    if (backend === 'cpu') {
      this.gpu?.destroy();
      this.gpu = null;
      this.backend = 'cpu';
      this.backendReason = 'CPU decoder chosen';
      return;
    }
    const support = await detectWebGPU();
    if (!support.adapter) throw new ModelLoadError(`WebGPU is not available: ${support.description}`);
    const device = await requestSharedDevice();
    const decoder = new GpuDecoder(device, this.cpu.weights, this.template.adjacency, this.manifest.model.config, 96);
    device.lost.then((info) => this.deviceLost(decoder, info));
    this.gpu = decoder;
    this.backend = 'webgpu';
    this.backendReason = `WebGPU: ${support.description}`;
  }

  /** The face the model makes in silence (I + O in the template's units, the last frame of a second of silence):
   * what a face shows before and between speech, instead of the template, whose mouth was opened for the lips
   * to part. Computed once. */
  restFace(): Promise<Float32Array> {
    const n3 = this.template.vertexCount * 3;
    this.rest ??= this.animate(new Float32Array(this.manifest.audio.sample_rate), { unposed: true })
      .then((a) => a.unposed!.slice((a.frames - 1) * n3, a.frames * n3));
    return this.rest;
  }

  private rest: Promise<Float32Array> | null = null;

  resetTimes(): void {
    for (const k of Object.keys(this.times) as (keyof StageTimes)[]) this.times[k] = 0;
  }
}

/**
 * Streaming inference: audio pushed in pieces of any size (an AudioWorklet's 128-sample quanta, a
 * network stream), frames emitted as soon as every sample of their receptive field has arrived, so
 * the output equals the offline animation of the same audio. `lookAheadMs` is the audio a frame
 * waits for beyond its own time; processing time comes on top.
 */
export class StreamSession {
  private buffer = new Float32Array(1 << 16);
  private offset = 0; // signal index of buffer[0]
  private received = 0; // samples received so far
  private next = 0; // next frame to produce
  private ended = false;
  private readonly state: ProducerState;
  private busy: Promise<void> = Promise.resolve();
  /** Arrival of recent pushes: the stream's sample count after the push, and the time (ms) it came. */
  private arrivals: { end: number; time: number }[] = [];
  private pending: Promise<void> | null = null;
  private latencies: number[] = [];

  /** Frames skipped to catch up (see maxLagFrames). */
  skippedFrames = 0;

  constructor(
    private readonly engine: TalkingFaceEngine,
    private readonly onFrames: (first: number, frames: Frames) => void,
    /**
     * Live use: when more than this many frames are ready but not yet computed (the device is slower
     * than real time), skip to the newest ones instead of falling further behind; the skipped frames
     * are never emitted (`first` jumps) and `skippedFrames` counts them. Default: never skip, so the
     * output equals the offline animation.
     */
    private readonly maxLagFrames = Infinity,
  ) {
    this.state = newProducerState(engine.manifest.model.config.pose_channels);
  }

  get lookAheadMs(): number {
    return ((this.engine.samplesNeeded(0) / this.engine.manifest.audio.sample_rate) * 1000);
  }

  get framesProduced(): number {
    return this.next;
  }

  get sampleRate(): number {
    return this.engine.manifest.audio.sample_rate;
  }

  /**
   * Measured latency of the frames emitted so far (the last 300): for each frame, the time from the
   * arrival of the audio sample at the frame's own instant to the frame's emission, in ms. It holds
   * the look-ahead, the size of the pieces pushed, and processing; not the audio hardware's own input
   * latency (an AudioContext's baseLatency), which comes before the samples reach push().
   */
  get latency(): { frames: number; lastMs: number; p50Ms: number; p95Ms: number } {
    const v = [...this.latencies].sort((a, b) => a - b);
    const at = (q: number) => (v.length ? v[Math.min(v.length - 1, Math.floor(q * v.length))] : NaN);
    return { frames: this.latencies.length, lastMs: this.latencies[this.latencies.length - 1] ?? NaN, p50Ms: at(0.5), p95Ms: at(0.95) };
  }

  /** Append mono samples at the model's rate; resolves when every frame they make ready has been emitted. */
  push(samples: Float32Array): Promise<void> {
    if (this.ended) throw new Error('StreamSession: push() after end()');
    this.append(samples);
    this.arrivals.push({ end: this.received, time: performance.now() });
    // Pushes that come while a drain runs share one follow-up drain: at most one waits, however fast
    // the pieces come. Each drain first yields to the event loop, so a page stays responsive (promise
    // continuations alone would starve input, rendering and timers).
    this.pending ??= this.schedule(async () => {
      await yieldToEventLoop();
      this.pending = null;
      await this.drain(false);
    });
    return this.pending;
  }

  /** No more audio: emit the remaining frames (the end of the clip is zero-padded, as offline). */
  end(): Promise<void> {
    this.ended = true;
    return this.schedule(() => this.drain(true));
  }

  private schedule(job: () => Promise<void>): Promise<void> {
    const run = this.busy.then(job);
    // Deliberate: the caller receives the run's error through `run`; `busy` only orders the runs.
    this.busy = run.catch(() => undefined);
    return run;
  }

  private append(samples: Float32Array): void {
    const used = this.received - this.offset;
    if (used + samples.length > this.buffer.length) {
      const bigger = new Float32Array(Math.max(2 * this.buffer.length, used + samples.length));
      bigger.set(this.buffer.subarray(0, used));
      this.buffer = bigger;
    }
    this.buffer.set(samples, used);
    this.received += samples.length;
  }

  private async drain(final: boolean): Promise<void> {
    const e = this.engine;
    const total = final ? this.received : Infinity;
    const last = final ? e.frameCount(this.received) : Infinity;
    let f1 = this.next;
    while (f1 < last && (final || e.samplesNeeded(f1) <= this.received)) f1++;
    if (!final && f1 - this.next > this.maxLagFrames) {
      const resume = f1 - Math.max(1, Math.floor(this.maxLagFrames / 4));
      this.skippedFrames += resume - this.next;
      this.next = resume;
    }
    for (let f0 = this.next; f0 < f1; f0 += 96) {
      const to = Math.min(f1, f0 + 96);
      const view = this.buffer.subarray(0, this.received - this.offset);
      const out = await e.produce(this.state, f0, to, view, this.offset, total);
      this.next = to;
      if (!final) this.measure(f0, to);
      this.onFrames(f0, out);
    }
    this.trim();
  }

  /** Record frames [f0, f1)'s latency: now minus the moment the sample at each frame's instant arrived. */
  private measure(f0: number, f1: number): void {
    const now = performance.now();
    const rate = this.engine.manifest.audio.sample_rate;
    for (let f = f0; f < f1; f++) {
      const sample = Math.round((f / this.engine.fps) * rate);
      while (this.arrivals.length > 1 && this.arrivals[0].end <= sample) this.arrivals.shift();
      const a = this.arrivals[0];
      if (!a || a.end <= sample) continue;
      // Pieces arrive when their last sample has been captured: the frame's sample came (end - sample) samples earlier.
      const captured = a.time - ((a.end - sample) / rate) * 1000;
      this.latencies.push(now - captured);
    }
    if (this.latencies.length > 300) this.latencies.splice(0, this.latencies.length - 300);
  }

  /** Forget audio no future frame can read: its content window's first frame, less the encoder's look-back. */
  private trim(): void {
    const { audio: a, model } = this.engine.manifest;
    const back = (model.config.window - model.config.window_future) * model.config.content_stride + contentContextBack(this.engine.manifest);
    const keepFrom = Math.max(0, (frameToMelIndex(this.next, a) - back) * a.hop - a.frame_size);
    if (keepFrom - this.offset > this.buffer.length / 2) {
      const drop = keepFrom - this.offset;
      this.buffer.copyWithin(0, drop, this.received - this.offset);
      this.offset = keepFrom;
    }
  }
}
