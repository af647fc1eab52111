/** The idle schedule (src/render/idle-motion.ts): a natural blink rate, early first blink and saccade, glances. */
import { describe, expect, it } from 'vitest';
import { IdleMotion } from '../../../src/render/idle-motion';

describe('IdleMotion', () => {
  it('blinks at a natural rate, the first within 3 s, never more than 5.5 s apart', () => {
    const idle = new IdleMotion(7);
    let closedAt: number[] = [];
    let was = 0;
    for (let t = 0; t < 600; t += 1 / 60) {
      const s = idle.at(t);
      if (s.blink > 0.95 && was <= 0.95) closedAt.push(t);
      was = s.blink;
    }
    expect(closedAt[0]).toBeLessThan(3.2);
    const gaps = closedAt.slice(1).map((t, i) => t - closedAt[i]);
    expect(Math.max(...gaps)).toBeLessThan(5.6);
    const perMinute = closedAt.length / 10;
    expect(perMinute).toBeGreaterThan(12);
    expect(perMinute).toBeLessThan(22);
    closedAt = [];
  });

  it('moves the eyes within 2 s, mostly by small saccades, sometimes glancing away; breathes 12-16 times a minute', () => {
    const idle = new IdleMotion(3);
    const yaws: number[] = [];
    let firstMove = Infinity, crossings = 0, last = idle.at(0).breath;
    for (let t = 0; t < 120; t += 1 / 60) {
      const s = idle.at(t);
      if (s.saccades > 0 && firstMove === Infinity) firstMove = t;
      yaws.push(Math.abs(s.yaw));
      if (last < 0 && s.breath >= 0) crossings++;
      last = s.breath;
    }
    expect(firstMove).toBeLessThan(2);
    const deg = (r: number) => (r * 180) / Math.PI;
    const small = yaws.filter((y) => deg(y) < 1.5).length / yaws.length;
    expect(small).toBeGreaterThan(0.5);
    expect(deg(Math.max(...yaws))).toBeGreaterThan(5);
    expect(crossings / 2).toBeGreaterThan(12);
    expect(crossings / 2).toBeLessThan(16.5);
  });

  it('is the same life for the same seed', () => {
    const a = new IdleMotion(5), b = new IdleMotion(5);
    for (let t = 0; t < 30; t += 0.37) expect(a.at(t)).toEqual(b.at(t));
  });
});
