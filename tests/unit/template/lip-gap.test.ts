import { describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { decodeTemplate } from '../../../src/template/face-template';
import { innerLipGaps } from '../../../src/template/lip-gap';

const MODELS = resolve(import.meta.dirname, '../../../models');
const index = JSON.parse(readFileSync(resolve(MODELS, 'samples/index.json'), 'utf8')) as {
  clips: { name: string; ground_truth: string; frames: number; vertices: number; lip_gap_mm: number[] }[];
};

describe('innerLipGaps', () => {
  it('equals training\'s contour_gap on the sample clips\' ground truth (fixture written by talkingface.samples)', async () => {
    const buf = (p: string) => { const b = readFileSync(p); return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer; };
    const t = await decodeTemplate(JSON.parse(readFileSync(resolve(MODELS, 'template/template.json'), 'utf8')), buf(resolve(MODELS, 'template/template.bin')));
    const { lips_inner_upper: upper, lips_inner_lower: lower } = t.regions;
    for (const c of index.clips) {
      const bytes = buf(resolve(MODELS, 'samples', c.ground_truth));
      const n = c.vertices, F = c.frames;
      const neutral = new Float32Array(bytes, 0, n * 3);
      const micrometres = new Int16Array(bytes, n * 3 * 4, F * n * 3);
      const unposed = Float32Array.from(micrometres, (o, i) => neutral[i % (n * 3)] + o * 1e-4); // cm
      const gaps = innerLipGaps(unposed, F, n, upper, lower);
      let worst = 0;
      for (let f = 0; f < F; f++) worst = Math.max(worst, Math.abs(gaps[f] * 10 - c.lip_gap_mm[f]));
      expect(worst, `${c.name}: largest |TS - Python| in mm`).toBeLessThan(0.01); // int16 micrometres and 4 decimals
      expect(Math.max(...gaps) * 10).toBeGreaterThan(3); // the fixture is speech, not a closed mouth
    }
  });
});
