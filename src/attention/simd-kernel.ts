/**
 * The CPU decoder's WebAssembly SIMD kernel (simd/decoder.wat, assembled by `npm run build:wasm` into
 * simd/decoder-wasm.ts): the DecoderKernel operations over one WebAssembly memory. Where SIMD is missing the
 * TypeScript kernel (decoder-kernels.ts) runs instead, and simdUnavailable says why.
 */
import { WASM_BASE64 } from './simd/decoder-wasm';
import { WASM_BASE64 as FMA_BASE64 } from './simd/decoder-fma-wasm';
import { GELU_RANGE, GELU_STEPS, geluTableData, addRowTo, matmulRows, type DecoderKernel, type PackedWeight } from './decoder-kernels';

let module: WebAssembly.Module | null | undefined;

/** Why the SIMD kernel is not used here ('' while it is, or before simdModule() was asked). */
export let simdUnavailable = '';

/** The compiled SIMD module, or null where this runtime has no WebAssembly SIMD. */
export function simdModule(): WebAssembly.Module | null {
  if (module !== undefined) return module;
  module = null;
  if (typeof WebAssembly !== 'object') {
    simdUnavailable = 'this runtime has no WebAssembly';
    return module;
  }
  const bytes = fromBase64(WASM_BASE64);
  try {
    if (WebAssembly.validate(bytes)) module = new WebAssembly.Module(bytes);
    else simdUnavailable = 'this runtime has no WebAssembly SIMD';
  } catch (e) {
    // e.g. a Content-Security-Policy without 'wasm-unsafe-eval': the TypeScript kernel runs, and the reason is kept.
    module = null;
    simdUnavailable = (e as Error).message;
  }
  return module;
}

let fused: WebAssembly.Module | null | undefined;

/**
 * The matrix product, GELU and the d 32 / 4 heads attention with fused multiply-adds (relaxed SIMD's
 * f32x4.relaxed_madd; simd/decoder-fma-wasm.ts, made by `npm run build:wasm` from decoder.wat's matmul, gelu and
 * attention_d32h4), or null where this runtime lacks relaxed SIMD (not
 * every browser has it; Node without --experimental-wasm-relaxed-simd), where the plain ones run. One rounding fewer
 * per multiply-add where the CPU has FMA, and faster (docs/results/README.md, Speed); on a CPU without FMA the same
 * numbers as the plain ones.
 */
export function fmaModule(): WebAssembly.Module | null {
  if (fused !== undefined) return fused;
  fused = null;
  if (simdModule() === null) return fused;
  const bytes = fromBase64(FMA_BASE64);
  if (WebAssembly.validate(bytes)) fused = new WebAssembly.Module(bytes);
  return fused;
}

function fromBase64(b64: string): Uint8Array<ArrayBuffer> {
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return bytes;
}

interface SimdExports {
  memory: WebAssembly.Memory;
  matmul(wt: number, b: number, outs: number, cols: number, x: number, rows: number, out: number): void;
  layer_norm(x: number, rows: number, d: number, g: number, b: number, out: number, eps: number): void;
  attention(qkv: number, tokens: number, d: number, heads: number, keyStart: number, keyIndex: number, scores: number, out: number, scale: number): void;
  attention_d32h4(qkv: number, tokens: number, keyStart: number, keyIndex: number, scores: number, out: number, scale: number): void;
  gelu(a: number, count: number, value: number, slope: number, range: number, steps: number): void;
  add(x: number, y: number, count: number): void;
  add_row(x: number, row: number, rows: number, d: number, out: number): void;
}

/**
 * The SIMD kernel over one memory of `bytes` bytes (everything alloc'd, placed and packed, plus alignment); its matrix
 * products, GELU and the model's attention with fused multiply-adds where the runtime has relaxed SIMD, unless `fma`
 * is false.
 */
export class SimdKernel implements DecoderKernel {
  readonly name = 'wasm-simd';
  /** Whether the matrix products, GELU and the model's attention fuse their multiply-adds (fmaModule). */
  readonly fusedMultiplyAdd: boolean;
  private readonly exports: SimdExports;
  /** matmul, gelu and attention_d32h4: the fused module's where there is one, else the plain module's. */
  private readonly fusable: Pick<SimdExports, 'matmul' | 'gelu' | 'attention_d32h4'>;
  private used = 0;
  private readonly capacity: number;
  private readonly geluValue: Float64Array;
  private readonly geluSlope: Float64Array;

  constructor(bytes: number, fma = true) {
    const mod = simdModule();
    if (!mod) throw new Error('WebAssembly SIMD is not available in this runtime');
    this.exports = new WebAssembly.Instance(mod).exports as unknown as SimdExports;
    const fusedModule = fma ? fmaModule() : null;
    this.fusedMultiplyAdd = fusedModule !== null;
    // The fused module works on this kernel's memory (it imports it), so it takes the same byte addresses.
    this.fusable = fusedModule
      ? new WebAssembly.Instance(fusedModule, { kernel: { memory: this.exports.memory } }).exports as unknown as SimdExports
      : this.exports;
    const table = geluTableData();
    const need = bytes + 16 * table.value.length + 4096;
    const have = this.exports.memory.buffer.byteLength;
    if (need > have) this.exports.memory.grow(Math.ceil((need - have) / 65536));
    this.capacity = this.exports.memory.buffer.byteLength;
    this.geluValue = this.take(Float64Array, table.value.length);
    this.geluValue.set(table.value);
    this.geluSlope = this.take(Float64Array, table.slope.length);
    this.geluSlope.set(table.slope);
  }

  private take<A extends Float32Array | Int32Array | Float64Array>(kind: { new (b: ArrayBuffer, o: number, n: number): A; BYTES_PER_ELEMENT: number }, length: number): A {
    const start = (this.used + 15) & ~15; // 16-byte aligned: one vector
    if (start + length * kind.BYTES_PER_ELEMENT > this.capacity) throw new Error(`SimdKernel: ${length} values more than reserved`);
    this.used = start + length * kind.BYTES_PER_ELEMENT;
    return new kind(this.exports.memory.buffer, start, length);
  }

  alloc(length: number): Float32Array {
    return this.take(Float32Array, length);
  }

  place(values: Float32Array): Float32Array {
    const a = this.take(Float32Array, values.length);
    a.set(values);
    return a;
  }

  placeInts(values: Int32Array): Int32Array {
    const a = this.take(Int32Array, values.length);
    a.set(values);
    return a;
  }

  /** `length` float64 for the TypeScript kernel's use; here 16 bytes per key (attention_d32h4: four heads' scores). */
  scratch(length: number): Float64Array {
    return this.take(Float64Array, SimdKernel.scratchFloats(length) / 2);
  }

  /** The float32s scratch(length) takes of the kernel's memory (for sizing it). */
  static scratchFloats(length: number): number {
    return 4 * length + 4;
  }

  pack(W: Float32Array, b: Float32Array, outs: number, cols: number): PackedWeight {
    if (outs % 4) return { outs, cols, w: W, b }; // matmul() uses the TypeScript product for these
    const w = this.alloc(outs * cols);
    for (let o = 0; o < outs; o++) for (let i = 0; i < cols; i++) w[i * outs + o] = W[o * cols + i];
    return { outs, cols, w, b: this.place(b) };
  }

  private mine(...arrays: ArrayBufferView[]): void {
    for (const a of arrays) {
      if (a.buffer !== this.exports.memory.buffer) throw new Error('SimdKernel: an array not allocated by this kernel');
    }
  }

  matmul(p: PackedWeight, X: Float32Array, rows: number, out: Float32Array): void {
    if (p.outs % 4) {
      matmulRows(p.w, p.b, p.outs, p.cols, X, rows, out);
      return;
    }
    if (rows % 2) throw new Error('SimdKernel.matmul: rows must be even');
    this.mine(X, out);
    this.fusable.matmul(p.w.byteOffset, p.b.byteOffset, p.outs, p.cols, X.byteOffset, rows, out.byteOffset);
  }

  layerNorm(X: Float32Array, rows: number, d: number, g: Float32Array, b: Float32Array, out: Float32Array, eps: number): void {
    this.mine(X, g, b, out);
    this.exports.layer_norm(X.byteOffset, rows, d, g.byteOffset, b.byteOffset, out.byteOffset, eps);
  }

  attention(qkv: Float32Array, tokens: number, d: number, heads: number, keyStart: Int32Array, keyIndex: Int32Array,
    scores: Float64Array, out: Float32Array): void {
    if ((d / heads) % 4) throw new Error('SimdKernel.attention: the head size must be a multiple of 4');
    this.mine(qkv, keyStart, keyIndex, scores, out);
    if (d === 32 && heads === 4) {
      // The model's shape: all four heads of a key at once (decoder.wat, attention_d32h4).
      this.fusable.attention_d32h4(qkv.byteOffset, tokens, keyStart.byteOffset, keyIndex.byteOffset, scores.byteOffset, out.byteOffset, 1 / Math.sqrt(8));
      return;
    }
    this.exports.attention(qkv.byteOffset, tokens, d, heads, keyStart.byteOffset, keyIndex.byteOffset, scores.byteOffset,
      out.byteOffset, 1 / Math.sqrt(d / heads));
  }

  gelu(a: Float32Array, count: number): void {
    this.mine(a);
    this.fusable.gelu(a.byteOffset, count, this.geluValue.byteOffset, this.geluSlope.byteOffset, GELU_RANGE, GELU_STEPS);
  }

  add(x: Float32Array, y: Float32Array, count: number): void {
    this.mine(x, y);
    this.exports.add(x.byteOffset, y.byteOffset, count);
  }

  addRow(x: Float32Array, row: Float32Array, rows: number, d: number, out: Float32Array): void {
    if (d % 4) {
      addRowTo(x, row, rows, d, out);
      return;
    }
    this.mine(x, row, out);
    this.exports.add_row(x.byteOffset, row.byteOffset, rows, d, out.byteOffset);
  }
}
