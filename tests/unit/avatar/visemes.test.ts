/** Oculus visemes from phone posteriors (src/avatar/visemes.ts). */
import { describe, expect, it } from 'vitest';
import { PHONE_TO_VISEME, VisemeMap } from '../../../src/avatar/visemes';
import { VISEME_NAMES } from '../../../src/avatar/names';
import { loadManifest } from '../helpers/exported';

const phones = loadManifest().content_phones;

describe('phone -> viseme', () => {
  it("covers every content class of the shipped model (the blank maps to none), and every viseme has phones", () => {
    const map = new VisemeMap(phones);
    expect(Array.from(map.classViseme).filter((v) => v < 0)).toHaveLength(1);
    expect(phones[map.classViseme.indexOf(-1)]).toBe('<blank>');
    expect(new Set(Object.values(PHONE_TO_VISEME))).toEqual(new Set(VISEME_NAMES));
    expect(() => new VisemeMap([...phones, 'QQ'])).toThrow(/no viseme for the content classes QQ/);
  });

  it('bilabials are PP, labiodentals FF, the open vowels aa (AO, rounded, O), silence sil', () => {
    for (const p of ['P', 'B', 'M']) expect(PHONE_TO_VISEME[p]).toBe('viseme_PP');
    for (const p of ['F', 'V']) expect(PHONE_TO_VISEME[p]).toBe('viseme_FF');
    for (const p of ['AA', 'AE', 'AH', 'AW', 'AY']) expect(PHONE_TO_VISEME[p]).toBe('viseme_aa');
    expect(PHONE_TO_VISEME.AO).toBe('viseme_O');
    expect(PHONE_TO_VISEME.UW).toBe('viseme_U');
    expect(PHONE_TO_VISEME.SIL).toBe('viseme_sil');
  });

  it("each viseme takes its phones' mass; the blank's share is spread; rows sum to 1", () => {
    const map = new VisemeMap(phones);
    const C = phones.length;
    const post = new Float32Array(3 * C);
    const at = (f: number, p: string, v: number) => (post[f * C + phones.indexOf(p)] = v);
    at(0, 'P', 0.3); at(0, 'B', 0.2); at(0, 'M', 0.1); at(0, 'AA', 0.2); at(0, '<blank>', 0.2);
    at(1, 'IY', 1);
    at(2, '<blank>', 1);
    const w = map.weights(post, 3);
    const row = (f: number) => Array.from(w.subarray(f * 15, f * 15 + 15));
    expect(row(0)[VISEME_NAMES.indexOf('viseme_PP')]).toBeCloseTo(0.6 / 0.8, 6);
    expect(row(0)[VISEME_NAMES.indexOf('viseme_aa')]).toBeCloseTo(0.2 / 0.8, 6);
    expect(row(1)[VISEME_NAMES.indexOf('viseme_I')]).toBe(1);
    expect(row(2)[VISEME_NAMES.indexOf('viseme_sil')]).toBe(1); // only the blank heard
    for (let f = 0; f < 3; f++) expect(row(f).reduce((s, x) => s + x, 0)).toBeCloseTo(1, 6);
  });
});
