/**
 * npm run compare: this project and in-browser lip-sync peers on the same test-split clips, in one headless
 * Chromium session (dev/compare.html), each run as its authors ship it; writes docs/results/peers.md and .json.
 *
 *   npm run compare [-- --corpus data/corpus --max-clips 80]       (npm run compare -- --help: the options, USAGE below)
 *   npm run compare -- --samples runs/reserved --out docs/results/peers-reserved
 *
 * Clips: the corpus's test split (unseen voices, sentences and faces); with --samples DIR, the clips of
 * DIR/index.json (models/samples' form: name, source, audio, phones), such as the reserved recordings of real
 * speakers (`scripts/py -m talkingface.train.reserved export DIR`).
 * --out BASE writes BASE.md and BASE.json instead of docs/results/peers.*. The same segment measures for every system, each on the output it has:
 * - this project: the inner-lip gap (closed below 1 mm, open above 3 mm), as talkingface.train.evaluate;
 * - HeadAudio: its viseme at each 16 ms step (no event = sil): closed = PP, open = aa, O or E;
 * - wlipsync: its vowel class and volume every 16 ms, calibrated (as uLipSync is) on vowels of the corpus's train
 *   split: closed = its mouth scale (volume) under 0.1 or its silence class, open = A, E or O with volume over 0.5.
 * A segment counts when the criterion holds at one or more output frames inside it (as evaluate); silence counts
 * as at rest when it holds on most of the pause's frames. Chance: the same output shifted in time against the
 * phones. Latency is algorithmic: how much audio after an instant each system needs before it shows that instant.
 */
import { chromium } from '@playwright/test';
import { cpus, loadavg } from 'node:os';
import { existsSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { CHROMIUM_ARGS } from '../playwright.config';
import { readWav16 } from '../tests/e2e/helpers/audio';
import { envPort, portFree, readOptions, startServer, usageError, within } from './script-cli';

const ROOT = resolve(import.meta.dirname, '..');
const args = process.argv.slice(2);
const USAGE = `npm run compare [-- OPTIONS]   this project and in-browser lip-sync peers on the same clips -> docs/results/peers.md/.json
  --corpus DIR       the corpus whose test split is measured (default data/corpus)
  --max-clips N      at most N clips (default 80 of the test split; a --samples folder whole)
  --samples DIR      the clips of DIR/index.json instead (models/samples' form), e.g. the reserved recordings;
                     with --out
  --out BASE         write BASE.md and BASE.json (default docs/results/peers)
  COMPARE_PORT=N     serve the pages on port N (default 4193; it must be free)`;
const o = readOptions('compare', USAGE, { corpus: { type: 'string' }, 'max-clips': { type: 'string' }, samples: { type: 'string' }, out: { type: 'string' } });
const CORPUS = resolve(ROOT, String(o.corpus ?? 'data/corpus'));
if (o.samples && !o.out) usageError('compare', USAGE, '--samples needs --out: the default, docs/results/peers, holds the test split\'s figures');
if (o.corpus && !o.samples && !existsSync(resolve(CORPUS, 'splits.json'))) usageError('compare', USAGE, `--corpus ${o.corpus}: no corpus there (no splits.json; build one: scripts/py -m talkingface.corpus build)`);
// The test split is cut to 80 clips unless told otherwise; a --samples folder is measured whole unless told otherwise.
const MAX_CLIPS = o['max-clips'] === undefined ? (o.samples ? Infinity : 80) : Number(o['max-clips']);
if (!(Number.isInteger(MAX_CLIPS) && MAX_CLIPS > 0) && MAX_CLIPS !== Infinity) usageError('compare', USAGE, `--max-clips takes a whole number above 0 (not ${o['max-clips']})`);
const SAMPLES = o.samples ? resolve(ROOT, String(o.samples)) : null;
const OUT = resolve(ROOT, String(o.out ?? 'docs/results/peers'));
if (!existsSync(dirname(OUT))) usageError('compare', USAGE, `--out ${o.out}: the folder ${dirname(OUT)} does not exist`);
const PORT = envPort('compare', USAGE, 'COMPARE_PORT', 4193);
const BILABIALS = new Set(['P', 'B', 'M']);
const OPEN_VOWELS = new Set(['AA', 'AE', 'AH', 'AO', 'AW', 'AY']); // corpus/checks.py OPEN_VOWELS
const HA_NAMES = ['aa', 'E', 'I', 'O', 'U', 'PP', 'SS', 'TH', 'DD', 'FF', 'kk', 'nn', 'RR', 'CH', 'sil'];
const HA_HOP = 0.016; // HeadAudio: 256-sample hop at 16 kHz (modules/processor.mjs)
const SHIFTS = [0.25, 0.5, 0.75];
const WL_HOP = 0.016; // src/dev/compare.ts WL_BLOCK at 16 kHz
// uLipSync's five vowels (and its silence) from ARPAbet, for wlipsync's calibration.
const WL_CLASSES: Record<string, string[]> = { A: ['AA', 'AE', 'AH'], I: ['IY', 'IH'], U: ['UW', 'UH'], E: ['EH', 'EY'], O: ['AO', 'OW'], '-': ['SIL'] };

/** 1024-sample excerpts from the middle of each vowel class (and pauses) of the train split, one per clip and class. */
function calibrationSnapshots(perClass = 16): Record<string, number[][]> | null {
  if (!existsSync(resolve(CORPUS, 'splits.json'))) return null;
  const keys: string[] = JSON.parse(readFileSync(resolve(CORPUS, 'splits.json'), 'utf8')).train;
  const out: Record<string, number[][]> = Object.fromEntries(Object.keys(WL_CLASSES).map((k) => [k, []]));
  for (let i = 0; i < keys.length && Object.values(out).some((v) => v.length < perClass); i += 7) { // every 7th clip: many voices
    const a = JSON.parse(readFileSync(resolve(CORPUS, 'alignments', `${keys[i]}.json`), 'utf8'));
    const x = readWav16(resolve(CORPUS, 'wav', `${keys[i]}.wav`));
    for (const [name, phones] of Object.entries(WL_CLASSES)) {
      if (out[name].length >= perClass) continue;
      const seg = (a.phones as Phone[]).find(([p, s, e]) => phones.includes(p) && e - s >= (name === '-' ? 0.3 : 0.07) && s > 0.05);
      if (!seg) continue;
      const c = Math.round(((seg[1] + seg[2]) / 2) * 16000);
      if (c - 512 >= 0 && c + 512 <= x.length) out[name].push(Array.from(x.subarray(c - 512, c + 512)));
    }
  }
  return out;
}

type Phone = [string, number, number];
interface Clip { key: string; source: string; samples: Float32Array; phones: Phone[] }

function loadSamples(dir: string, what: string): { clips: Clip[]; from: string } {
  const index = resolve(dir, 'index.json');
  if (!existsSync(index)) throw new Error(`no ${index}: --samples names a folder with an index.json (models/samples' form)`);
  const clips = JSON.parse(readFileSync(index, 'utf8')).clips.slice(0, MAX_CLIPS);
  return {
    from: `the ${clips.length} ${what}`,
    clips: clips.map((c: { name: string; source: string; audio: string; phones: Phone[] }) =>
      ({ key: c.name, source: c.source, samples: readWav16(resolve(dir, c.audio)), phones: c.phones })),
  };
}

function loadClips(): { clips: Clip[]; from: string } {
  if (SAMPLES) return loadSamples(SAMPLES, `clips in ${SAMPLES.replace(ROOT + '/', '')}`);
  if (existsSync(resolve(CORPUS, 'splits.json'))) {
    const keys: string[] = JSON.parse(readFileSync(resolve(CORPUS, 'splits.json'), 'utf8')).test.slice(0, MAX_CLIPS);
    return {
      from: `${keys.length} clips of the test split of ${CORPUS.replace(ROOT + '/', '')}`,
      clips: keys.map((key) => {
        const a = JSON.parse(readFileSync(resolve(CORPUS, 'alignments', `${key}.json`), 'utf8'));
        return { key, source: a.source, samples: readWav16(resolve(CORPUS, 'wav', `${key}.wav`)), phones: a.phones };
      }),
    };
  }
  // Not the three sample clips in its place: their figures would replace the test split's in docs/results/peers.md.
  return usageError('compare', USAGE, `no corpus at ${CORPUS} (build it: scripts/py -m talkingface.corpus build --preset full --seed 0 --out data/corpus), ` +
    'or measure the sample clips elsewhere: --samples models/samples --out runs/peers-samples');
}

/** Output frames of a system whose frame k shows t = k * step (+ offset) that fall in [a, b); the nearest if none. */
function framesIn(a: number, b: number, step: number, count: number): number[] {
  const out: number[] = [];
  for (let k = Math.max(0, Math.ceil(a / step - 1e-6)); k < Math.min(count, Math.ceil(b / step - 1e-6)); k++) out.push(k);
  return out.length ? out : [Math.min(count - 1, Math.max(0, Math.round((a + b) / 2 / step)))];
}

interface Counts { closed: number; bilabial: number; falseClosed: number; other: number; opened: number; open: number; rest: number; pauses: number }
const zero = (): Counts => ({ closed: 0, bilabial: 0, falseClosed: 0, other: 0, opened: 0, open: 0, rest: 0, pauses: 0 });

/** Segment counts for one system's per-frame states (closed / open / at rest) on a clip's phones. */
function count(phones: Phone[], step: number, states: { closed: boolean[]; open: boolean[]; rest: boolean[] }, c: Counts): void {
  const F = states.closed.length;
  for (const [p, a, b] of phones) {
    const k = framesIn(a, b, step, F);
    if (p === 'SIL') {
      if (b - a >= 0.3) {
        c.pauses++;
        c.rest += Number(k.filter((i) => states.rest[i]).length > k.length / 2);
      }
      continue;
    }
    const closed = k.some((i) => states.closed[i]);
    if (BILABIALS.has(p)) { c.bilabial++; c.closed += Number(closed); } else { c.other++; c.falseClosed += Number(closed); }
    if (OPEN_VOWELS.has(p) && b - a >= 0.08) { c.open++; c.opened += Number(k.some((i) => states.open[i])); }
  }
}

function roll<T>(x: T[], by: number): T[] {
  const s = ((by % x.length) + x.length) % x.length;
  return [...x.slice(x.length - s), ...x.slice(0, x.length - s)];
}

async function main() {
  const { clips, from } = loadClips();
  if (!(await portFree(PORT))) throw new Error(`port ${PORT} is in use (another server would answer): free it, or set COMPARE_PORT`);
  const server = startServer('npx', ['vite', '--host', '127.0.0.1', '--port', String(PORT), '--strictPort'], ROOT);
  try {
    await server.ready(`http://127.0.0.1:${PORT}/dev/compare.html`, 120);
  } catch (e) {
    server.stop();
    throw e;
  }
  const browser = await chromium.launch({ executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium', args: CHROMIUM_ARGS });
  const t0 = Date.now();
  try {
    const page = await browser.newPage();
    await page.goto(`http://127.0.0.1:${PORT}/dev/compare.html`);
    await page.waitForFunction(() => (globalThis as unknown as { compare?: unknown }).compare, null, { timeout: 120_000 });
    const info = await page.evaluate(() => {
      const c = (globalThis as unknown as { compare: { error?: string; lookAheadMs: number; fps: number; backend: string } }).compare;
      return { error: c.error, lookAheadMs: c.lookAheadMs, fps: c.fps, backend: c.backend };
    });
    if (info.error) throw new Error(info.error);
    const snapshots = calibrationSnapshots();
    const wlEntries = snapshots ? await page.evaluate(async (s) => (globalThis as unknown as { compare: { calibrate(s: Record<string, number[][]>): Promise<number> } }).compare.calibrate(s), snapshots) : 0;
    const group = () => ({ ours: zero(), oursChance: zero(), ha: zero(), haChance: zero(), wl: zero(), wlChance: zero() });
    const groups = { all: group(), human: group() };
    const cost = { ours: 0, ha: 0, wl: 0, seconds: 0 };
    for (const [i, clip] of clips.entries()) {
      const r = await within(page.evaluate(async (s) => (globalThis as unknown as { compare: { compareClip(s: number[]): Promise<{
        ours: { gapMm: number[]; ms: number }; headaudio: { events: { viseme: number; t: number }[]; ms: number };
        wlipsync?: { names: string[]; volume: number[]; ms: number } }> } }).compare.compareClip(s),
        Array.from(clip.samples)), 300, `clip ${clip.key ?? i} in the page`);
      const seconds = clip.samples.length / 16000;
      cost.ours += r.ours.ms; cost.ha += r.headaudio.ms; cost.wl += r.wlipsync?.ms ?? 0; cost.seconds += seconds;
      const gap = r.ours.gapMm;
      const ours = { closed: gap.map((g) => g < 1), open: gap.map((g) => g > 3), rest: gap.map((g) => g < 1) };
      const steps = Math.ceil(seconds / HA_HOP);
      const vis = new Array<number>(steps).fill(14);
      for (const e of r.headaudio.events) {
        const k = Math.round(e.t / HA_HOP);
        if (k >= 0 && k < steps) vis[k] = e.viseme;
      }
      const ha = { closed: vis.map((v) => v === 5), open: vis.map((v) => v === 0 || v === 3 || v === 1), rest: vis.map((v) => v === 14) };
      // wlipsync's k-th analysis covers the block ending at (k + 1) * hop: its centre is half a window (32 ms) earlier.
      const wlShift = Math.round(0.032 / WL_HOP) - 1;
      const w = r.wlipsync;
      const wlState = w ? (() => {
        const names = [...w.names.slice(wlShift), ...new Array(Math.max(0, wlShift)).fill('-')];
        const vol = [...w.volume.slice(wlShift), ...new Array(Math.max(0, wlShift)).fill(0)];
        return { closed: vol.map((v, k) => v < 0.1 || names[k] === '-'), open: vol.map((v, k) => v > 0.5 && 'AEO'.includes(names[k])), rest: vol.map((v, k) => v < 0.1 || names[k] === '-') };
      })() : null;
      for (const g of clip.source === 'human' ? [groups.all, groups.human] : [groups.all]) {
        count(clip.phones, 1 / info.fps, ours, g.ours);
        count(clip.phones, HA_HOP, ha, g.ha);
        if (wlState) count(clip.phones, WL_HOP, wlState, g.wl);
        for (const s of SHIFTS) {
          const shift = <T>(x: { closed: T[]; open: T[]; rest: T[] }) => ({ closed: roll(x.closed, Math.round(s * x.closed.length)), open: roll(x.open, Math.round(s * x.open.length)), rest: roll(x.rest, Math.round(s * x.rest.length)) });
          count(clip.phones, 1 / info.fps, shift(ours) as typeof ours, g.oursChance);
          count(clip.phones, HA_HOP, shift(ha) as typeof ha, g.haChance);
          if (wlState) count(clip.phones, WL_HOP, shift(wlState) as typeof ha, g.wlChance);
        }
      }
      process.stderr.write(`\r${i + 1}/${clips.length} clips`);
    }
    process.stderr.write('\n');
    const rate = (a: number, b: number) => (b ? a / b : 0);
    const summary = (c: Counts, chance: Counts) => ({
      bilabial_segments: c.bilabial, closure: rate(c.closed, c.bilabial), false_closure: rate(c.falseClosed, c.other),
      chance_closure: rate(chance.closed, chance.bilabial), open_vowel_opened: rate(c.opened, c.open), pauses: c.pauses, rest_in_pauses: rate(c.rest, c.pauses),
    });
    const result = {
      clips: from, audio_seconds: cost.seconds, backend: info.backend,
      // Costs are of this machine as it was: the load average says how busy (other work slows every system alike).
      machine: { cores: cpus().length, load_average: loadavg(), browser: browser.version(), seconds: (Date.now() - t0) / 1000, date: new Date().toISOString() },
      systems: {
        'talking-face (this project)': {
          output: 'inner-lip gap per 1/30 s frame', all: summary(groups.all.ours, groups.all.oursChance),
          human: summary(groups.human.ours, groups.human.oursChance),
          ms_per_audio_second: cost.ours / cost.seconds, algorithmic_latency_ms: info.lookAheadMs,
          latency_note: 'manifest.look_ahead_ms: one future content frame + the encoder\'s reach + half a Mel frame',
        },
        'HeadAudio 0.1.0': {
          output: 'Oculus viseme per 16 ms (PP = closed; aa, E, O = open; sil = rest)', all: summary(groups.all.ha, groups.all.haChance),
          human: summary(groups.human.ha, groups.human.haChance),
          ms_per_audio_second: cost.ha / cost.seconds, algorithmic_latency_ms: 16 + 48,
          latency_note: 'half its 32 ms window (its events are stamped at the window centre) + its 6-frame majority vote (3 hops of 16 ms); its node then ramps over 100 ms',
        },
      },
      not_run: {} as Record<string, string>,
    };
    if (wlEntries) {
      (result.systems as Record<string, unknown>)['wlipsync 1.3.1'] = {
        output: `uLipSync vowel class (A I U E O, silence) and volume per 16 ms; profile calibrated on the train split (${wlEntries} snapshots per entry, 12 entries)`,
        all: summary(groups.all.wl, groups.all.wlChance), human: summary(groups.human.wl, groups.human.wlChance),
        ms_per_audio_second: cost.wl / cost.seconds, algorithmic_latency_ms: 32,
        latency_note: 'half its 64 ms analysis window (1024 samples at 16 kHz); its node then smooths over about 50 ms',
      };
    } else {
      result.not_run['wlipsync 1.3.1'] = 'needs a uLipSync profile calibrated on speech; built from the corpus\'s train split, which is not built here';
    }
    writeFileSync(`${OUT}.json`, JSON.stringify(result, null, 1) + '\n');
    writeFileSync(`${OUT}.md`, markdown(result));
    console.log(markdown(result));
  } finally {
    await browser.close();
    server.stop();
  }
}

function markdown(r: { clips: string; audio_seconds: number; machine: { cores: number; load_average: number[]; date: string }; systems: Record<string, { output: string; all: Record<string, number>; human: Record<string, number>; ms_per_audio_second: number; algorithmic_latency_ms: number; latency_note: string }>; not_run: Record<string, string> }): string {
  const pct = (x: number) => `${(100 * x).toFixed(1)}%`;
  const rows: string[] = [];
  for (const [name, s] of Object.entries(r.systems)) {
    for (const [g, label] of [['all', 'all'], ['human', 'recorded speech']] as const) {
      const m = s[g];
      if (!m.bilabial_segments) continue;
      if (g === 'human' && m.bilabial_segments === s.all.bilabial_segments && m.pauses === s.all.pauses) continue; // every clip is recorded speech
      rows.push(`| ${name} | ${label} | ${m.bilabial_segments} | **${pct(m.closure)}** / ${pct(m.false_closure)} / ${pct(m.chance_closure)} | ${pct(m.open_vowel_opened)} | ${pct(m.rest_in_pauses)} of ${m.pauses} | ${g === 'all' ? s.ms_per_audio_second.toFixed(1) : ''} | ${g === 'all' ? s.algorithmic_latency_ms : ''} |`);
    }
  }
  return [
    '# Peers side by side', '',
    `Made by \`npm run compare${args.length ? ' -- ' + args.join(' ') : ''}\` on ${r.clips} (${r.audio_seconds.toFixed(0)} s of audio), every system in the same headless Chromium session.`,
    'Closed: the mouth closed (our gap < 1 mm; HeadAudio\'s PP viseme) at one or more output frames of a /p b m/ segment; false: the same in',
    'other speech segments; chance: the same output shifted in time against the phones. Open: an open vowel (80 ms or more) with the mouth',
    'open (gap > 3 mm; aa, E or O). Rest: pauses of 0.3 s or more at rest on most of their frames (gap < 1 mm; sil or no viseme).',
    `Cost: milliseconds of compute per second of audio on ${r.machine.cores} cores (load average ${r.machine.load_average.map((x) => x.toFixed(1)).join(', ')}; ${r.machine.date.slice(0, 10)}), all systems in turn in one run: compare them as ratios. Latency: algorithmic, ms of audio needed after an instant.`, '',
    '| system | clips | /p b m/ | closed / false / chance | open vowels opened | pauses at rest | cost (ms per s) | latency (ms) |',
    '| --- | --- | --- | --- | --- | --- | --- | --- |', ...rows, '',
    ...Object.entries(r.systems).map(([n, s]) => `- ${n}: ${s.output}; latency: ${s.latency_note}.`),
    ...Object.entries(r.not_run).map(([n, why]) => `- Not run: ${n}: ${why}.`), '',
  ].join('\n');
}

main().catch((e) => {
  console.error(`compare: ${(e as Error).message}`);
  process.exit(1);
});
