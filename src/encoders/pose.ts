/**
 * The pose branch (paper Fig. 2, "pose encoder"): log-Mel -> pose convolution (ONNX) -> LSTM (ONNX) whose state
 * carries from chunk to chunk -> one pose feature per Mel frame; the pose token of a frame is the feature at its
 * Mel frame. The LSTM advances over every Mel frame exactly once, so chunked and streaming runs equal the whole clip.
 */
import type { Manifest } from '../model/manifest';
import { OnnxModel, type ExecutionProvider } from './onnx-model';
import { specOf } from './onnx-spec';
import { allOrFree } from '../model/all-or-free';

/** What carries from one chunk to the next: the LSTM's state and the pose features still needed. */
export interface PoseState {
  h: Float32Array;
  c: Float32Array;
  /** Mel frames the LSTM has consumed. */
  lstmDone: number;
  poseFeatures: Float32Array;
  /** The Mel frame of poseFeatures' first row. */
  poseFeaturesStart: number;
}

export class PoseEncoder {
  private constructor(
    private readonly manifest: Manifest,
    private readonly conv: OnnxModel,
    private readonly lstm: OnnxModel,
  ) {}

  static async create(manifest: Manifest, files: Record<string, ArrayBuffer | Promise<ArrayBuffer>>, providers: ExecutionProvider[]): Promise<PoseEncoder> {
    const [conv, lstm] = await allOrFree([ // (one session failing frees the other)
      Promise.resolve(files.pose_conv).then((bytes) => OnnxModel.create(specOf(manifest, 'pose_conv', bytes), providers)),
      Promise.resolve(files.pose_lstm).then((bytes) => OnnxModel.create(specOf(manifest, 'pose_lstm', bytes), providers)),
    ]);
    return new PoseEncoder(manifest, conv, lstm);
  }

  /** Free both sessions (TalkingFaceEngine.dispose). */
  release(): Promise<void> {
    return Promise.all([this.conv.release(), this.lstm.release()]).then(() => undefined);
  }

  newState(): PoseState {
    const C = this.manifest.model.config.pose_channels;
    return { h: new Float32Array(C), c: new Float32Array(C), lstmDone: 0, poseFeatures: new Float32Array(0), poseFeaturesStart: 0 };
  }

  /** Mel frames of context the convolution needs before and after the frames it computes (its reach, plus one content frame). */
  get melContext(): { back: number; ahead: number } {
    const r = this.manifest.receptive_field;
    const margin = this.manifest.model.config.content_stride;
    return { back: r.pose_mel_frames_back + margin, ahead: r.pose_mel_frames + margin };
  }

  /**
   * Advance the LSTM to Mel frame `need` (exclusive). `mel(lo, hi)` returns log-Mel frames [lo, hi) of the clip;
   * K: the clip's Mel frames (Infinity while streaming). Keeps the features from `keepFrom` on.
   */
  async advance(state: PoseState, need: number, keepFrom: number, K: number, mel: (lo: number, hi: number) => Float32Array): Promise<void> {
    if (need <= state.lstmDone) return;
    const C = this.manifest.model.config.pose_channels;
    const d = this.manifest.model.config.d_model;
    const ctx = this.melContext;
    const lo = Math.max(0, state.lstmDone - ctx.back);
    const hi = Math.min(K, need + ctx.ahead);
    const conv = (await this.conv.run({ mel: { data: mel(lo, hi), shape: [1, hi - lo, this.manifest.audio.n_mels] } })).conv.data;
    const fresh = conv.slice((state.lstmDone - lo) * C, (need - lo) * C);
    const out = await this.lstm.run({
      conv: { data: fresh, shape: [1, need - state.lstmDone, C] },
      h0: { data: state.h, shape: [1, 1, C] },
      c0: { data: state.c, shape: [1, 1, C] },
    });
    state.h = out.hn.data.slice();
    state.c = out.cn.data.slice();
    // Keep only the features this and later chunks can still ask for: from keepFrom, or from where the LSTM
    // stopped if that is earlier (new features start there).
    const from = Math.min(keepFrom, state.lstmDone);
    const old = state.poseFeatures.subarray((from - state.poseFeaturesStart) * d);
    const merged = new Float32Array(old.length + out.pose_features.data.length);
    merged.set(old);
    merged.set(out.pose_features.data, old.length);
    state.poseFeaturesStart = from;
    state.poseFeatures = merged;
    state.lstmDone = need;
  }

  /** The pose token of each frame (frames x d): the feature at its Mel frame. */
  tokens(state: PoseState, melIndex: number[]): Float32Array {
    const d = this.manifest.model.config.d_model;
    const out = new Float32Array(melIndex.length * d);
    const pf = state.poseFeatures;
    melIndex.forEach((k, i) => out.set(pf.subarray((k - state.poseFeaturesStart) * d, (k - state.poseFeaturesStart + 1) * d), i * d));
    return out;
  }
}
