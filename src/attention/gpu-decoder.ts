/**
 * The GAVA decoder as WGSL compute passes (shaders/gava_attention.wgsl), batched over frames.
 * Same interface and numbers as ReferenceDecoder (src/attention/reference.ts), which is what the
 * browser tests compare it with. From latents (decodeLatents), first vertex_tokens; per layer: ln_qkv -> attend ->
 * out_ffn; then heads.
 */
import shaderSource from '../../shaders/gava_attention.wgsl?raw';
import type { ModelConstants } from '../model/manifest';
import type { Adjacency } from '../template/mesh-topology';
import { vertexEmbeddingMismatch, type DecodeResult, type DecoderWeights } from './reference';

const PARAMS_BYTES = 32; // struct Params in the shader: 5 x u32, 2 x f32, padding

/** Lay out the decoder's weights in the order the shader's o_* offset functions read them. */
export function packWeights(w: DecoderWeights): { data: Float32Array; layerBases: number[]; finalBase: number } {
  const parts: Float32Array[] = [];
  const layerBases: number[] = [];
  let size = 0;
  const push = (a: Float32Array) => {
    parts.push(a);
    size += a.length;
  };
  for (const L of w.layers) {
    layerBases.push(size);
    for (const a of [L.ln1g, L.ln1b, L.qkvW, L.qkvB, L.outW, L.outB, L.ln2g, L.ln2b, L.ffn1W, L.ffn1B, L.ffn2W, L.ffn2B]) push(a);
  }
  const finalBase = size;
  for (const a of [w.lnG, w.lnB, w.dispW, w.dispB, w.poseW, w.poseB]) push(a);
  for (const a of [w.vertexEmbedding, w.localOutW, w.localOutB]) push(a); // the shader's vertex_tokens: at final_base + 11 d + 9
  const data = new Float32Array(size);
  let o = 0;
  for (const a of parts) {
    data.set(a, o);
    o += a.length;
  }
  return { data, layerBases, finalBase };
}

/** The device limits a decoder is sized by (a GPUDevice's `limits` has them). */
export type GpuLimits = Pick<GPUSupportedLimits, 'maxStorageBufferBindingSize' | 'maxBufferSize' | 'maxComputeWorkgroupsPerDimension'>;

/**
 * How many frames one batch may hold on a device with `limits` (at most `wanted`): its largest buffer (q, k and v of
 * every token of every frame) within one binding, its frames within one dispatch. A mesh, a model or its weights too
 * large for the device at all is an Error that says which limit: past a limit WebGPU only reports an error to the
 * console, and the batch would read back zeros.
 */
export function gpuFramesWithin(limits: GpuLimits, vertices: number, d: number, weightFloats: number, wanted: number): number {
  const binding = Math.min(limits.maxStorageBufferBindingSize, limits.maxBufferSize);
  const tokens = vertices + 1;
  const perFrame = Math.max(tokens * 3 * d * 4, (vertices * 3 + 6) * 4);
  const why = tokens > limits.maxComputeWorkgroupsPerDimension
    ? `${tokens} tokens exceed this device's ${limits.maxComputeWorkgroupsPerDimension} workgroups per dispatch`
    : weightFloats * 4 > binding ? `the decoder's weights (${weightFloats * 4} bytes) exceed this device's ${binding}-byte storage binding`
      : perFrame > binding ? `one frame of ${tokens} tokens of ${d} (${perFrame} bytes) exceeds this device's ${binding}-byte storage binding` : '';
  if (why) throw new Error(`GpuDecoder: ${why}`);
  return Math.max(1, Math.min(wanted, Math.floor(binding / perFrame), limits.maxComputeWorkgroupsPerDimension));
}

export class GpuDecoder {
  private readonly pipelines: Record<'vertex_tokens' | 'ln_qkv' | 'attend' | 'out_ffn' | 'heads', GPUComputePipeline>;
  private readonly bindGroups: GPUBindGroup[]; // one per layer, then one for the heads
  private readonly x: GPUBuffer;
  private readonly attn: GPUBuffer;
  /** Why decodeLatents cannot run (weights of another mesh; decode can), or null. */
  private readonly noTokens: string | null;
  private readonly result: GPUBuffer;
  private readonly readback: GPUBuffer;
  private readonly uniforms: GPUBuffer[];
  private readonly buffers: GPUBuffer[] = [];
  private readonly n: number;
  private readonly t: number;
  private readonly d: number;
  /** Frames one batch holds: as many as asked for, or fewer where the device's limits say so (gpuFramesWithin). */
  readonly maxFrames: number;
  private busy: Promise<unknown> = Promise.resolve();

  constructor(
    readonly device: GPUDevice,
    weights: DecoderWeights,
    adjacency: Adjacency,
    readonly m: ModelConstants,
    framesWanted: number,
  ) {
    const d = m.d_model;
    // From 8: the heads' pass writes pose channel i from thread i (six of them); the heads split d evenly.
    if ((d & (d - 1)) !== 0 || d < 8 || d > 256) throw new Error(`GpuDecoder: d_model ${d} must be a power of two from 8 to 256`);
    if (d % m.heads !== 0) throw new Error(`GpuDecoder: ${m.heads} heads do not divide d_model ${d}`);
    if (m.ffn > 512) throw new Error(`GpuDecoder: ffn ${m.ffn} exceeds the shader's 512`);
    this.n = adjacency.offsets.length - 1;
    this.t = this.n + 1;
    this.d = d;
    const packed = packWeights(weights);
    const maxFrames = (this.maxFrames = gpuFramesWithin(device.limits, this.n, d, packed.data.length, framesWanted));
    const storage = (label: string, bytes: number, usage = 0) => {
      const b = device.createBuffer({ label, size: Math.max(16, bytes), usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_DST | usage });
      this.buffers.push(b);
      return b;
    };
    const upload = (label: string, data: Float32Array | Uint32Array) => {
      const b = storage(label, data.byteLength);
      device.queue.writeBuffer(b, 0, data.buffer, data.byteOffset, data.byteLength);
      return b;
    };
    const frameTokens = maxFrames * this.t;
    this.x = storage('GpuDecoder.x', frameTokens * d * 4);
    const qkv = storage('GpuDecoder.qkv', frameTokens * 3 * d * 4);
    const attn = (this.attn = storage('GpuDecoder.attn', frameTokens * d * 4));
    this.noTokens = vertexEmbeddingMismatch(weights, this.n, d);
    const offsets = upload('GpuDecoder.csrOffsets', adjacency.offsets);
    const indices = upload('GpuDecoder.csrIndices', adjacency.indices.length ? adjacency.indices : new Uint32Array(1));
    const w = upload('GpuDecoder.weights', packed.data);
    const resultBytes = (maxFrames * this.n * 3 + maxFrames * 6) * 4;
    this.result = storage('GpuDecoder.result', resultBytes, GPUBufferUsage.COPY_SRC);
    this.readback = device.createBuffer({ label: 'GpuDecoder.readback', size: resultBytes, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
    this.buffers.push(this.readback);

    const module = device.createShaderModule({ label: 'GpuDecoder.shader', code: shaderSource });
    const layout = device.createBindGroupLayout({
      label: 'GpuDecoder.bindGroupLayout',
      entries: [
        { binding: 0, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'storage' } }, // x: residual stream
        { binding: 1, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'storage' } }, // qkv
        { binding: 2, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'storage' } }, // attn
        { binding: 3, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'uniform' } }, // params
        { binding: 4, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'read-only-storage' } }, // csr offsets
        { binding: 5, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'read-only-storage' } }, // csr indices
        { binding: 6, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'read-only-storage' } }, // weights
        { binding: 7, visibility: GPUShaderStage.COMPUTE, buffer: { type: 'storage' } }, // result
      ],
    });
    const pipelineLayout = device.createPipelineLayout({ label: 'GpuDecoder.pipelineLayout', bindGroupLayouts: [layout] });
    const constants = { D: d, HEADS: m.heads, FFN: m.ffn, LN_EPS: weights.lnEps };
    const pipeline = (entryPoint: string) =>
      device.createComputePipeline({ label: `GpuDecoder.${entryPoint}`, layout: pipelineLayout, compute: { module, entryPoint, constants } });
    this.pipelines = {
      vertex_tokens: pipeline('vertex_tokens'), ln_qkv: pipeline('ln_qkv'), attend: pipeline('attend'), out_ffn: pipeline('out_ffn'),
      heads: pipeline('heads'),
    };

    // One uniform buffer per layer (and one for the heads): all passes are encoded before the queue
    // runs them, so a single buffer rewritten between passes would hold only its last value.
    this.layerBases = [...packed.layerBases, 0]; // the heads' pass reads only final_base
    this.uniforms = this.layerBases.map((_, i) => {
      const u = device.createBuffer({ label: `GpuDecoder.params.${i}`, size: PARAMS_BYTES, usage: GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST });
      this.buffers.push(u);
      return u;
    });
    this.finalBase = packed.finalBase;
    this.bindGroups = this.uniforms.map((u, i) =>
      device.createBindGroup({
        label: `GpuDecoder.bindGroup.${i}`,
        layout,
        entries: [this.x, qkv, attn, u, offsets, indices, w, this.result].map((buffer, binding) => ({ binding, resource: { buffer } })),
      }),
    );
  }

  private readonly finalBase: number;
  private readonly layerBases: number[];

  /** tokens (F x N x d), poseToken (F x d) -> offsets (F x N x 3) mm, pose (F x 6). Calls are serialised. */
  decode(tokens: Float32Array, poseToken: Float32Array, frames: number): Promise<DecodeResult> {
    return this.serialised(() => this.run(tokens, null, poseToken, frames));
  }

  /** latents (F x 2d: the hierarchical feature's [a, g]), poseToken (F x d) -> as decode; the vertex tokens are made on the GPU. */
  decodeLatents(latents: Float32Array, poseToken: Float32Array, frames: number): Promise<DecodeResult> {
    return this.serialised(() => this.run(null, latents, poseToken, frames));
  }

  private serialised(job: () => Promise<DecodeResult>): Promise<DecodeResult> {
    const run = this.busy.then(job);
    this.busy = run.catch(() => undefined); // the caller gets the error through `run`; `busy` only orders runs
    return run;
  }

  /** One batch, from vertex tokens or (tokens null) from latents. */
  private async run(tokens: Float32Array | null, latents: Float32Array | null, poseToken: Float32Array, frames: number): Promise<DecodeResult> {
    const { device, n, d } = this;
    if (frames > this.maxFrames) throw new RangeError(`GpuDecoder: ${frames} frames exceed the ${this.maxFrames} it was built for`);
    if ((tokens && tokens.length !== frames * n * d) || (latents && latents.length !== frames * 2 * d) || poseToken.length !== frames * d) {
      throw new RangeError('GpuDecoder: token arrays do not match the frame count');
    }
    if (latents && this.noTokens) throw new Error(`GpuDecoder: ${this.noTokens}`);
    // Validation and memory errors only reach the console unless a scope catches them: the batch would read back
    // zeros. Caught, they fail it, and the engine carries on with the CPU decoder.
    device.pushErrorScope('out-of-memory');
    device.pushErrorScope('validation');
    let thrown: unknown = null;
    try {
      this.upload(tokens, latents, poseToken, frames);
      this.encode(frames, latents !== null);
    } catch (e) {
      thrown = e; // thrown once the scopes are popped: they must be, whatever happens
    }
    const error = (await Promise.all([device.popErrorScope(), device.popErrorScope()])).find((e) => e);
    if (error) throw new Error(`GpuDecoder: ${error.message}`);
    if (thrown) throw thrown;
    const offsetBytes = frames * this.n * 3 * 4;
    await this.readback.mapAsync(GPUMapMode.READ, 0, offsetBytes + frames * 6 * 4);
    const out = new Float32Array(this.readback.getMappedRange(0, offsetBytes + frames * 6 * 4).slice(0));
    this.readback.unmap();
    return { offsets: out.subarray(0, frames * this.n * 3), pose: out.subarray(frames * this.n * 3) };
  }

  /** Write one batch's inputs and each pass's uniforms. */
  private upload(tokens: Float32Array | null, latents: Float32Array | null, poseToken: Float32Array, frames: number): void {
    const { device, n, t, d } = this;
    if (tokens) {
      const xs = new Float32Array(frames * t * d);
      for (let f = 0; f < frames; f++) {
        xs.set(tokens.subarray(f * n * d, (f + 1) * n * d), f * t * d);
        xs.set(poseToken.subarray(f * d, (f + 1) * d), (f * t + n) * d);
      }
      device.queue.writeBuffer(this.x, 0, xs);
    } else {
      // From latents the vertex_tokens pass writes every vertex row: only the pose tokens go up (d floats a frame,
      // not the whole frames x t x d block of zeros, 5.8 MB for 96 frames of 469 tokens).
      for (let f = 0; f < frames; f++) device.queue.writeBuffer(this.x, (f * t + n) * d * 4, poseToken, f * d, d);
    }
    if (latents) device.queue.writeBuffer(this.attn, 0, latents.buffer, latents.byteOffset, latents.byteLength);
    const params = new ArrayBuffer(PARAMS_BYTES);
    const u32 = new Uint32Array(params);
    const f32 = new Float32Array(params);
    for (const [i, u] of this.uniforms.entries()) {
      u32.set([n, t, frames, this.layerBases[i], this.finalBase]);
      f32[5] = this.m.max_rotation;
      f32[6] = this.m.max_translation_mm;
      device.queue.writeBuffer(u, 0, params);
    }
  }

  /** Encode and submit one batch's passes and its copy to the readback buffer. */
  private encode(frames: number, fromLatents: boolean): void {
    const { device, n, t } = this;
    const encoder = device.createCommandEncoder({ label: 'GpuDecoder.encoder' });
    const pass = encoder.beginComputePass({ label: 'GpuDecoder.pass' });
    const layers = this.uniforms.length - 1;
    if (fromLatents) { // the heads' uniforms hold final_base, where the vertex tokens' weights begin
      pass.setBindGroup(0, this.bindGroups[layers]);
      pass.setPipeline(this.pipelines.vertex_tokens);
      pass.dispatchWorkgroups(n, frames);
    }
    for (let l = 0; l < layers; l++) {
      pass.setBindGroup(0, this.bindGroups[l]);
      for (const p of ['ln_qkv', 'attend', 'out_ffn'] as const) {
        pass.setPipeline(this.pipelines[p]);
        pass.dispatchWorkgroups(t, frames);
      }
    }
    pass.setBindGroup(0, this.bindGroups[layers]);
    pass.setPipeline(this.pipelines.heads);
    pass.dispatchWorkgroups(t, frames);
    pass.end();
    const offsetBytes = frames * n * 3 * 4;
    encoder.copyBufferToBuffer(this.result, 0, this.readback, 0, offsetBytes);
    // The shader writes the poses right after this call's offsets.
    encoder.copyBufferToBuffer(this.result, offsetBytes, this.readback, offsetBytes, frames * 6 * 4);
    device.queue.submit([encoder.finish()]);
  }

  destroy(): void {
    for (const b of this.buffers) b.destroy();
  }
}
