/**
 * The demo live, as a visitor sees it (npm run bench): Chromium's fake microphone plays a speech clip into Record,
 * and the page counts, over `seconds`, the face's renders and the live frames it showed against the frames the model
 * made; then how often the face renders at rest, and how long a sample clip takes to animate. On a 1x and a 2x screen.
 * WebGL here is SwiftShader (software): the face's drawing shares the two cores with the model, as on a computer
 * without a usable GPU.
 */
import { chromium } from '@playwright/test';
import { CHROMIUM_ARGS, fakeMicrophone } from '../playwright.config';

export interface LiveDisplay {
  device_scale_factor: number;
  /** The face's renders per second while recording, and at rest (idle life: breathing, blinks). */
  renders_per_second: number;
  idle_renders_per_second: number;
  /** Live frames the model made in the whole take; the frames the speech of the counted seconds has (fps x seconds),
   * and how many of those the face showed (the rest passed unseen). */
  frames_made: number;
  frames_in_window: number;
  frames_shown: number;
  /** Median time between two live frames shown (ms). */
  shown_gap_p50_ms: number;
  /** Choosing the first sample clip -> its take ready (ms). */
  sample_ms: number;
}

/** Counts the view's renders and its setVertices calls (the frames shown) from now on (from zero when called again). */
const COUNT = `(() => {
  globalThis.counts = { renders: 0, shown: [] };
  const v = globalThis.talkingFace.view, r = v.renderer;
  if (v.counted) return;
  v.counted = true;
  const render = r.render.bind(r), set = v.setVertices.bind(v);
  r.render = (a, b) => (globalThis.counts.renders++, render(a, b));
  v.setVertices = (x) => (globalThis.counts.shown.push(performance.now()), set(x));
})()`;

export async function measureLiveDisplay(url: string, wav: string, scale: number, seconds = 8): Promise<LiveDisplay> {
  const mic = fakeMicrophone(wav);
  const browser = await chromium.launch({ ...mic, args: [...CHROMIUM_ARGS, ...mic.args.filter((a) => !CHROMIUM_ARGS.includes(a))] });
  try {
    const page = await browser.newPage({ viewport: { width: 1000, height: 800 }, deviceScaleFactor: scale });
    await page.goto(url);
    await page.waitForSelector('body[data-engine=ready]', { timeout: 60_000 });
    await page.waitForTimeout(1500); // the face at rest computed and shown
    await page.evaluate(COUNT);
    await page.waitForTimeout(3000);
    const idle = await page.evaluate('globalThis.counts.renders') as number;
    await page.click('#record-button');
    await page.waitForSelector('body[data-recording=true]', { timeout: 20_000 });
    await page.evaluate(COUNT); // counted from here: the renders while the recording starts up are no live frames
    const t0 = Date.now();
    await page.waitForTimeout(seconds * 1000);
    const during = await page.evaluate(`({ renders: globalThis.counts.renders, shown: globalThis.counts.shown.slice() })`) as { renders: number; shown: number[] };
    const elapsed = (Date.now() - t0) / 1000;
    await page.click('#record-button');
    await page.waitForSelector('body[data-take=ready]', { timeout: 60_000 });
    const made = await page.evaluate('globalThis.talkingFace.take.animation.frames') as number;
    const fps = await page.evaluate('globalThis.talkingFace.take.animation.fps') as number;
    const gaps = during.shown.slice(1).map((t, i) => t - during.shown[i]).sort((a, b) => a - b);
    const t1 = Date.now();
    await page.locator('#sample-select').selectOption({ index: 1 });
    await page.waitForFunction(() => document.body.dataset.take === 'ready' && (globalThis as unknown as { talkingFace: { take: { name: string } } }).talkingFace.take.name !== 'Recording', null, { timeout: 60_000 });
    return {
      device_scale_factor: scale, renders_per_second: during.renders / elapsed, idle_renders_per_second: idle / 3,
      frames_made: made, frames_in_window: Math.round(fps * elapsed), frames_shown: during.shown.length, shown_gap_p50_ms: gaps[gaps.length >> 1] ?? NaN, sample_ms: Date.now() - t1,
    };
  } finally {
    await browser.close();
  }
}

export function printLiveDisplay(runs: LiveDisplay[]): void {
  for (const r of runs) {
    console.log(`live in the demo (${r.device_scale_factor}x screen): face drawn ${r.renders_per_second.toFixed(1)} times a second ` +
      `(${r.idle_renders_per_second.toFixed(1)} at rest), ${r.frames_shown} of the ${r.frames_in_window} live frames of those seconds shown ` +
      `(one every ${r.shown_gap_p50_ms.toFixed(0)} ms, median); a sample clip animated in ${(r.sample_ms / 1000).toFixed(1)} s`);
  }
}
