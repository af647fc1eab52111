/**
 * Idle blinks for an avatar. The model does not predict blinks from audio (they are not in the speech; its eye
 * motion is matched only in distribution, and on the test clips it is under 0.1 mm: docs/results/avatar.md), so
 * the avatar view adds them through eyeBlinkLeft / eyeBlinkRight as the corpus's subjects blink
 * (training/src/talkingface/corpus/coarticulation.py, sample_blinks and blink_track): every 1.8 to 6.5 s, about
 * 120 ms long, a fast close (35% of it) and a slower opening, one blink in five partial.
 */
export class Blinks {
  private next: number;
  private blink: { start: number; duration: number; amount: number } | null = null;

  /** `random`: a source of uniform numbers in [0, 1) (tests pass a seeded one). */
  constructor(now: number, private readonly random: () => number = Math.random) {
    this.next = now + this.interval() * this.random(); // start somewhere in the cycle
  }

  /** Lid closure in [0, 1] at time `now` (ms, increasing). */
  at(now: number): number {
    if (!this.blink && now >= this.next) {
      const seconds = 0.1 + 0.05 * this.random(); // as sample_blinks: uniform(0.1, 0.15)
      this.blink = { start: now, duration: 1000 * seconds, amount: this.random() > 0.2 ? 1 : 0.5 + 0.35 * this.random() };
      this.next = now + this.interval();
    }
    const b = this.blink;
    if (!b) return 0;
    const t = (now - b.start) / b.duration;
    if (t >= 1) {
      this.blink = null;
      return 0;
    }
    const ease = (x: number) => x * x * (3 - 2 * x);
    return b.amount * (t < 0.35 ? ease(t / 0.35) : ease((1 - t) / 0.65));
  }

  private interval(): number {
    const lo = 1800 + 1200 * this.random(); // a subject's shortest interval, as the corpus samples it
    return lo + (2000 + 1500 * this.random()) * this.random();
  }
}
