/**
 * The GAVA decoder on the CPU, in plain TypeScript: the readable reference that the WGSL kernel
 * is tested against, and the fallback where WebGPU is missing. Same layers as
 * training/src/talkingface/model (pre-norm transformer; paper Eq. 1 with the augmented adjacency):
 *
 *   x = x + Wo · Attn(LN1 x)      vertex j attends to itself and its 1-ring; the pose token to all
 *   x = x + W2 · gelu(W1 · LN2 x)
 *   then LN, displacement head (d -> 3, mm) per vertex, pose head (d -> 6) on the pose token.
 */
import { f32, type Tensor } from '../model/safetensors';
import type { ModelConstants } from '../model/manifest';
import type { Adjacency } from '../template/mesh-topology';

export interface LayerWeights {
  ln1g: Float32Array; ln1b: Float32Array;
  qkvW: Float32Array; qkvB: Float32Array; // (3d x d), (3d)
  outW: Float32Array; outB: Float32Array; // (d x d), (d)
  ln2g: Float32Array; ln2b: Float32Array;
  ffn1W: Float32Array; ffn1B: Float32Array; // (ffn x d)
  ffn2W: Float32Array; ffn2B: Float32Array; // (d x ffn)
}

export interface DecoderWeights {
  layers: LayerWeights[];
  lnG: Float32Array; lnB: Float32Array;
  dispW: Float32Array; dispB: Float32Array; // (3 x d)
  poseW: Float32Array; poseB: Float32Array; // (6 x d)
  /**
   * The hierarchical feature's per-vertex part (paper Sec. III-C): vertex j's token is
   * localOut(gelu(a + e_j)) + g, from the frame's latents [a, g] (hierarchical.onnx). e: (N x d).
   */
  vertexEmbedding: Float32Array;
  localOutW: Float32Array; localOutB: Float32Array; // (d x d), (d)
  /** The LayerNorms' epsilon (manifest.model.layer_norm_eps). */
  lnEps: number;
}

/** Pick the decoder's tensors out of gava.safetensors, checking every shape against the model constants. */
/** `eps`: the LayerNorms' epsilon (manifest.model.layer_norm_eps). */
export function decoderWeights(t: Map<string, Tensor>, m: ModelConstants, eps: number): DecoderWeights {
  const d = m.d_model;
  const layers: LayerWeights[] = [];
  for (let i = 0; i < m.layers; i++) {
    const p = `decoder.blocks.${i}.`;
    layers.push({
      ln1g: f32(t, p + 'ln1.weight', [d]), ln1b: f32(t, p + 'ln1.bias', [d]),
      qkvW: f32(t, p + 'attn.qkv.weight', [3 * d, d]), qkvB: f32(t, p + 'attn.qkv.bias', [3 * d]),
      outW: f32(t, p + 'attn.out.weight', [d, d]), outB: f32(t, p + 'attn.out.bias', [d]),
      ln2g: f32(t, p + 'ln2.weight', [d]), ln2b: f32(t, p + 'ln2.bias', [d]),
      ffn1W: f32(t, p + 'ffn.0.weight', [m.ffn, d]), ffn1B: f32(t, p + 'ffn.0.bias', [m.ffn]),
      ffn2W: f32(t, p + 'ffn.2.weight', [d, m.ffn]), ffn2B: f32(t, p + 'ffn.2.bias', [d]),
    });
  }
  return {
    layers,
    lnG: f32(t, 'decoder.ln.weight', [d]), lnB: f32(t, 'decoder.ln.bias', [d]),
    dispW: f32(t, 'displacement_head.weight', [3, d]), dispB: f32(t, 'displacement_head.bias', [3]),
    poseW: f32(t, 'pose_head.weight', [6, d]), poseB: f32(t, 'pose_head.bias', [6]),
    vertexEmbedding: f32(t, 'hierarchical.vertex_embedding', [t.get('hierarchical.vertex_embedding')?.shape[0] ?? 0, d]),
    localOutW: f32(t, 'hierarchical.local_out.weight', [d, d]), localOutB: f32(t, 'hierarchical.local_out.bias', [d]),
    lnEps: eps,
  };
}

/** Why weights cannot make the vertex tokens of an N-vertex mesh (their vertex embedding is another mesh's), or null. */
export function vertexEmbeddingMismatch(w: DecoderWeights, n: number, d: number): string | null {
  const have = w.vertexEmbedding.length / d;
  return have === n ? null : `the decoder weights' vertex embedding has ${have} vertices, the template ${n}: they are of different meshes`;
}

/**
 * The vertex tokens (F x N x d) of frames' hierarchical latents (F x 2d: [a, g], hierarchical.onnx's output):
 * token j = localOut(gelu(a + e_j)) + g, exact GELU. The readable form FastDecoder.decodeLatents is held to.
 */
export function vertexTokens(w: DecoderWeights, latents: Float32Array, frames: number, d: number): Float32Array {
  const n = w.vertexEmbedding.length / d;
  const tokens = new Float32Array(frames * n * d);
  const h = new Float32Array(d);
  for (let f = 0; f < frames; f++) {
    const a = f * 2 * d, g = a + d;
    for (let j = 0; j < n; j++) {
      for (let i = 0; i < d; i++) h[i] = gelu(latents[a + i] + w.vertexEmbedding[j * d + i]);
      const o = (f * n + j) * d;
      linear(w.localOutW, w.localOutB, d, d, h, 0, tokens, o);
      for (let i = 0; i < d; i++) tokens[o + i] += latents[g + i];
    }
  }
  return tokens;
}

/** erf by Abramowitz & Stegun 7.1.26 (|error| < 1.5e-7); the WGSL kernel uses the same formula. */
export function erf(x: number): number {
  const s = Math.sign(x);
  const a = Math.abs(x);
  const t = 1 / (1 + 0.3275911 * a);
  const y = 1 - ((((1.061405429 * t - 1.453152027) * t + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * Math.exp(-a * a);
  return s * y;
}

/** GELU, exact form (PyTorch's nn.GELU default): x/2 (1 + erf(x / sqrt 2)). */
export function gelu(x: number): number {
  return 0.5 * x * (1 + erf(x * Math.SQRT1_2));
}

function layerNorm(x: Float32Array, off: number, d: number, g: Float32Array, b: Float32Array, out: Float32Array, outOff: number, eps: number): void {
  let mean = 0;
  for (let i = 0; i < d; i++) mean += x[off + i];
  mean /= d;
  let v = 0;
  for (let i = 0; i < d; i++) v += (x[off + i] - mean) ** 2;
  const inv = 1 / Math.sqrt(v / d + eps);
  for (let i = 0; i < d; i++) out[outOff + i] = (x[off + i] - mean) * inv * g[i] + b[i];
}

/** out[o] = W[o, :] . x + b[o] for a (rows x cols) row-major W. */
function linear(W: Float32Array, b: Float32Array, rows: number, cols: number, x: Float32Array, xOff: number, out: Float32Array, outOff: number): void {
  for (let o = 0; o < rows; o++) {
    let s = b[o];
    const w = o * cols;
    for (let i = 0; i < cols; i++) s += W[w + i] * x[xOff + i];
    out[outOff + o] = s;
  }
}

export interface DecodeResult {
  offsets: Float32Array; // (F x N x 3) mm
  pose: Float32Array; // (F x 6) axis-angle (rad), translation (mm)
}

/**
 * The keys each token attends to, as one CSR list: vertex t -> [t, its 1-ring...] (the augmented
 * adjacency M~); with `poseToken`, token N (the pose token) -> every token 0..N.
 */
export function keyLists(adjacency: Adjacency, poseToken: boolean): { keyStart: Int32Array; keys: Int32Array } {
  const { offsets: ro, indices: ri } = adjacency;
  const n = ro.length - 1;
  const T = poseToken ? n + 1 : n;
  const keyStart = new Int32Array(T + 1);
  const keys = new Int32Array(n + ri.length + (poseToken ? T : 0));
  let k = 0;
  for (let t = 0; t < n; t++) {
    keyStart[t] = k;
    keys[k++] = t;
    for (let e = ro[t]; e < ro[t + 1]; e++) keys[k++] = ri[e];
  }
  if (poseToken) {
    keyStart[n] = k;
    for (let s = 0; s < T; s++) keys[k++] = s;
  }
  keyStart[T] = k;
  return { keyStart, keys };
}

/** Attention weights of one layer for one frame (averaged over heads), for the paper's Fig. 7 and Fig. 10. */
export interface AttentionMaps {
  layer: number;
  /** (N + 1): how much the pose token attends to each vertex token (and, last, to itself). */
  poseToken: Float32Array;
  /** Vertex j's weights over its keys: keys[keyStart[j] .. keyStart[j + 1]) = [j, its 1-ring...]. */
  vertexWeights: Float32Array;
  keyStart: Int32Array;
  keys: Int32Array;
}

/** At least `frames` frames in each array, `per` floats a frame (the first are read): else a RangeError naming the
 * short one (it decoded NaN, silently). */
export function checkFrames(who: string, frames: number, arrays: [string, Float32Array, number][]): void {
  if (!Number.isInteger(frames) || frames < 0) throw new RangeError(`${who}: frames must be a whole number, not ${frames}`);
  for (const [name, a, per] of arrays) {
    if (a.length < frames * per) throw new RangeError(`${who}: ${name} holds ${a.length} floats, fewer than ${frames} frames of ${per}`);
  }
}

export class ReferenceDecoder {
  readonly n: number;
  private readonly d: number;
  private readonly x: Float32Array;
  private readonly h: Float32Array;
  private readonly qkv: Float32Array;
  private readonly attn: Float32Array;
  private readonly hidden: Float32Array;
  private readonly scores: Float32Array;

  constructor(
    readonly weights: DecoderWeights,
    readonly adjacency: Adjacency,
    readonly m: ModelConstants,
  ) {
    this.n = adjacency.offsets.length - 1;
    this.d = m.d_model;
    const T = this.n + 1;
    this.x = new Float32Array(T * this.d);
    this.h = new Float32Array(T * this.d);
    this.qkv = new Float32Array(T * 3 * this.d);
    this.attn = new Float32Array(T * this.d);
    this.hidden = new Float32Array(m.ffn);
    this.scores = new Float32Array(T);
  }

  private capture: AttentionMaps | null = null;

  /** The attention weights of `layer` (0-based) when decoding frame 0 of tokens / poseToken. */
  attention(tokens: Float32Array, poseToken: Float32Array, layer: number): AttentionMaps {
    const n = this.n;
    const { keyStart, keys } = keyLists(this.adjacency, false);
    this.capture = { layer, poseToken: new Float32Array(n + 1), vertexWeights: new Float32Array(keys.length), keyStart, keys };
    try {
      this.decode(tokens.subarray(0, n * this.d), poseToken.subarray(0, this.d), 1);
      return this.capture;
    } finally {
      this.capture = null;
    }
  }

  /** tokens (F x N x d), poseToken (F x d) -> displacement and pose per frame. `layerOut` receives each layer's tokens of frame 0. */
  decode(tokens: Float32Array, poseToken: Float32Array, frames: number, layerOut?: Float32Array[]): DecodeResult {
    const { n, d } = this;
    checkFrames('ReferenceDecoder.decode', frames, [['tokens', tokens, n * d], ['poseToken', poseToken, d]]);
    const offsets = new Float32Array(frames * n * 3);
    const pose = new Float32Array(frames * 6);
    for (let f = 0; f < frames; f++) {
      this.x.set(tokens.subarray(f * n * d, (f + 1) * n * d), 0);
      this.x.set(poseToken.subarray(f * d, (f + 1) * d), n * d);
      this.weights.layers.forEach((L, i) => {
        this.layer(L, i);
        if (f === 0 && layerOut) layerOut[i] = this.x.slice();
      });
      this.heads(offsets, pose, f);
    }
    return { offsets, pose };
  }

  private layer(L: LayerWeights, index: number): void {
    const { n, d, x, h, qkv, attn } = this;
    const T = n + 1;
    const heads = this.m.heads;
    const dk = d / heads;
    const scale = 1 / Math.sqrt(dk);
    for (let t = 0; t < T; t++) {
      layerNorm(x, t * d, d, L.ln1g, L.ln1b, h, t * d, this.weights.lnEps);
      linear(L.qkvW, L.qkvB, 3 * d, d, h, t * d, qkv, t * 3 * d);
    }
    const { offsets: ro, indices: ri } = this.adjacency;
    for (let t = 0; t < T; t++) {
      // Keys this token may see: itself and its 1-ring; the pose token (t = n) sees every token.
      const count = t < n ? 1 + ro[t + 1] - ro[t] : T;
      const key = (s: number) => (t < n ? (s === 0 ? t : ri[ro[t] + s - 1]) : s);
      for (let hd = 0; hd < heads; hd++) {
        const qo = t * 3 * d + hd * dk;
        let max = -Infinity;
        for (let s = 0; s < count; s++) {
          const ko = key(s) * 3 * d + d + hd * dk;
          let dot = 0;
          for (let i = 0; i < dk; i++) dot += qkv[qo + i] * qkv[ko + i];
          this.scores[s] = dot * scale;
          max = Math.max(max, this.scores[s]);
        }
        let sum = 0;
        for (let s = 0; s < count; s++) {
          this.scores[s] = Math.exp(this.scores[s] - max);
          sum += this.scores[s];
        }
        const ao = t * d + hd * dk;
        for (let i = 0; i < dk; i++) attn[ao + i] = 0;
        const cap = this.capture && this.capture.layer === index ? this.capture : null;
        for (let s = 0; s < count; s++) {
          const w = this.scores[s] / sum;
          if (cap) {
            if (t === n) cap.poseToken[s] += w / heads;
            else cap.vertexWeights[cap.keyStart[t] + s] += w / heads;
          }
          const vo = key(s) * 3 * d + 2 * d + hd * dk;
          for (let i = 0; i < dk; i++) attn[ao + i] += w * qkv[vo + i];
        }
      }
    }
    for (let t = 0; t < T; t++) {
      linear(L.outW, L.outB, d, d, attn, t * d, h, t * d);
      for (let i = 0; i < d; i++) x[t * d + i] += h[t * d + i];
      layerNorm(x, t * d, d, L.ln2g, L.ln2b, h, t * d, this.weights.lnEps);
      linear(L.ffn1W, L.ffn1B, this.m.ffn, d, h, t * d, this.hidden, 0);
      for (let i = 0; i < this.m.ffn; i++) this.hidden[i] = gelu(this.hidden[i]);
      linear(L.ffn2W, L.ffn2B, d, this.m.ffn, this.hidden, 0, attn, t * d);
      for (let i = 0; i < d; i++) x[t * d + i] += attn[t * d + i];
    }
  }

  private heads(offsets: Float32Array, pose: Float32Array, f: number): void {
    const { n, d, x, h } = this;
    const w = this.weights;
    for (let t = 0; t <= n; t++) layerNorm(x, t * d, d, w.lnG, w.lnB, h, t * d, w.lnEps);
    for (let j = 0; j < n; j++) linear(w.dispW, w.dispB, 3, d, h, j * d, offsets, (f * n + j) * 3);
    const raw = new Float32Array(6);
    linear(w.poseW, w.poseB, 6, d, h, n * d, raw, 0);
    for (let i = 0; i < 3; i++) pose[f * 6 + i] = this.m.max_rotation * Math.tanh(raw[i]);
    for (let i = 3; i < 6; i++) pose[f * 6 + i] = this.m.max_translation_mm * Math.tanh(raw[i]);
  }
}
