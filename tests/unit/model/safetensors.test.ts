/** parseSafetensors (src/model/safetensors.ts): a file a faulty exporter or a damaged copy made is refused naming the tensor, never read wrong. */
import { describe, expect, it } from 'vitest';
import { parseSafetensors, SafetensorsError } from '../../../src/model/safetensors';

/** A safetensors file of `header` (JSON) and `data` bytes. */
function file(header: object, data: number): ArrayBuffer {
  const json = new TextEncoder().encode(JSON.stringify(header));
  const out = new Uint8Array(8 + json.length + data);
  new DataView(out.buffer).setBigUint64(0, BigInt(json.length), true);
  out.set(json, 8);
  new DataView(out.buffer).setFloat32(8 + json.length, 1.5, true);
  return out.buffer;
}

describe('parseSafetensors', () => {
  it('reads a tensor where its offsets say', () => {
    const { tensors } = parseSafetensors(file({ w: { dtype: 'F32', shape: [2], data_offsets: [0, 8] } }, 8));
    expect(Array.from(tensors.get('w')!.data as Float32Array)).toEqual([1.5, 0]);
  });

  it('refuses offsets that are missing, negative, reversed, past the end or not whole values, naming the tensor', () => {
    const cases: [object, RegExp][] = [
      [{ w: { dtype: 'F32', shape: [2] } }, /tensor w lies outside the file \(data_offsets undefined\)/],
      [{ w: { dtype: 'F32', shape: [1], data_offsets: [-4, 0] } }, /tensor w lies outside the file/],
      [{ w: { dtype: 'F32', shape: [1], data_offsets: [8, 4] } }, /tensor w lies outside the file/],
      [{ w: { dtype: 'F32', shape: [4], data_offsets: [0, 16] } }, /tensor w lies outside the file \(data_offsets \[0,16\]\): file truncated or damaged/],
      [{ w: { dtype: 'F32', shape: [1], data_offsets: [0, 6] } }, /tensor w: 6 bytes is not a whole number of F32 values/],
      [{ w: { dtype: 'F16', shape: [1], data_offsets: [0, 2] } }, /tensor w: dtype F16 is not supported/],
      [{ w: { dtype: 'constructor', shape: [1], data_offsets: [0, 4] } }, /dtype constructor is not supported/],
      [{ w: { dtype: 'F32', shape: [-1], data_offsets: [0, 4] } }, /tensor w: its shape \[-1\] is not a list of sizes/],
      [{ w: { dtype: 'F32', shape: [3], data_offsets: [0, 8] } }, /tensor w: 2 values for shape \[3\]/],
    ];
    for (const [header, message] of cases) expect(() => parseSafetensors(file(header, 8)), JSON.stringify(header)).toThrow(message);
    expect(() => parseSafetensors(file({ w: { dtype: 'F32', shape: [1], data_offsets: [0, 6] } }, 8))).toThrow(SafetensorsError);
  });
});
