/**
 * Read the safetensors layout (https://huggingface.co/docs/safetensors): a little-endian u64
 * header length, a JSON header naming each tensor's dtype, shape and byte range, then the data.
 * The exporter (training/src/talkingface/export.py, with fixtures.py for the fixtures) writes the attention weights and the fixtures so.
 */

export type TensorData = Float32Array | Int32Array | BigInt64Array | Uint32Array;

export interface Tensor {
  dtype: 'F32' | 'I32' | 'I64' | 'U32';
  shape: number[];
  data: TensorData;
}

/** Bytes per value of each dtype read here. */
const ELEMENT_BYTES: Record<string, number> = { F32: 4, I32: 4, I64: 8, U32: 4 };

export class SafetensorsError extends Error {
  override name = 'SafetensorsError';
}

export function parseSafetensors(buffer: ArrayBuffer): { tensors: Map<string, Tensor>; metadata: Record<string, string> } {
  if (buffer.byteLength < 8) throw new SafetensorsError('file too short to be safetensors');
  const view = new DataView(buffer);
  const headerLength = Number(view.getBigUint64(0, true));
  if (headerLength <= 0 || 8 + headerLength > buffer.byteLength) throw new SafetensorsError('safetensors header length is out of range: file truncated or not safetensors');
  let header: Record<string, { dtype: string; shape: number[]; data_offsets: [number, number] } | Record<string, string>>;
  try {
    header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, headerLength)));
  } catch (e) {
    throw new SafetensorsError(`safetensors header is not JSON: ${(e as Error).message}`);
  }
  const base = 8 + headerLength;
  const tensors = new Map<string, Tensor>();
  let metadata: Record<string, string> = {};
  for (const [name, spec] of Object.entries(header)) {
    if (name === '__metadata__') {
      metadata = spec as Record<string, string>;
      continue;
    }
    const { dtype, shape, data_offsets } = spec as { dtype: string; shape: number[]; data_offsets: [number, number] };
    const size = Object.hasOwn(ELEMENT_BYTES, dtype) ? ELEMENT_BYTES[dtype] : 0;
    if (!size) throw new SafetensorsError(`tensor ${name}: dtype ${dtype} is not supported`);
    if (!Array.isArray(shape) || !shape.every((d) => Number.isInteger(d) && d >= 0)) throw new SafetensorsError(`tensor ${name}: its shape ${JSON.stringify(shape)} is not a list of sizes`);
    const [a, b] = Array.isArray(data_offsets) ? data_offsets : [NaN, NaN];
    if (!Number.isInteger(a) || !Number.isInteger(b) || a < 0 || a > b || base + b > buffer.byteLength) {
      throw new SafetensorsError(`tensor ${name} lies outside the file (data_offsets ${JSON.stringify(data_offsets)}): file truncated or damaged`);
    }
    if ((b - a) % size) throw new SafetensorsError(`tensor ${name}: ${b - a} bytes is not a whole number of ${dtype} values`);
    const bytes = buffer.slice(base + a, base + b);
    const count = shape.reduce((x, y) => x * y, 1);
    let data: TensorData;
    if (dtype === 'F32') data = new Float32Array(bytes);
    else if (dtype === 'I32') data = new Int32Array(bytes);
    else if (dtype === 'I64') data = new BigInt64Array(bytes);
    else data = new Uint32Array(bytes);
    if (data.length !== count) throw new SafetensorsError(`tensor ${name}: ${data.length} values for shape [${shape}]`);
    tensors.set(name, { dtype: dtype as Tensor['dtype'], shape, data });
  }
  return { tensors, metadata };
}

export function f32(tensors: Map<string, Tensor>, name: string, shape?: number[]): Float32Array {
  const t = tensors.get(name);
  if (!t) throw new SafetensorsError(`missing tensor ${name}`);
  if (t.dtype !== 'F32') throw new SafetensorsError(`tensor ${name} is ${t.dtype}, expected F32`);
  if (shape && (shape.length !== t.shape.length || shape.some((s, i) => s !== t.shape[i]))) {
    throw new SafetensorsError(`tensor ${name} has shape [${t.shape}], expected [${shape}]`);
  }
  return t.data as Float32Array;
}
