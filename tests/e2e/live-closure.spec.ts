import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { FPS, SAMPLE_RATE, readWav16 } from './helpers/audio';

/**
 * The lips close on /p b m/ in the browser (issue 14): a test-split sample clip (an unseen voice, sentence and
 * face) plays through Chromium's fake microphone, in a loop, into the live engine (dev/live.html). The take is
 * placed against the clip by cross-correlation, and every /p b m/ segment of the clip's alignment that the take
 * covers counts as closed when the inner-lip gap (training's definition) falls below 1 mm at a frame inside it.
 * Reported beside the rate: the same gap track's closures in other speech (false alarms).
 */
const SAMPLES = resolve(import.meta.dirname, '../../models/samples');
const index = JSON.parse(readFileSync(resolve(SAMPLES, 'index.json'), 'utf8')) as {
  clips: { name: string; audio: string; phones: [string, number, number][]; lip_gap_mm: number[] }[];
};
// The sample with the most bilabials.
const clip = index.clips.map((c) => ({ c, n: c.phones.filter(([p]) => 'P B M'.split(' ').includes(p)).length }))
  .sort((a, b) => b.n - a.n)[0].c;
const WAV = resolve(SAMPLES, clip.audio);
test.use({ launchOptions: fakeMicrophone(WAV) });

/** Offset (samples) into the looped clip at which the take begins: coarse at 2 kHz, refined at 16 kHz. */
function offsetInLoop(take: number[], clipAudio: Float32Array): number {
  const L = clipAudio.length;
  const start = Math.min(SAMPLE_RATE, Math.max(0, take.length - SAMPLE_RATE));
  const score = (off: number, step: number, len: number) => {
    let s = 0;
    for (let t = 0; t < len; t += step) s += take[start + t] * clipAudio[(start + t + off) % L];
    return s;
  };
  let best = 0, bestScore = -Infinity;
  for (let off = 0; off < L; off += 8) {
    const s = score(off, 8, SAMPLE_RATE);
    if (s > bestScore) [best, bestScore] = [off, s];
  }
  let fine = best;
  bestScore = -Infinity;
  for (let off = best - 8; off <= best + 8; off++) {
    const s = score((off + L) % L, 1, SAMPLE_RATE);
    if (s > bestScore) [fine, bestScore] = [(off + L) % L, s];
  }
  return fine;
}

/** Frames (at FPS, of `count`) whose time lies in [a, b) s, as training's articulation.segment_frames; the nearest if none. */
function framesIn(a: number, b: number, count: number): number[] {
  const out: number[] = [];
  for (let f = Math.max(0, Math.ceil(a * FPS - 1e-6)); f < Math.min(count, Math.ceil(b * FPS - 1e-6)); f++) out.push(f);
  return out.length ? out : [Math.min(count - 1, Math.max(0, Math.round(((a + b) / 2) * FPS)))];
}

test('live from a microphone: the lips close on /p b m/ of an unseen voice', async ({ page }) => {
  test.setTimeout(120_000);
  // 14 s: about five passes of the clip, 15 /p b m/ and 120 other segments (7 s gave 58 others, and the false-alarm
  // rate of four takes ran from 21% to 28%).
  await page.goto('/dev/live.html?seconds=14&take=1');
  const handle = await page.waitForFunction(() => (globalThis as unknown as { liveResult?: unknown }).liveResult, null, { timeout: 90_000 });
  const r = (await handle.jsonValue()) as { error?: string; contourGaps: number[]; take: number[]; mmPerUnit: number };
  expect(r.error, r.error).toBeUndefined();
  const audio = readWav16(WAV);
  const fps = FPS, sr = SAMPLE_RATE;
  const off = offsetInLoop(r.take, audio) / sr;
  const loop = audio.length / sr;
  const gaps = r.contourGaps.map((g) => g * r.mmPerUnit);
  const takeSeconds = gaps.length / fps;
  const truth = clip.lip_gap_mm; // the corpus's own inner-lip gap for this clip, frame by frame from its start
  let hits = 0, trials = 0, falseHits = 0, others = 0, truthFalse = 0;
  for (let k = -1; (k * loop) - off < takeSeconds; k++) {
    for (const [p, a, b] of clip.phones) {
      const [ta, tb] = [a + k * loop - off, b + k * loop - off];
      if (p === 'SIL' || ta < 0.5 || tb > takeSeconds - 0.2) continue; // skip the first half second (the stream warms up)
      const closed = Math.min(...framesIn(ta, tb, gaps.length).map((f) => gaps[f])) < 1.0;
      if ('PBM'.includes(p) && p.length === 1) { trials++; hits += Number(closed); continue; }
      others++;
      falseHits += Number(closed);
      // The truth on the same segment, on its own frame grid (the clip's frames from its start).
      truthFalse += Number(Math.min(...framesIn(a, b, truth.length).map((f) => truth[f])) < 1.0);
    }
  }
  console.log(`${clip.name} through the fake microphone: /p b m/ closed ${hits}/${trials}, closed in other speech ${falseHits}/${others}` +
    ` (the truth ${truthFalse}/${others}; offset ${off.toFixed(3)} s)`);
  expect(trials).toBeGreaterThanOrEqual(10);
  // The shipped model closes 85% of the test split's /p b m/ (docs/results/default.md) and 86% in the browser
  // (docs/results/peers.md); issue 14's target of 95% is not reached yet. Held here to the same: at least 85%.
  expect(hits / trials, '/p b m/ segments with the lips closed').toBeGreaterThanOrEqual(0.85);
  // Neighbours of /p b m/ share their closure, in the truth too (3 of this clip's 24 other segments). Offline
  // (`python -m talkingface.train.looped`: the clip looped as here, on the page's face), 17 to 25 of 96 (18% to
  // 26%), by where in a frame the loop starts, which a take does not choose; 7 s takes gave 21% to 28%. Held here:
  // fewer than twice the truth's rate plus 10 points.
  expect(falseHits / others, 'other speech segments with the lips closed').toBeLessThan(2 * truthFalse / others + 0.1);
});
