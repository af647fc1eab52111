/** Content windows (src/encoders/windows.ts) and the frame -> Mel index map against the exporter's fixture. */
import { describe, expect, it } from 'vitest';
import { frameToMelIndex } from '../../../src/model/manifest';
import { f32 } from '../../../src/model/safetensors';
import { contentWindows, softmaxRows } from '../../../src/encoders/windows';
import { loadFixtures, loadManifest, maxAbsDiff } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);

describe('content windows vs the PyTorch fixture', () => {
  it('frame -> Mel index and the content windows match', () => {
    const melIndex = fx.get('mel_index')!.data as BigInt64Array;
    for (let i = 0; i < melIndex.length; i++) expect(frameToMelIndex(i, manifest.audio)).toBe(Number(melIndex[i]));
    const post = softmaxRows(f32(fx, 'content_logits').slice(), manifest.model.config.content_classes);
    const win = contentWindows(post, Array.from(melIndex, Number), manifest.model.config);
    expect(maxAbsDiff(win, f32(fx, 'windows'))).toBeLessThan(1e-6);
  });
});
