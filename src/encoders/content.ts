/**
 * The content branch (paper Fig. 2, "audio encoder"): log-Mel -> content encoder (ONNX, phone logits every
 * content_stride Mel frames) -> softmax -> each animation frame's window of posteriors -> the hierarchical
 * encoder (ONNX) -> its latents, of which the decoder makes one token per vertex. The model's stand-in for
 * DeepSpeech: what it heard, per frame.
 */
import type { Manifest, ModelConstants } from '../model/manifest';
import { contentWindows, softmaxRows } from './windows';
import { OnnxModel, type ExecutionProvider } from './onnx-model';
import { specOf } from './onnx-spec';
import { melFlatness, speechProbabilities } from './voice-activity';
import { melBandWidths } from '../audio/mel';
import { allOrFree } from '../model/all-or-free';

/** Content frames [lo, hi) and the Mel frames [melLo, melHi) that compute them exactly. */
export interface ContentRange {
  lo: number;
  hi: number;
  melLo: number;
  melHi: number;
}

/**
 * The phones that raise the tongue's tip to the ridge behind the upper teeth (ARPAbet: /t d n l/ and the dental
 * fricatives /th/ (TH) and /dh/ (DH)). Their posteriors, summed, say how raised the tongue is at a frame.
 */
export const TONGUE_RAISING_PHONES = ['T', 'D', 'N', 'L', 'TH', 'DH'];

export class ContentEncoder {
  private readonly m: ModelConstants;
  /** Indices of TONGUE_RAISING_PHONES among manifest.content_phones (names the manifest lacks are skipped). */
  private readonly tongueClasses: number[];
  /** The silence class (voice-activity.ts), or -1 for a model without one (every frame then counts as speech). */
  private readonly silence: number;

  private constructor(
    private readonly manifest: Manifest,
    private readonly content: OnnxModel,
    private readonly hierarchical: OnnxModel,
  ) {
    this.m = manifest.model.config;
    this.tongueClasses = TONGUE_RAISING_PHONES.map((p) => manifest.content_phones.indexOf(p)).filter((k) => k >= 0);
    this.silence = manifest.content_phones.indexOf('SIL');
  }

  static async create(manifest: Manifest, files: Record<string, ArrayBuffer | Promise<ArrayBuffer>>, providers: ExecutionProvider[]): Promise<ContentEncoder> {
    const [content, hierarchical] = await allOrFree([ // (one session failing frees the other)
      Promise.resolve(files.content_encoder).then((bytes) => OnnxModel.create(specOf(manifest, 'content_encoder', bytes), providers)),
      Promise.resolve(files.hierarchical).then((bytes) => OnnxModel.create(specOf(manifest, 'hierarchical', bytes), providers)),
    ]);
    return new ContentEncoder(manifest, content, hierarchical);
  }

  /** Free both sessions (TalkingFaceEngine.dispose). */
  release(): Promise<void> {
    return Promise.all([this.content.release(), this.hierarchical.release()]).then(() => undefined);
  }

  /**
   * Mel frames of context before a range's first content frame: the encoder's look-back, rounded up to a
   * whole content frame so the strided convolution lines up with the whole clip.
   */
  get melBack(): number {
    const stride = this.m.content_stride;
    return Math.ceil(this.manifest.receptive_field.content_mel_frames_back / stride) * stride;
  }

  /** Mel frames read past a content frame's first Mel frame (its look-ahead), plus one content frame of margin. */
  get melAhead(): number {
    return this.manifest.receptive_field.content_mel_frames + this.m.content_stride;
  }

  /** The content frames the windows of frames at `melIndex` read, and the Mel frames they need (K: Mel frames in the clip). */
  range(melIndex: number[], K: number): ContentRange {
    const m = this.m;
    const Kc = Math.ceil(K / m.content_stride);
    const lo = Math.max(0, Math.floor(melIndex[0] / m.content_stride) - (m.window - 1 - m.window_future));
    const hi = Math.min(Kc, Math.floor(melIndex[melIndex.length - 1] / m.content_stride) + m.window_future + 1);
    const melLo = Math.max(0, lo * m.content_stride - this.melBack);
    const melHi = Math.min(K, Math.max(hi * m.content_stride, melIndex[melIndex.length - 1] + 1) + this.melAhead);
    return { lo, hi, melLo, melHi };
  }

  /** Phone posteriors (content frames r.lo..r.hi x classes) from the Mel frames r.melLo..r.melHi. */
  async posteriors(mel: Float32Array, r: ContentRange): Promise<Float32Array> {
    const m = this.m;
    const logits = (await this.content.run({ mel: { data: mel, shape: [1, r.melHi - r.melLo, this.manifest.audio.n_mels] } })).logits.data;
    // Content frame j of this run is the clip's content frame melLo / stride + j: melLo is 0 or a multiple
    // of the stride, so the strided convolution lines up with the whole-clip computation.
    const runOffset = r.melLo / m.content_stride;
    return softmaxRows(logits.slice((r.lo - runOffset) * m.content_classes, (r.hi - runOffset) * m.content_classes), m.content_classes);
  }

  /** Each frame's window of posteriors (frames x window x classes); K: the clip's Mel frames (Infinity while streaming). */
  windows(post: Float32Array, melIndex: number[], r: ContentRange, K: number): Float32Array {
    const Kc = Math.ceil(K / this.m.content_stride);
    return contentWindows(post, melIndex, this.m, r.lo, Number.isFinite(Kc) ? Kc : undefined);
  }

  /** The most probable content class at each frame's content position (names: manifest.content_phones). */
  heardPhones(post: Float32Array, melIndex: number[], r: ContentRange): Uint8Array {
    const { content_stride: stride, content_classes: classes } = this.m;
    return Uint8Array.from(melIndex, (k) => {
      const row = (Math.floor(k / stride) - r.lo) * classes;
      let best = 0;
      for (let j = 1; j < classes; j++) if (post[row + j] > post[row + best]) best = j;
      return best;
    });
  }

  /** Each frame's row of posteriors (frames x classes), at the content position heardPhones reads. */
  framePosteriors(post: Float32Array, melIndex: number[], r: ContentRange): Float32Array {
    const { content_stride: stride, content_classes: classes } = this.m;
    const out = new Float32Array(melIndex.length * classes);
    melIndex.forEach((k, i) => {
      const row = (Math.floor(k / stride) - r.lo) * classes;
      out.set(post.subarray(row, row + classes), i * classes);
    });
    return out;
  }

  /**
   * How raised the tongue is at each frame, 0..1: the summed posteriors of TONGUE_RAISING_PHONES at the frame's
   * content position (what a renderer draws the tongue from; the face model itself does not move a tongue).
   */
  tongueRaise(post: Float32Array, melIndex: number[], r: ContentRange): Float32Array {
    const { content_stride: stride, content_classes: classes } = this.m;
    return Float32Array.from(melIndex, (k) => {
      const row = (Math.floor(k / stride) - r.lo) * classes;
      let s = 0;
      for (const j of this.tongueClasses) s += post[row + j];
      return Math.min(1, s);
    });
  }

  /**
   * Each frame's speech probability (voice-activity.ts): 1 - P(SIL) at its content position, 0 where its `level`
   * (RMS) is too low or its Mel frame (`mel`: frames r.melLo..r.melHi) is as flat as noise.
   */
  speechProbability(post: Float32Array, mel: Float32Array, melIndex: number[], r: ContentRange, level: number[]): Float32Array {
    if (this.silence < 0) return new Float32Array(melIndex.length).fill(1);
    const bands = this.manifest.audio.n_mels;
    const widths = melBandWidths(this.manifest.audio);
    const flatness = melIndex.map((k) => melFlatness(mel.subarray((k - r.melLo) * bands, (k - r.melLo + 1) * bands), widths));
    return speechProbabilities(post, this.m.content_classes, this.silence, melIndex.map((k) => Math.floor(k / this.m.content_stride) - r.lo), level, flatness);
  }

  /**
   * The hierarchical encoder's part that is one per frame: windows (frames x window x classes) -> latents
   * (frames x 2d, [a, g]); the decoder makes each vertex's token of them (reference.ts vertexTokens).
   */
  async latents(windows: Float32Array, frames: number): Promise<Float32Array> {
    const m = this.m;
    return (await this.hierarchical.run({ windows: { data: windows, shape: [frames, m.window, m.content_classes] } })).latents.data;
  }
}
