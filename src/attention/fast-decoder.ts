/**
 * The GAVA decoder on the CPU, written for speed: the engine's CPU backend.
 *
 * Same layers and numbers as ReferenceDecoder (reference.ts, the readable version the tests hold
 * it to), computed differently:
 * - every projection is one matrix product over all N + 1 tokens of a frame;
 * - the keys each token attends to are one precomputed list (self first, then the 1-ring; the pose
 *   token: every token), no per-key closures;
 * - GELU reads a table of the exact function with cubic Hermite interpolation (error < 1e-9), not
 *   an erf with an exp per element;
 * - buffers are allocated once;
 * - the arithmetic runs in WebAssembly SIMD where the runtime has it, else in TypeScript
 *   (decoder-kernels.ts: the same operations, `kernel` chooses).
 */
import type { ModelConstants } from '../model/manifest';
import type { Adjacency } from '../template/mesh-topology';
import { checkFrames, keyLists, vertexEmbeddingMismatch, type DecodeResult, type DecoderWeights } from './reference';
import { geluInPlace, jsKernel, matmulRows, type DecoderKernel, type PackedWeight } from './decoder-kernels';
import { simdModule, SimdKernel } from './simd-kernel';

export { geluInPlace, matmulRows };

/** Which arithmetic: 'auto' = WebAssembly SIMD where available (and the head size a multiple of 4), else TypeScript. */
export type KernelChoice = 'auto' | 'wasm-simd' | 'js';

interface PackedLayer {
  ln1g: Float32Array; ln1b: Float32Array; ln2g: Float32Array; ln2b: Float32Array;
  qkv: PackedWeight; out: PackedWeight; ffn1: PackedWeight; ffn2: PackedWeight;
}

export class FastDecoder {
  readonly n: number;
  /** The arithmetic in use: 'wasm-simd' or 'js'. */
  readonly kernelName: string;
  private readonly d: number;
  private readonly tokens: number;
  private readonly rows: number;
  private readonly kernel: DecoderKernel;
  private readonly layers: PackedLayer[];
  private readonly vertexEmbedding: Float32Array | null;
  /** Why decodeLatents cannot run (weights of another mesh), or null. */
  private readonly noTokens: string | null;
  private readonly localOut: PackedWeight;
  /** The frame's a, where the kernel reads it. */
  private readonly aRow: Float32Array;
  /** The displacement head, padded to 4 outputs (the SIMD product's width; the fourth is zeros), and its output. */
  private readonly dispHead: PackedWeight;
  private readonly dispOut: Float32Array;
  private readonly lnG: Float32Array;
  private readonly lnB: Float32Array;
  private readonly x: Float32Array;
  private readonly h: Float32Array;
  private readonly qkv: Float32Array;
  private readonly attn: Float32Array;
  private readonly hidden: Float32Array;
  private readonly scores: Float64Array;
  private readonly keyStart: Int32Array; // token t attends to keys keyIndex[keyStart[t] .. keyStart[t + 1])
  private readonly keyIndex: Int32Array;
  private readonly raw = new Float32Array(6);

  constructor(
    readonly weights: DecoderWeights,
    readonly adjacency: Adjacency,
    readonly m: ModelConstants,
    kernel: KernelChoice = 'auto',
  ) {
    const n = adjacency.offsets.length - 1;
    this.n = n;
    const d = (this.d = m.d_model);
    this.tokens = n + 1;
    // The SIMD product takes two tokens at a time: buffers have an even number of rows (the spare
    // row is zeros in, finite numbers out, and never read as a result).
    const rows = (this.rows = (n + 2) & ~1);
    const lists = keyLists(adjacency, true);
    const simdFits = (d / m.heads) % 4 === 0;
    if (kernel === 'wasm-simd' && !simdFits) throw new Error(`FastDecoder: the SIMD kernel needs a head size divisible by 4 (d ${d}, ${m.heads} heads)`);
    const simd = kernel === 'wasm-simd' || (kernel === 'auto' && simdFits && simdModule() !== null);
    if (simd) {
      const L = weights.layers.length;
      const floats = rows * (6 * d + m.ffn) + L * (4 * d * d + 2 * d * m.ffn + 8 * d + m.ffn) + 2 * d
        + n * d + d * d + d + lists.keyStart.length + lists.keys.length + SimdKernel.scratchFloats(n + 1)
        + d + 4 * d + 4 + 4 * rows;
      const allocations = 15 + 14 * L;
      this.kernel = new SimdKernel(4 * floats + 16 * allocations);
    } else {
      this.kernel = jsKernel;
    }
    this.kernelName = this.kernel.name;
    const k = this.kernel;
    this.x = k.alloc(rows * d);
    this.h = k.alloc(rows * d);
    this.qkv = k.alloc(rows * 3 * d);
    this.attn = k.alloc(rows * d);
    this.hidden = k.alloc(rows * m.ffn);
    this.layers = weights.layers.map((L) => ({
      ln1g: k.place(L.ln1g), ln1b: k.place(L.ln1b), ln2g: k.place(L.ln2g), ln2b: k.place(L.ln2b),
      qkv: k.pack(L.qkvW, L.qkvB, 3 * d, d),
      out: k.pack(L.outW, L.outB, d, d),
      ffn1: k.pack(L.ffn1W, L.ffn1B, m.ffn, d),
      ffn2: k.pack(L.ffn2W, L.ffn2B, d, m.ffn),
    }));
    // Weights of another mesh decode tokens given (decode) but cannot make them (decodeLatents): the benchmark's larger meshes.
    this.noTokens = vertexEmbeddingMismatch(weights, n, d);
    this.vertexEmbedding = this.noTokens ? null : k.place(weights.vertexEmbedding);
    // Its bias is rewritten every frame with localOutB + g (a copy: the TypeScript kernel packs the arrays it is given).
    this.localOut = k.pack(weights.localOutW, weights.localOutB.slice(), d, d);
    this.aRow = k.alloc(d);
    const dispW = new Float32Array(4 * d), dispB = new Float32Array(4);
    dispW.set(weights.dispW.subarray(0, 3 * d));
    dispB.set(weights.dispB.subarray(0, 3));
    this.dispHead = k.pack(dispW, dispB, 4, d);
    this.dispOut = k.alloc(rows * 4);
    this.lnG = k.place(weights.lnG);
    this.lnB = k.place(weights.lnB);
    this.scores = k.scratch(n + 1);
    this.keyStart = k.placeInts(lists.keyStart);
    this.keyIndex = k.placeInts(lists.keys);
  }

  /** tokens (F x N x d), poseToken (F x d) -> displacement (F x N x 3, mm) and pose (F x 6) per frame. */
  decode(tokens: Float32Array, poseToken: Float32Array, frames: number): DecodeResult {
    const { n, d } = this;
    checkFrames('FastDecoder.decode', frames, [['tokens', tokens, n * d], ['poseToken', poseToken, d]]);
    return this.frames(poseToken, frames, (f) => this.x.set(tokens.subarray(f * n * d, (f + 1) * n * d), 0));
  }

  /**
   * latents (F x 2d: each frame's [a, g], hierarchical.onnx's output), poseToken (F x d) -> as decode. The vertex
   * tokens are made here, in the decoder's arithmetic: localOut(gelu(a + e_j)) + g (reference.ts vertexTokens).
   */
  decodeLatents(latents: Float32Array, poseToken: Float32Array, frames: number): DecodeResult {
    checkFrames('FastDecoder.decodeLatents', frames, [['latents', latents, 2 * this.d], ['poseToken', poseToken, this.d]]);
    return this.frames(poseToken, frames, (f) => this.vertexTokensOf(latents, f));
  }

  /** Every frame: `vertexRows(f)` fills x's N vertex rows, then the pose token, the layers and the heads. */
  private frames(poseToken: Float32Array, frames: number, vertexRows: (f: number) => void): DecodeResult {
    const { n, d } = this;
    const offsets = new Float32Array(frames * n * 3);
    const pose = new Float32Array(frames * 6);
    for (let f = 0; f < frames; f++) {
      vertexRows(f);
      this.x.set(poseToken.subarray(f * d, (f + 1) * d), n * d);
      for (const L of this.layers) this.layer(L);
      this.heads(offsets, pose, f);
    }
    return { offsets, pose };
  }

  /** The vertex tokens (F x N x d) of frames' latents, as decodeLatents makes them (for a decoder that takes tokens). */
  vertexTokens(latents: Float32Array, frames: number): Float32Array {
    const { n, d } = this;
    const tokens = new Float32Array(frames * n * d);
    for (let f = 0; f < frames; f++) {
      this.vertexTokensOf(latents, f);
      tokens.set(this.x.subarray(0, n * d), f * n * d);
    }
    return tokens;
  }

  /** Frame f's vertex tokens into x's first N rows (h is scratch): g rides in the product's bias. */
  private vertexTokensOf(latents: Float32Array, f: number): void {
    const { n, d, h, x, rows, vertexEmbedding: e, kernel: k } = this;
    if (!e) throw new Error(`FastDecoder: ${this.noTokens}`);
    const a = f * 2 * d, g = a + d;
    this.aRow.set(latents.subarray(a, a + d));
    k.addRow(e, this.aRow, n, d, h);
    h.fill(0, n * d, rows * d);
    k.gelu(h, n * d);
    const bias = this.localOut.b;
    for (let i = 0; i < d; i++) bias[i] = this.weights.localOutB[i] + latents[g + i];
    k.matmul(this.localOut, h, rows, x);
  }

  private layer(L: PackedLayer): void {
    const { d, x, h, qkv, attn, hidden, kernel: k, tokens: T, rows } = this;
    k.layerNorm(x, T, d, L.ln1g, L.ln1b, h, this.weights.lnEps);
    k.matmul(L.qkv, h, rows, qkv);
    k.attention(qkv, T, d, this.m.heads, this.keyStart, this.keyIndex, this.scores, attn);
    k.matmul(L.out, attn, rows, h);
    k.add(x, h, T * d);
    k.layerNorm(x, T, d, L.ln2g, L.ln2b, h, this.weights.lnEps);
    k.matmul(L.ffn1, h, rows, hidden);
    k.gelu(hidden, T * this.m.ffn);
    k.matmul(L.ffn2, hidden, rows, attn);
    k.add(x, attn, T * d);
  }

  private heads(offsets: Float32Array, pose: Float32Array, f: number): void {
    const { n, d, x, h, raw } = this;
    const w = this.weights;
    this.kernel.layerNorm(x, this.tokens, d, this.lnG, this.lnB, h, this.weights.lnEps);
    const out = this.dispOut;
    this.kernel.matmul(this.dispHead, h, this.rows, out);
    for (let j = 0, o = f * n * 3; j < n; j++, o += 3) {
      offsets[o] = out[4 * j];
      offsets[o + 1] = out[4 * j + 1];
      offsets[o + 2] = out[4 * j + 2];
    }
    matmulRows(w.poseW, w.poseB, 6, d, h.subarray(n * d), 1, raw);
    for (let i = 0; i < 3; i++) pose[f * 6 + i] = this.m.max_rotation * Math.tanh(raw[i]);
    for (let i = 3; i < 6; i++) pose[f * 6 + i] = this.m.max_translation_mm * Math.tanh(raw[i]);
  }
}

