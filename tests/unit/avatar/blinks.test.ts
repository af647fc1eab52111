/** Idle blinks (src/avatar/blinks.ts): as often, as long and as deep as the corpus's. */
import { describe, expect, it } from 'vitest';
import { Blinks } from '../../../src/avatar/blinks';

/** A seeded uniform source (mulberry32). */
function seeded(seed: number): () => number {
  return () => {
    seed = (seed + 0x6d2b79f5) | 0;
    let t = Math.imul(seed ^ (seed >>> 15), 1 | seed);
    t = (t + Math.imul(t ^ (t >>> 7), 61 | t)) ^ t;
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

describe('Blinks', () => {
  it('blinks every 1.8 to 6.5 s for about 120 ms, closing fully in four of five, and stays in [0, 1]', () => {
    const blinks = new Blinks(0, seeded(7));
    const starts: number[] = [];
    const lengths: number[] = [];
    const peaks: number[] = [];
    let inside = false, since = 0, peak = 0, lo = 0, hi = 0;
    for (let t = 0; t < 600_000; t += 2) { // ten minutes at 500 Hz
      const v = blinks.at(t);
      lo = Math.min(lo, v);
      hi = Math.max(hi, v);
      if (v > 0 && !inside) { inside = true; since = t; peak = 0; starts.push(t); }
      if (inside) peak = Math.max(peak, v);
      if (v === 0 && inside) { inside = false; lengths.push(t - since); peaks.push(peak); }
    }
    expect(lo).toBe(0);
    expect(hi).toBeLessThanOrEqual(1);
    expect(hi).toBeGreaterThan(0.99);
    const gaps = starts.slice(1).map((t, i) => t - starts[i]);
    expect(Math.min(...gaps)).toBeGreaterThanOrEqual(1800);
    expect(Math.max(...gaps)).toBeLessThanOrEqual(6600);
    expect(starts.length).toBeGreaterThan(600 / 6.5);
    expect(starts.length).toBeLessThan(600 / 1.8);
    expect(Math.min(...lengths)).toBeGreaterThanOrEqual(90);
    expect(Math.max(...lengths)).toBeLessThanOrEqual(152);
    const full = peaks.filter((p) => p > 0.97).length / peaks.length;
    expect(full).toBeGreaterThan(0.65);
    expect(full).toBeLessThan(0.95);
  });
});
