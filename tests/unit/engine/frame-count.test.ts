/**
 * How many frames a clip gets (src/engine/pipeline.ts frameCount): round(duration x fps) with a half to the even
 * neighbour, as Python's round() in training (fixtures.py, reserved.py). Rounding halves up gave an odd multiple of
 * 50 ms one frame more in the browser than in Python.
 */
import { describe, expect, it } from 'vitest';
import { Pipeline } from '../../../src/engine/pipeline';
import type { DecoderBackends } from '../../../src/engine/backends';
import type { ContentEncoder } from '../../../src/encoders/content';
import type { PoseEncoder } from '../../../src/encoders/pose';
import { loadManifest, loadTemplateFile } from '../helpers/exported';

const manifest = loadManifest();
const template = await loadTemplateFile(manifest);

describe('frameCount', () => {
  it('rounds as Python does, at the model\'s 16 kHz and 30 fps', () => {
    expect([manifest.audio.sample_rate, manifest.audio.fps]).toEqual([16000, 30]); // what the figures below are for
    const pipeline = new Pipeline(manifest, template, {} as ContentEncoder, {} as PoseEncoder, {} as DecoderBackends, null);
    // max(1, round(samples / 16000 * 30)) in Python 3
    const python: [number, number][] = [[1, 1], [800, 2], [2400, 4], [4000, 8], [5600, 10], [7200, 14], [8000, 15], [12345, 23], [17600, 33], [48800, 92]];
    for (const [samples, frames] of python) expect(pipeline.frameCount(samples), `${samples} samples`).toBe(frames);
  });
});
