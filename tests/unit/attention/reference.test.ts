/** The reference GAVA decoder (src/attention/reference.ts) against PyTorch: layer by layer, the posed vertices, the attention maps. */
import { describe, expect, it } from 'vitest';
import type { Manifest } from '../../../src/model/manifest';
import { f32 } from '../../../src/model/safetensors';
import { ReferenceDecoder } from '../../../src/attention/reference';
import { applyPose } from '../../../src/pose/posing';
import { loadDecoderWeights, loadFixtures, loadManifest, loadTemplateFile, maxAbsDiff } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);

describe('the reference decoder vs the PyTorch fixture', () => {
  it('the TypeScript GAVA decoder matches PyTorch layer by layer, and the posed vertices', async () => {
    const m = manifest.model.config;
    const template = await loadTemplateFile(manifest);
    const weights = loadDecoderWeights(manifest);
    const dec = new ReferenceDecoder(weights, template.adjacency, m);
    const frames = manifest.fixtures.token_frames;
    const layers: Float32Array[] = [];
    const poseTok = f32(fx, 'pose_token');
    const out = dec.decode(f32(fx, 'tokens'), poseTok, frames, layers);
    for (let i = 0; i < m.layers; i++) {
      const want = f32(fx, `layer${i}`);
      expect(maxAbsDiff(layers[i], want.subarray(0, layers[i].length))).toBeLessThan(1e-4);
    }
    const wantOffsets = f32(fx, 'offsets').subarray(0, out.offsets.length);
    expect(maxAbsDiff(out.offsets, wantOffsets)).toBeLessThan(1e-4);
    expect(maxAbsDiff(out.pose, f32(fx, 'pose').subarray(0, out.pose.length))).toBeLessThan(1e-5);
    const y = applyPose(f32(fx, 'template_mm'), out.offsets, out.pose, frames);
    expect(maxAbsDiff(y, f32(fx, 'vertices').subarray(0, y.length))).toBeLessThan(1e-3); // mm: 1e-4 of the template's cm
  });
});

describe('attention maps (the paper\'s Fig. 7 and Fig. 10)', () => {
  it('the reference decoder\'s attention weights equal PyTorch\'s, for every layer', async () => {
    const m = manifest.model.config;
    const template = await loadTemplateFile(manifest);
    const weights = loadDecoderWeights(manifest);
    const dec = new ReferenceDecoder(weights, template.adjacency, m);
    const n = template.vertexCount;
    for (let layer = 0; layer < m.layers; layer++) {
      const maps = dec.attention(f32(fx, 'tokens'), f32(fx, 'pose_token'), layer);
      expect(maxAbsDiff(maps.poseToken, f32(fx, `attention_pose${layer}`))).toBeLessThan(1e-5);
      const table = f32(fx, `attention_vertex${layer}`);
      const K = table.length / n;
      let worst = 0;
      for (let j = 0; j < n; j++) {
        let sum = 0;
        for (let s = 0; s < maps.keyStart[j + 1] - maps.keyStart[j]; s++) {
          worst = Math.max(worst, Math.abs(maps.vertexWeights[maps.keyStart[j] + s] - table[j * K + s]));
          sum += maps.vertexWeights[maps.keyStart[j] + s];
        }
        expect(sum).toBeCloseTo(1, 5);
      }
      expect(worst).toBeLessThan(1e-5);
    }
  });
});
