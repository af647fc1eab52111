/**
 * What a session takes, as the manifest describes it (manifest.onnx[key].inputs), and the check of a run's feeds
 * against it: names, ranks, fixed sizes and value counts, so a mismatched models/ fails with a clear message
 * before onnxruntime sees it.
 */
import type { Manifest } from '../model/manifest';

/** Where an ONNX session runs (onnxruntime-web's execution providers this project uses). */
export type ExecutionProvider = 'webgpu' | 'wasm';

export interface SessionSpec {
  name: string;
  bytes: ArrayBuffer;
  /** Expected input names with their shapes ("K"-style strings are free dimensions). */
  inputs: Record<string, (number | string)[]>;
}

/** A run's inputs: float32 or int64 data with its shape. */
export type Feeds = Record<string, { data: Float32Array | BigInt64Array; shape: number[] }>;

/** The session spec of runtime file `key` as the manifest describes it (manifest.onnx[key].inputs). */
export function specOf(manifest: Manifest, key: string, bytes: ArrayBuffer): SessionSpec {
  return { name: key, bytes, inputs: manifest.onnx[key].inputs };
}

/** A dimension's fixed size, or null for a free one ("K", "ceil(K / content_stride)"); "1" is fixed. */
function fixedSize(dim: number | string): number | null {
  if (typeof dim === 'number') return dim;
  return /^\d+$/.test(dim) ? Number(dim) : null;
}

/** Throw a RangeError naming session `name` where `feeds` lack an input or do not fit its shape. */
export function checkFeeds(name: string, inputs: SessionSpec['inputs'], feeds: Feeds): void {
  for (const [input, want] of Object.entries(inputs)) {
    const got = feeds[input];
    if (!got) throw new RangeError(`${name}: missing input ${input}`);
    const bad = want.length !== got.shape.length || want.some((w, i) => fixedSize(w) !== null && fixedSize(w) !== got.shape[i]);
    if (bad) throw new RangeError(`${name}: input ${input} has shape [${got.shape}], expected [${want}]`);
    const count = got.shape.reduce((a, b) => a * b, 1);
    if (count !== got.data.length) throw new RangeError(`${name}: input ${input} has ${got.data.length} values for shape [${got.shape}]`);
  }
}
