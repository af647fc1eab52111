/** DecoderBackends (src/engine/backends.ts): what it refuses at load, before any chunk is decoded. */
import { describe, expect, it } from 'vitest';
import { DecoderBackends } from '../../../src/engine/backends';
import { ModelLoadError } from '../../../src/model/artefacts';
import { loadDecoderWeights, loadManifest, loadTemplateFile } from '../helpers/exported';

const noGpu = { available: false, description: 'none in this test', adapter: null, info: null };

describe('DecoderBackends.create', () => {
  it('refuses decoder weights made for another mesh than the template, naming both sizes', async () => {
    const manifest = loadManifest();
    const m = manifest.model.config;
    const template = await loadTemplateFile(manifest);
    const weights = loadDecoderWeights(manifest);
    const other = { ...weights, vertexEmbedding: weights.vertexEmbedding.subarray(0, 10 * m.d_model) };
    const n = template.adjacency.offsets.length - 1;
    const refused = DecoderBackends.create(other, template.adjacency, m, noGpu, 8, { cpuWorkers: 1 });
    await expect(refused).rejects.toThrow(ModelLoadError);
    await expect(refused).rejects.toThrow(`has 10 vertices, the template ${n}`);
    const backends = await DecoderBackends.create(weights, template.adjacency, m, noGpu, 8, { cpuWorkers: 1 });
    expect(backends.backend).toBe('cpu');
  });
});
