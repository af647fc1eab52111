/**
 * One chunk of the pipeline (paper Fig. 2): samples -> log-Mel -> content encoder -> windows -> the hierarchical
 * feature's latents; log-Mel -> pose encoder (state carried) -> pose token; both -> the attention decoder (which
 * makes the vertex tokens of the latents) -> posing.
 *
 * Every chunk recomputes the Mel and content frames it needs with enough context on each side that the result
 * equals the whole-clip computation exactly, so memory holds one chunk of intermediates whatever the clip's length.
 */
import { frameToMelIndex, type Manifest } from '../model/manifest';
import { logMelFrames, melFrameCount } from '../audio/mel';
import type { ContentEncoder } from '../encoders/content';
import type { PoseEncoder, PoseState } from '../encoders/pose';
import { EngineDisposedError, type DecoderBackends } from './backends';
import { poseFrames } from '../pose/posing';
import type { HeadMotion, HeadMotionState } from '../pose/head-motion';
import { levelAt } from '../encoders/voice-activity';
import { MM_PER_UNIT, type FaceTemplate } from '../template/face-template';
import { emptyBlendshapes, type Animation, type Frames, type StageTimes } from './frames';
import { AvatarWeights, yawPitchRoll } from '../avatar/weights';
import { ARKIT_NAMES } from '../avatar/names';
import { LipClosure } from './lip-closure';
import type { SolverState } from '../avatar/solver';

/** Frames per chunk when the caller does not say: bounds memory and the WebGPU decoder's buffers. */
export const DEFAULT_CHUNK_FRAMES = 96;

/** Frames posed at a time by holdRest. */
const HOLD_FRAMES = 256;

/**
 * What carries from one chunk to the next: the pose encoder's LSTM state and features, the head motion's last
 * residuals, and, when the frames carry ARKit weights, the solver's warm start.
 */
export type ProducerState = PoseState & { head?: HeadMotionState; headScale?: number; headSeed?: number | null; blendshapes?: SolverState };

/** What a new state computes besides the face: `blendshapes` (the avatar stage), and its own head-motion scale. */
export interface StateOptions {
  blendshapes?: boolean;
  /** Multiplies the head's own motion for this state's frames (default: the pipeline's headScale). */
  headMotionScale?: number;
}

export class Pipeline {
  readonly times: StageTimes = { mel: 0, content: 0, hierarchical: 0, pose: 0, decoder: 0, posing: 0, blendshapes: 0 };
  readonly mmPerUnit: number;
  readonly templateMm: Float32Array;
  /** The seed of the head's own motion (new states draw with it); null: the pose head's mean pose alone. */
  headSeed: number | null = 0;
  /** How far the head's own motion turns the head: 1 as fitted (the corpus's typical speaker), below calmer, above livelier. */
  headScale = 1;
  private avatar: AvatarWeights | null = null;
  private restWeights: Promise<Float32Array> | null = null;
  private rest: Promise<{ face: Float32Array; pose: Float32Array }> | null = null;
  private closure: LipClosure | null | undefined;
  /** dispose() was called: everything that runs the model is refused (EngineDisposedError). */
  disposed = false;

  constructor(
    readonly manifest: Manifest,
    readonly template: FaceTemplate,
    readonly content: ContentEncoder,
    readonly pose: PoseEncoder,
    readonly decoders: DecoderBackends,
    /** The head's own motion added to the mean pose, or null for a model exported without it. */
    readonly headMotion: HeadMotion | null,
  ) {
    this.mmPerUnit = MM_PER_UNIT[template.units];
    this.templateMm = Float32Array.from(template.positions, (v) => v * this.mmPerUnit);
  }

  get fps(): number {
    return this.manifest.audio.fps;
  }

  /** Frames produced for `samples` samples: round(duration * fps), a half to the even neighbour as Python's round()
   * (training's frame counts: fixtures.py, reserved.py; 0.15 s at 30 fps is 4 frames there, and was 5 here). */
  frameCount(samples: number): number {
    const x = (samples / this.manifest.audio.sample_rate) * this.fps;
    const r = Math.round(x);
    return Math.max(1, r - x === 0.5 && r % 2 !== 0 ? r - 1 : r);
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

  /** Audio samples before frame `next`'s Mel frame that no later frame reads (for a stream to forget). */
  samplesBehind(next: number): number {
    const { audio: a, model } = this.manifest;
    const back = (model.config.window - model.config.window_future) * model.config.content_stride + this.content.melBack;
    return Math.max(0, (frameToMelIndex(next, a) - back) * a.hop - a.frame_size);
  }

  /** `blendshapes`: the frames also carry ARKit weights, visemes and head rotations (the avatar stage). */
  newState(options: StateOptions = {}): ProducerState {
    const state: ProducerState = this.pose.newState();
    if (options.blendshapes) state.blendshapes = this.avatarWeights.newState();
    state.headScale = options.headMotionScale ?? this.headScale;
    state.headSeed = this.headSeed; // (a seed set later is for later animations: this one's head does not jump)
    return state;
  }

  /** Free the encoders' sessions and the decoders (TalkingFaceEngine.dispose); later runs are refused. */
  async dispose(): Promise<void> {
    if (this.disposed) return;
    this.disposed = true;
    this.decoders.dispose();
    await Promise.all([this.content.release(), this.pose.release()]);
  }

  /** The model's closure on the face's own lip gap (null: a model exported without it), built on first use. */
  get lipClosure(): LipClosure | null {
    const c = this.manifest.lip_closure;
    if (this.closure === undefined) this.closure = c ? new LipClosure(this.template, c.reference_gap_mm, c.mouth_gain ?? 1) : null;
    return this.closure;
  }

  /** The avatar stage, built on first use (the ARKit basis of the template: a few hundred ms). */
  get avatarWeights(): AvatarWeights {
    this.avatar ??= new AvatarWeights(this.template, this.manifest.content_phones);
    return this.avatar;
  }

  /**
   * The face the model makes in silence (I + O in the template's units) and its head pose (the mean pose, without
   * the head's own motion): the last frame of a second of silence, on a state of its own. What a face shows before
   * and between speech. Computed once; the caller must not change them.
   */
  restFrame(): Promise<{ face: Float32Array; pose: Float32Array }> {
    if (this.disposed) return Promise.reject(new EngineDisposedError()); // (computed before, as when not)
    this.rest ??= (async () => {
      const silence = new Float32Array(this.manifest.audio.sample_rate);
      const F = this.frameCount(silence.length);
      const frames = await this.produce(this.newState({ headMotionScale: 0 }), 0, F, silence, 0, silence.length);
      const n3 = this.template.vertexCount * 3;
      return { face: frames.unposed.slice((F - 1) * n3, F * n3), pose: frames.pose.slice((F - 1) * 6, F * 6) };
    })().catch((e: unknown) => {
      this.rest = null; // not kept: the next call tries again
      throw e;
    });
    return this.rest;
  }

  restFace(): Promise<Float32Array> {
    return this.restFrame().then((r) => r.face);
  }

  /**
   * `frames` frames of the face at rest, the head still at the pose of silence (restFrame), made without running
   * the model on them: what a silent clip is.
   */
  async restAnimation(frames: number, options: { keep?: boolean; unposed?: boolean; blendshapes?: boolean }): Promise<Animation> {
    const n3 = this.template.vertexCount * 3;
    const rest = await this.restFrame();
    const pose = new Float32Array(frames * 6);
    for (let f = 0; f < frames; f++) pose.set(rest.pose, f * 6);
    const silence = Math.max(0, this.manifest.content_phones.indexOf('SIL'));
    const animation: Animation = {
      fps: this.fps, frames, pose, vertices: new Float32Array(options.keep ?? true ? frames * n3 : 0),
      unposed: options.unposed ? new Float32Array(frames * n3) : undefined, phones: new Uint8Array(frames).fill(silence),
      tongue: new Float32Array(frames), speech: new Float32Array(frames),
      blendshapes: options.blendshapes ? emptyBlendshapes(frames) : undefined,
    };
    for (let f = 0; f < frames && animation.blendshapes; f++) yawPitchRoll(pose, f * 6, animation.blendshapes.headRotation, f * 3);
    await this.holdRest(animation); // the face, and the blend shapes' weights and visemes
    return animation;
  }

  /**
   * The face at rest on every frame of `animation` (its head poses kept), in place; with blend shapes, the ARKit
   * weights of the rest (restArkit) and the visemes at viseme_sil. Posed a few hundred frames at a time: an hour's
   * clip needs no copy of its frames.
   */
  async holdRest(animation: Animation): Promise<void> {
    const rest = this.offsetsOf(await this.restFace());
    const n3 = rest.length;
    const step = Math.min(HOLD_FRAMES, animation.frames);
    const offsets = new Float32Array(step * n3);
    for (let f = 0; f < step; f++) offsets.set(rest, f * n3);
    for (let f0 = 0; f0 < animation.frames; f0 += step) {
      const count = Math.min(step, animation.frames - f0);
      const posed = poseFrames(this.templateMm, offsets.subarray(0, count * n3), animation.pose.subarray(f0 * 6, (f0 + count) * 6), count, this.mmPerUnit);
      if (animation.vertices.length) animation.vertices.set(posed.vertices, f0 * n3);
      animation.unposed?.set(posed.unposed, f0 * n3);
    }
    animation.tongue.fill(0); // at rest, as in silence
    const b = animation.blendshapes;
    if (b) {
      const arkit = await this.restArkit();
      for (let f = 0; f < animation.frames; f++) b.arkit.set(arkit, f * arkit.length);
      b.visemes.fill(0);
      const V = b.visemes.length / animation.frames;
      for (let f = 0; f < animation.frames; f++) b.visemes[f * V] = 1; // viseme_sil, the first of VISEME_NAMES
    }
  }

  /**
   * The 52 ARKit weights of the face at rest (restFace through the avatar stage's solver: what every frame of silence
   * gets, the solver's minimiser being unique). Computed once; the caller must not change it.
   */
  restArkit(): Promise<Float32Array> {
    if (this.disposed) return Promise.reject(new EngineDisposedError());
    this.restWeights ??= this.restFace().then((rest) => {
      const out = new Float32Array(ARKIT_NAMES.length);
      this.avatarWeights.solver.solve(this.offsetsOf(rest), 0, this.avatarWeights.newState(), out);
      return out;
    }, (e: unknown) => {
      this.restWeights = null; // not kept, as restFace's failure is not
      throw e;
    });
    return this.restWeights;
  }

  /** The displacement O (mm) of a face `unposed` (template units): what the decoder and the solver work in. */
  private offsetsOf(unposed: Float32Array): Float32Array {
    return Float32Array.from(unposed, (x, i) => x * this.mmPerUnit - this.templateMm[i]);
  }

  /**
   * Frames [f0, f1) of a signal of `total` samples (Infinity while streaming), of which `samples` holds
   * [offset, offset + samples.length). Exact whenever the samples cover every frame's receptive field.
   * `inputs` receives the decoder's inputs (vertex and pose tokens) when given.
   */
  async produce(state: ProducerState, f0: number, f1: number, samples: Float32Array, offset: number, total: number,
    inputs?: { tokens?: Float32Array; poseToken?: Float32Array }): Promise<Frames> {
    if (this.disposed) throw new EngineDisposedError();
    try {
      return await this.frames(state, f0, f1, samples, offset, total, inputs);
    } catch (e) {
      throw this.disposed ? new EngineDisposedError() : e; // a session released under the work: dispose(), no failure
    }
  }

  private async frames(state: ProducerState, f0: number, f1: number, samples: Float32Array, offset: number, total: number,
    inputs?: { tokens?: Float32Array; poseToken?: Float32Array }): Promise<Frames> {
    const a = this.manifest.audio;
    const K = Number.isFinite(total) ? melFrameCount(total, a) : Infinity;
    const melIndex = Array.from({ length: f1 - f0 }, (_, i) => Math.min(frameToMelIndex(f0 + i, a), K - 1));
    const signalEnd = Number.isFinite(total) ? total : offset + samples.length;
    const range = this.content.range(melIndex, K);
    let t = performance.now();
    const mel = logMelFrames(samples, a, range.melLo, range.melHi - range.melLo, undefined, offset, signalEnd);
    this.times.mel += performance.now() - t;

    t = performance.now();
    const post = await this.content.posteriors(mel, range);
    const windows = this.content.windows(post, melIndex, range, K);
    const phones = this.content.heardPhones(post, melIndex, range);
    const tongue = this.content.tongueRaise(post, melIndex, range);
    const level = melIndex.map((k) => levelAt(samples, offset, k * a.hop, a.frame_size));
    const speech = this.content.speechProbability(post, mel, melIndex, range, level);
    this.times.content += performance.now() - t;

    t = performance.now();
    const latents = await this.content.latents(windows, melIndex.length);
    this.times.hierarchical += performance.now() - t;

    // Pose: the LSTM advances over every Mel frame up to this chunk's last one, exactly once.
    t = performance.now();
    const melOf = (lo: number, hi: number) => lo >= range.melLo && hi <= range.melHi
      ? mel.subarray((lo - range.melLo) * a.n_mels, (hi - range.melLo) * a.n_mels)
      : logMelFrames(samples, a, lo, hi - lo, undefined, offset, signalEnd);
    await this.pose.advance(state, melIndex[melIndex.length - 1] + 1, melIndex[0], K, melOf);
    const poseToken = this.pose.tokens(state, melIndex);
    this.times.pose += performance.now() - t;

    if (inputs) {
      inputs.tokens = this.decoders.vertexTokens(latents, melIndex.length);
      inputs.poseToken = poseToken;
    }
    t = performance.now();
    const decoded = await this.decoders.decode(latents, poseToken, melIndex.length, this.template.vertexCount);
    this.times.decoder += performance.now() - t;

    t = performance.now();
    this.lipClosure?.apply(decoded.offsets, melIndex.length, this.template.vertexCount);
    const seed = state.headSeed === undefined ? this.headSeed : state.headSeed;
    if (this.headMotion && seed !== null) {
      state.head ??= this.headMotion.start(seed);
      const residual = this.headMotion.residuals(state.head, f0, poseToken, melIndex.length);
      this.headMotion.compose(decoded.pose, residual, melIndex.length, state.headScale ?? this.headScale);
    }
    const { vertices, unposed } = poseFrames(this.templateMm, decoded.offsets, decoded.pose, melIndex.length, this.mmPerUnit);
    this.times.posing += performance.now() - t;
    const frames: Frames = { count: melIndex.length, vertices, unposed, pose: decoded.pose, phones, tongue, speech };
    if (state.blendshapes) {
      t = performance.now();
      const posteriors = this.content.framePosteriors(post, melIndex, range);
      frames.blendshapes = this.avatarWeights.frames(state.blendshapes, decoded.offsets, decoded.pose, posteriors, frames.count);
      this.times.blendshapes += performance.now() - t;
    }
    return frames;
  }
}
