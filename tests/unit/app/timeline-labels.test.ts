import { describe, expect, it } from 'vitest';
import { gapScale, labelsThatFit } from '../../../src/app/timeline';

const row = (xs: number[], first: number[] = [], width = 10) => xs.map((x, i) => ({ x, width, first: first.includes(i) }));

describe('labelsThatFit', () => {
  it('keeps every label where there is room', () => {
    expect(labelsThatFit(row([10, 30, 50]), 3)).toEqual([0, 1, 2]);
  });

  it('leaves out a label that would overlap or come within the gap of the one before', () => {
    expect(labelsThatFit(row([10, 15, 30, 42]), 3)).toEqual([0, 2]); // 15 overlaps 10; 42 is 2 px from 30's label
    expect(labelsThatFit(row([10, 23]), 3)).toEqual([0, 1]); // 3 px apart: just room
  });

  it('keeps a /p b m/ label over the ordinary ones around it, whatever their order', () => {
    expect(labelsThatFit(row([10, 16, 22, 28], [2]), 2)).toEqual([0, 2]); // 16 and 28 touch the bilabial at 22
    expect(labelsThatFit(row([10, 14], [0, 1]), 2)).toEqual([0]); // two bilabials: the first kept
  });

  it('returns nothing for no labels, and no two kept labels ever overlap', () => {
    expect(labelsThatFit([], 3)).toEqual([]);
    const many = Array.from({ length: 200 }, (_, i) => ({ x: (i * 37) % 400, width: 6 + (i % 5), first: i % 7 === 0 }));
    const kept = labelsThatFit(many, 2).map((i) => many[i]).sort((a, b) => a.x - b.x);
    for (let k = 1; k < kept.length; k++) {
      expect(kept[k].x - kept[k].width / 2).toBeGreaterThanOrEqual(kept[k - 1].x + kept[k - 1].width / 2 + 2);
    }
  });
});

describe('gapScale', () => {
  it('is the widest gap of the take or its truth, at least 8 mm, for a take of hours too', () => {
    expect(gapScale(Float32Array.of(1, 3, 2))).toBe(8);
    expect(gapScale(Float32Array.of(1, 9.5, 2), [4, 12])).toBe(12);
    const hours = new Float32Array(2 * 30 * 3600).fill(2); // spread as Math.max's arguments, this overflowed the stack
    hours[177_777] = 14;
    expect(gapScale(hours)).toBe(14);
  });
});
