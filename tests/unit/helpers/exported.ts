/** The exporter's artefacts (models/, or MODELS_DIR) as the unit tests read them: manifest, fixtures, weights, template. */
import { expect } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import * as ort from 'onnxruntime-node';
import { checkManifest, type Manifest } from '../../../src/model/manifest';
import { parseSafetensors, type Tensor } from '../../../src/model/safetensors';
import { decoderWeights, type DecoderWeights } from '../../../src/attention/reference';
import { decodeTemplate, type FaceTemplate } from '../../../src/template/face-template';

export const ROOT = resolve(import.meta.dirname, '../../..');
export const MODELS = resolve(ROOT, process.env.MODELS_DIR ?? 'models');

export const buf = (p: string): ArrayBuffer => {
  const b = readFileSync(resolve(MODELS, p));
  return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer;
};

export function loadManifest(): Manifest {
  return checkManifest(JSON.parse(readFileSync(resolve(MODELS, 'manifest.json'), 'utf8')));
}

/** The fixture tensors PyTorch computed for one clip (models/fixtures). */
export function loadFixtures(manifest: Manifest): Map<string, Tensor> {
  return parseSafetensors(buf(manifest.fixtures.file)).tensors;
}

export function loadTemplateFile(manifest: Manifest): Promise<FaceTemplate> {
  return decodeTemplate(JSON.parse(readFileSync(resolve(MODELS, manifest.template.path), 'utf8')), buf(manifest.template.path.replace('.json', '.bin')));
}

export function loadDecoderWeights(manifest: Manifest): DecoderWeights {
  return decoderWeights(parseSafetensors(buf(manifest.files.decoder_weights)).tensors, manifest.model.config, manifest.model.layer_norm_eps);
}

/** The largest absolute difference (the lengths must be equal). */
export const maxAbsDiff = (a: ArrayLike<number>, b: ArrayLike<number>): number => {
  expect(a.length).toBe(b.length);
  let m = 0;
  for (let i = 0; i < a.length; i++) m = Math.max(m, Math.abs(a[i] - b[i]));
  return m;
};

/** One ONNX file of models/ run on onnxruntime-node. */
export async function runOnnx(file: string, feeds: Record<string, ort.Tensor>): Promise<Record<string, ort.Tensor>> {
  const s = await ort.InferenceSession.create(resolve(MODELS, file));
  return s.run(feeds) as Promise<Record<string, ort.Tensor>>;
}
