/** The feed check every ONNX run goes through (src/encoders/onnx-spec.ts), on the manifest's own input specs. */
import { describe, expect, it } from 'vitest';
import { checkFeeds, specOf } from '../../../src/encoders/onnx-spec';
import { loadManifest } from '../helpers/exported';

const manifest = loadManifest();

describe('checkFeeds', () => {
  const spec = specOf(manifest, 'content_encoder', new ArrayBuffer(0));
  const mels = manifest.audio.n_mels;

  it('takes any length along a free dimension and the manifest\'s size along a fixed one', () => {
    for (const K of [1, 37, 200]) expect(() => checkFeeds(spec.name, spec.inputs, { mel: { data: new Float32Array(K * mels), shape: [1, K, mels] } })).not.toThrow();
  });

  it('names the session and the input on a missing input, a wrong shape or a wrong value count', () => {
    expect(() => checkFeeds(spec.name, spec.inputs, {})).toThrow('content_encoder: missing input mel');
    expect(() => checkFeeds(spec.name, spec.inputs, { mel: { data: new Float32Array(10 * 7), shape: [1, 10, 7] } }))
      .toThrow(`content_encoder: input mel has shape [1,10,7], expected [1,K,${mels}]`);
    expect(() => checkFeeds(spec.name, spec.inputs, { mel: { data: new Float32Array(5), shape: [1, 10, mels] } }))
      .toThrow(`content_encoder: input mel has 5 values for shape [1,10,${mels}]`);
  });
});
