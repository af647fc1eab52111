/**
 * The lip closure (src/engine/lip-closure.ts) against training/src/talkingface/model/lip_closure.py on the exporter's
 * fixtures: the template's own face, and one whose lips part 1.5 mm further; and what it must do on any face.
 */
import { describe, expect, it } from 'vitest';
import { f32 } from '../../../src/model/safetensors';
import { LipClosure } from '../../../src/engine/lip-closure';
import { faceFields } from '../../../src/avatar/fields';
import { innerLipGaps } from '../../../src/template/lip-gap';
import { MM_PER_UNIT, type FaceTemplate } from '../../../src/template/face-template';
import { loadFixtures, loadManifest, loadTemplateFile, maxAbsDiff } from '../helpers/exported';

const manifest = loadManifest();
const fx = loadFixtures(manifest);
const template = await loadTemplateFile(manifest);
const mm = MM_PER_UNIT[template.units];
const n = template.vertexCount;
const reference = manifest.lip_closure?.reference_gap_mm;
const gain = manifest.lip_closure?.mouth_gain ?? 1;

const withFace = (faceMm: Float32Array): FaceTemplate => ({ ...template, positions: Float32Array.from(faceMm, (v) => v / mm) });
const gaps = (face: Float32Array, offsets: Float32Array, frames: number) => {
  const unposed = Float32Array.from(offsets, (o, i) => o + face[i % (n * 3)]);
  return innerLipGaps(unposed, frames, n, Uint32Array.from(template.regions.lips_inner_upper), Uint32Array.from(template.regions.lips_inner_lower));
};

describe.runIf(reference !== undefined)('lip closure', () => {
  it('equals PyTorch on the template\'s face, on a face with wider-parted lips and on one whose lips meet', () => {
    const input = f32(fx, 'lips_in');
    const count = input.length / (n * 3);
    for (const [face, want] of [['template_mm', 'lips_out'], ['template_wider_mm', 'lips_out_wider'], ['template_shut_mm', 'lips_out_shut']] as const) {
      const offsets = input.slice();
      new LipClosure(withFace(f32(fx, face)), reference!, gain).apply(offsets, count, n);
      expect(maxAbsDiff(offsets, f32(fx, want))).toBeLessThan(1e-4); // mm
    }
    expect(maxAbsDiff(input, f32(fx, 'lips_out_wider'))).toBeGreaterThan(0.5); // the fixture closes lips: it can fail
    expect(maxAbsDiff(input, f32(fx, 'lips_out_shut'))).toBeGreaterThan(0.5);  // and takes a closing out
  });

  it('closes the lips of any face on the model\'s full closure, and leaves an opening alone', () => {
    const base = f32(fx, 'template_mm');
    const closer = new LipClosure(template, reference!);
    // Two frames: the model's own closure of the reference gap (the lower lip's tissue raised by it), and an opening.
    const lower = new Float64Array(n);
    const upperRegion = new Set(template.regions.lips_inner_upper);
    for (const v of template.regions.lips_inner_lower) if (!upperRegion.has(v)) lower[v] = 1;
    for (const wider of [0, 1.5, -1, -Infinity]) {
      // -Infinity: the lower lip raised until the lips meet at rest (a face modelled with its mouth shut).
      const by = wider === -Infinity ? -new LipClosure(template, reference!).faceGap : wider;
      const face = Float32Array.from(base, (v, i) => (i % 3 === 1 ? v - by * lower[Math.floor(i / 3)] : v));
      const c = new LipClosure(withFace(face), reference!);
      const g = c.faceGap;
      if (wider === -Infinity) expect(g).toBeLessThan(0.05);
      const offsets = new Float32Array(2 * n * 3);
      for (let v = 0; v < n; v++) {
        offsets[3 * v + 1] = (reference! * lower[v]);   // frame 0: the reference gap closed
        offsets[n * 3 + 3 * v + 1] = -2 * lower[v];      // frame 1: the lower lip drops 2 mm
      }
      const before = gaps(face, offsets, 2);
      c.apply(offsets, 2, n);
      const after = gaps(face, offsets, 2);
      expect(Math.abs(before[0] - (g - reference!))).toBeLessThan(0.05); // as the model closes: off by the difference
      expect(Math.abs(after[0])).toBeLessThan(0.05);                       // on the face's own gap: shut
      expect(after[1]).toBeCloseTo(before[1], 5);                           // an opening is the model's
    }
    expect(closer.vertexCount).toBeGreaterThan(template.regions.lips_inner_upper.length);
  });

  it('scales the mouth by its gain, fading with the rig\'s fields, and nothing else', () => {
    const f = faceFields(template);
    const opening = new Float32Array(n * 3);
    for (let v = 0; v < n; v++) opening[3 * v + 1] = -2 * f.wJaw[v]; // the jaw drops 2 mm: no closure to make
    const plain = opening.slice(), louder = opening.slice();
    new LipClosure(template, reference!).apply(plain, 1, n);
    new LipClosure(template, 1.3 * reference!, 1.3).apply(louder, 1, n);
    let scaled = 0;
    for (let v = 0; v < n; v++) {
      const m = Math.min(1, Math.max(f.wJaw[v], f.wLips[v]));
      expect(louder[3 * v + 1]).toBeCloseTo(plain[3 * v + 1] * (1 + 0.3 * m), 5);
      if (m === 0) expect(louder[3 * v + 1]).toBe(plain[3 * v + 1]);
      if (m > 0.99 && plain[3 * v + 1] !== 0) scaled++;
    }
    expect(scaled).toBeGreaterThan(20); // the chin and the lower lip at full gain: the test can fail
  });
});
