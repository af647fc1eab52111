/**
 * The life of a face between words: breathing, blinks and where the eyes look, as functions of time. Pure (no
 * three.js, no clock of its own): the view asks `at(seconds)` each frame, the .glb export at each frame's time.
 *
 * - Breathing: about 14 breaths a minute, inhaling a little faster than exhaling; -1 (out) .. 1 (in).
 * - Blinks: 2 to 5.5 s apart (about 16 a minute, a natural resting rate), the first within 3 s; each closes in
 *   80 ms, stays shut 40 ms and opens in 160 ms.
 * - Gaze: fixations on the viewer of 0.5 to 1.8 s, each a small saccade (about a degree) away from the last;
 *   about one fixation in five is a glance away (6 to 12 degrees aside, a little down) before coming back.
 *
 * The schedule is drawn from a seeded generator, so a given seed always gives the same life (tests, exports).
 */

export interface IdleState {
  /** -1 breathed out .. 1 breathed in. */
  breath: number;
  /** 0 open .. 1 closed. */
  blink: number;
  /** Gaze offset from the viewer (radians): + yaw looks to the face's left, + pitch looks up. */
  yaw: number;
  pitch: number;
  /** Number of blinks begun and of gaze shifts made so far (for tests and curious callers). */
  blinks: number;
  saccades: number;
}

const BREATH_PERIOD = 4.3;
const CLOSE = 0.08, SHUT = 0.04, OPEN = 0.16;
const DEG = Math.PI / 180;

/** mulberry32: a small, good-enough seeded generator. */
function random(seed: number): () => number {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

interface Fixation {
  start: number;
  yaw: number;
  pitch: number;
}

export class IdleMotion {
  private readonly blinkStarts: number[] = [];
  private readonly fixations: Fixation[] = [];
  private readonly rand: () => number;
  /** Blinks and fixations dropped from the front of the lists (they lie in the past). */
  private pastBlinks = 0;
  private pastFixations = 0;

  constructor(seed = 1) {
    this.rand = random(seed);
    this.blinkStarts.push(0.8 + 2.2 * this.rand());
    this.fixations.push({ start: 0, yaw: 0, pitch: 0 });
  }

  at(t: number): IdleState {
    this.extend(t);
    while (this.blinkStarts.length > 1 && this.blinkStarts[0] + 1 < t) {
      this.blinkStarts.shift();
      this.pastBlinks++;
    }
    while (this.fixations.length > 2 && this.fixations[1].start < t) {
      this.fixations.shift();
      this.pastFixations++;
    }
    const phase = (t / BREATH_PERIOD) % 1;
    // In over the first 40% of the cycle, out over the rest: a smooth, asymmetric wave.
    const breath = phase < 0.4 ? -Math.cos((phase / 0.4) * Math.PI) : Math.cos(((phase - 0.4) / 0.6) * Math.PI);
    let blink = 0, blinks = this.pastBlinks;
    for (const s of this.blinkStarts) {
      if (s > t) break;
      blinks++;
      const u = t - s;
      if (u < CLOSE) blink = Math.max(blink, u / CLOSE);
      else if (u < CLOSE + SHUT) blink = 1;
      else if (u < CLOSE + SHUT + OPEN) blink = Math.max(blink, 1 - (u - CLOSE - SHUT) / OPEN);
    }
    let k = 0;
    while (k + 1 < this.fixations.length && this.fixations[k + 1].start <= t) k++;
    const f = this.fixations[k];
    return { breath, blink: blink * blink * (3 - 2 * blink), yaw: f.yaw, pitch: f.pitch, blinks, saccades: this.pastFixations + k };
  }

  /** Draw the schedule up to a little past t. */
  private extend(t: number): void {
    const r = this.rand;
    while (this.blinkStarts[this.blinkStarts.length - 1] < t + 6) this.blinkStarts.push(this.blinkStarts[this.blinkStarts.length - 1] + 2 + 3.5 * r());
    while (this.fixations[this.fixations.length - 1].start < t + 6) {
      const last = this.fixations[this.fixations.length - 1];
      const away = Math.abs(last.yaw) < 3 * DEG && r() < 0.2;
      const start = last.start + (away ? 0.6 + 0.6 * r() : 0.5 + 1.3 * r());
      if (away) this.fixations.push({ start, yaw: (r() < 0.5 ? -1 : 1) * (6 + 6 * r()) * DEG, pitch: (-4 + 3 * r()) * DEG });
      else this.fixations.push({ start, yaw: (r() - 0.5) * 2.4 * DEG, pitch: (r() - 0.5) * 1.6 * DEG });
    }
  }
}
