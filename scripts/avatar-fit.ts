/**
 * npm run avatar-fit: how much of the model's predicted motion the ARKit weights reproduce, and what the solver
 * costs per frame; writes docs/results/avatar.md and .json.
 *
 *   npm run avatar-fit [-- --corpus data/corpus --max-clips 80 --port 4195]
 *   npm run avatar-fit -- --from-json      (rewrite the .md from the .json, nothing run)
 *
 * Clips: the corpus's test split (unseen voices, sentences and faces) when it is built, else the three sample clips
 * in models/samples. The engine runs in headless Chromium (dev/avatar-fit.html) with `blendshapes: true`; here, each
 * frame's weights are turned back into a displacement (neutral + B w) and compared with the model's own
 * displacement O, region by region (mm). Where the clip has ground truth (the sample clips) the prediction and its
 * ARKit reconstruction are also both compared with the truth. The solver's cost is measured here (Node, one thread,
 * the solve alone) and in the page (the whole avatar stage: solve, visemes, head angles).
 */
import { chromium } from '@playwright/test';
import { existsSync, readFileSync, writeFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { CHROMIUM_ARGS } from '../playwright.config';
import { readWav16 } from '../tests/e2e/helpers/audio';
import { decodeTemplate, lipMask, MM_PER_UNIT } from '../src/template/face-template';
import { arkitBasis } from '../src/avatar/basis';
import { faceFields } from '../src/avatar/fields';
import { BlendshapeSolver } from '../src/avatar/solver';
import { ARKIT_INDEX, ARKIT_NAMES, VISEME_NAMES } from '../src/avatar/names';
import { portFree, readOptions, startServer, usageError, within } from './script-cli';

const ROOT = resolve(import.meta.dirname, '..');
const USAGE = `usage: npm run avatar-fit [-- --corpus data/corpus --max-clips 80 --port 4195]
       npm run avatar-fit -- --from-json      (rewrite docs/results/avatar.md from its .json, nothing run)`;
const opts = readOptions('avatar-fit', USAGE, {
  corpus: { type: 'string', default: 'data/corpus' }, 'max-clips': { type: 'string', default: '80' },
  port: { type: 'string', default: '4195' }, 'from-json': { type: 'boolean' },
});
const whole = (name: string, low: number): number => {
  const v = Number(opts[name]);
  return Number.isInteger(v) && v >= low ? v : usageError('avatar-fit', USAGE, `--${name} ${String(opts[name])}: a whole number from ${low}`);
};
const CORPUS = resolve(ROOT, String(opts.corpus));
const MAX_CLIPS = whole('max-clips', 1);
const PORT = whole('port', 1);
const OPEN_VOWELS = new Set(['AA', 'AE', 'AH', 'AO', 'AW', 'AY']); // talkingface.phones.OPEN_VOWELS
const BILABIALS = new Set(['P', 'B', 'M']);

type Phone = [string, number, number];
interface Clip { key: string; samples: Float32Array; phones: Phone[]; truth?: { neutral: Float32Array; offsetsMm: Float32Array; frames: number } }

const buf = (p: string) => { const b = readFileSync(p); return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength) as ArrayBuffer; };
const f32 = (b64: string) => { const b = Buffer.from(b64, 'base64'); return new Float32Array(b.buffer, b.byteOffset, b.byteLength / 4); };

function loadClips(): { clips: Clip[]; source: string } {
  if (existsSync(resolve(CORPUS, 'splits.json'))) {
    const keys: string[] = JSON.parse(readFileSync(resolve(CORPUS, 'splits.json'), 'utf8')).test.slice(0, MAX_CLIPS);
    return {
      source: `the corpus's test split (${keys.length} clips, ${CORPUS.replace(ROOT + '/', '')})`,
      clips: keys.map((key) => ({ key, samples: readWav16(resolve(CORPUS, 'wav', `${key}.wav`)),
        phones: JSON.parse(readFileSync(resolve(CORPUS, 'alignments', `${key}.json`), 'utf8')).phones })),
    };
  }
  const dir = resolve(ROOT, 'models/samples');
  const index = JSON.parse(readFileSync(resolve(dir, 'index.json'), 'utf8'));
  return {
    source: `the ${index.clips.length} sample clips of models/samples (test split; the corpus is not built here)`,
    clips: index.clips.map((c: { name: string; audio: string; ground_truth: string; frames: number; vertices: number; phones: Phone[] }) => {
      const b = buf(resolve(dir, c.ground_truth));
      const n3 = c.vertices * 3;
      const micrometres = new Int16Array(b, n3 * 4, c.frames * n3);
      return { key: c.name, samples: readWav16(resolve(dir, c.audio)), phones: c.phones,
        truth: { neutral: new Float32Array(b, 0, n3), offsetsMm: Float32Array.from(micrometres, (x) => x / 1000), frames: c.frames } };
    }),
  };
}

/** Frames whose centre lies inside a segment of one of `phones` (the segment's middle 60%, clear of the edges). */
function framesOf(phones: Phone[], set: Set<string>, fps: number, frames: number): number[] {
  const out: number[] = [];
  for (const [p, s, e] of phones) {
    if (!set.has(p)) continue;
    const a = s + 0.2 * (e - s), b = e - 0.2 * (e - s);
    for (let f = Math.ceil(a * fps); f <= Math.floor(b * fps) && f < frames; f++) out.push(f);
  }
  return out;
}

async function main(): Promise<void> {
  const { clips, source } = loadClips();
  const manifest = JSON.parse(readFileSync(resolve(ROOT, 'models/manifest.json'), 'utf8'));
  const fps: number = manifest.audio.fps;
  const template = await decodeTemplate(JSON.parse(readFileSync(resolve(ROOT, 'models/template/template.json'), 'utf8')), buf(resolve(ROOT, 'models/template/template.bin')));
  const mm = MM_PER_UNIT[template.units];
  const n = template.vertexCount, n3 = n * 3;
  const basis = arkitBasis(template);
  const solver = new BlendshapeSolver(basis);
  const fields = faceFields(template);

  // Regions, each vertex in one: lips, jaw (below the mouth corners), eyes (the lids' fields), brows, the rest.
  const lips = lipMask(template);
  const jaw = new Set(template.regions.jaw);
  const eye = (i: number) => [fields.eyes.left, fields.eyes.right].some((e) => e.wUpper[i] > 0.05 || e.wLower[i] > 0.05);
  const regionOf = Array.from({ length: n }, (_, i) => lips[i] ? 'lips' : eye(i) ? 'eyes' : fields.wBrow[i] > 0.05 ? 'brows' : jaw.has(i) ? 'jaw' : 'rest');
  const REGIONS = ['lips', 'jaw', 'eyes', 'brows', 'rest', 'face'] as const;
  const acc = Object.fromEntries(REGIONS.map((r) => [r, { err: 0, err2: 0, motion2: 0, worst: 0, vertexFrames: 0, frames: 0 }]));
  const truthAcc = { predLip: 0, reconLip: 0, predMean: 0, reconMean: 0, frames: 0 };
  const classes = { open: { jawOpen: [] as number[], mouthClose: [] as number[], pp: [] as number[], aa: [] as number[] },
    bilabial: { jawOpen: [] as number[], mouthClose: [] as number[], pp: [] as number[], aa: [] as number[] } };
  const solveMs: number[] = [];
  const solves: number[] = [];
  let pageStageMs = 0, pageFrames = 0, unposedChange = 0, streamChange = 0;

  if (!clips.length) throw new Error(`no clips to measure in ${source}`);
  if (!(await portFree(PORT))) throw new Error(`port ${PORT} is in use (another server would answer): free it, or give --port`);
  // (script-cli stops it on Ctrl-C and on any exit, the finally below or not)
  const server = startServer('npx', ['vite', '--host', '127.0.0.1', '--port', String(PORT), '--strictPort'], ROOT);
  await server.ready(`http://127.0.0.1:${PORT}/dev/avatar-fit.html`, 120);
  const browser = await chromium.launch({ executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium', args: CHROMIUM_ARGS });
  let info: Record<string, unknown> = {};
  try {
    const page = await browser.newPage();
    await page.goto(`http://127.0.0.1:${PORT}/dev/avatar-fit.html`);
    await page.waitForFunction(() => document.getElementById('status')?.textContent === 'Ready.', undefined, { timeout: 120_000 });
    info = await page.evaluate(() => (globalThis as unknown as { avatarFit: { info(): Record<string, unknown> } }).avatarFit.info());
    for (const [c, clip] of clips.entries()) {
      const r = await within(page.evaluate(async (s) => (globalThis as unknown as { avatarFit: { clip(s: number[]): Promise<{
        frames: number; unposed: string; arkit: string; visemes: string; stageMs: { blendshapes: number }; unposedChange: number; streamChange: number }> } })
        .avatarFit.clip(s), Array.from(clip.samples)), 300, `clip ${clip.key} in the page`);
      const F = r.frames, unposed = f32(r.unposed), arkit = f32(r.arkit), visemes = f32(r.visemes);
      pageStageMs += r.stageMs.blendshapes;
      pageFrames += F;
      unposedChange = Math.max(unposedChange, r.unposedChange);
      streamChange = Math.max(streamChange, r.streamChange);
      const state = solver.newState();
      const w = new Float32Array(ARKIT_NAMES.length);
      const O = new Float32Array(n3);
      for (let f = 0; f < F; f++) {
        for (let i = 0; i < n3; i++) O[i] = (unposed[f * n3 + i] - template.positions[i]) * mm; // the model's displacement, mm
        const t = performance.now();
        solver.solve(O, 0, state, w);
        solveMs.push(performance.now() - t);
        solves.push(solver.lastSolves);
        const recon = solver.reconstruct(arkit, f * ARKIT_NAMES.length);
        const worst: Record<string, number> = {};
        for (let v = 0; v < n; v++) {
          const e = Math.hypot(recon[3 * v] - O[3 * v], recon[3 * v + 1] - O[3 * v + 1], recon[3 * v + 2] - O[3 * v + 2]);
          const m = Math.hypot(O[3 * v] - basis.neutralOffset[3 * v], O[3 * v + 1] - basis.neutralOffset[3 * v + 1], O[3 * v + 2] - basis.neutralOffset[3 * v + 2]);
          for (const region of [regionOf[v], 'face']) {
            const a = acc[region];
            a.err += e; a.err2 += e * e; a.motion2 += m * m; a.vertexFrames++;
            worst[region] = Math.max(worst[region] ?? 0, e);
          }
        }
        for (const [region, value] of Object.entries(worst)) { acc[region].worst += value; acc[region].frames++; }
        if (clip.truth && f < clip.truth.frames) {
          // The truth's subject has its own face: compare displacements (the prediction's and the weights') with its.
          let pl = 0, rl = 0, pm = 0, rm = 0;
          for (let v = 0; v < n; v++) {
            const t3 = f * n3 + 3 * v;
            const ep = Math.hypot(O[3 * v] - clip.truth.offsetsMm[t3], O[3 * v + 1] - clip.truth.offsetsMm[t3 + 1], O[3 * v + 2] - clip.truth.offsetsMm[t3 + 2]);
            const er = Math.hypot(recon[3 * v] - clip.truth.offsetsMm[t3], recon[3 * v + 1] - clip.truth.offsetsMm[t3 + 1], recon[3 * v + 2] - clip.truth.offsetsMm[t3 + 2]);
            pm += ep / n; rm += er / n;
            if (lips[v]) { pl = Math.max(pl, ep); rl = Math.max(rl, er); }
          }
          truthAcc.predLip += pl; truthAcc.reconLip += rl; truthAcc.predMean += pm; truthAcc.reconMean += rm; truthAcc.frames++;
        }
      }
      for (const [name, set] of [['open', OPEN_VOWELS], ['bilabial', BILABIALS]] as const) {
        for (const f of framesOf(clip.phones, set, fps, F)) {
          classes[name].jawOpen.push(arkit[f * ARKIT_NAMES.length + ARKIT_INDEX.jawOpen]);
          classes[name].mouthClose.push(arkit[f * ARKIT_NAMES.length + ARKIT_INDEX.mouthClose]);
          classes[name].pp.push(visemes[f * VISEME_NAMES.length + VISEME_NAMES.indexOf('viseme_PP')]);
          classes[name].aa.push(visemes[f * VISEME_NAMES.length + VISEME_NAMES.indexOf('viseme_aa')]);
        }
      }
      process.stdout.write(`\r${c + 1}/${clips.length} clips`);
    }
  } finally {
    await browser.close();
    server.stop();
  }
  process.stdout.write('\n');

  const r3 = (x: number) => Math.round(x * 1000) / 1000;
  const mean = (a: number[]) => a.reduce((s, x) => s + x, 0) / Math.max(1, a.length);
  const quantile = (a: number[], q: number) => [...a].sort((x, y) => x - y)[Math.min(a.length - 1, Math.floor(q * a.length))];
  const regions = Object.fromEntries(REGIONS.map((r) => {
    const a = acc[r];
    return [r, { vertices: r === 'face' ? n : regionOf.filter((x) => x === r).length, meanErrorMm: r3(a.err / a.vertexFrames),
      rmsErrorMm: r3(Math.sqrt(a.err2 / a.vertexFrames)), maxErrorMm: r3(a.worst / a.frames),
      rmsMotionMm: r3(Math.sqrt(a.motion2 / a.vertexFrames)), reproduced: r3(1 - a.err2 / Math.max(1e-12, a.motion2)) }];
  }));
  const steady = solveMs.slice(Math.min(solveMs.length - 1, 30)); // after the JIT has warmed up
  const result = {
    source, clips: clips.length, frames: pageFrames, regions,
    phones: Object.fromEntries(Object.entries(classes).map(([k, v]) => [k, { frames: v.jawOpen.length,
      jawOpen: r3(mean(v.jawOpen)), mouthClose: r3(mean(v.mouthClose)), viseme_PP: r3(mean(v.pp)), viseme_aa: r3(mean(v.aa)) }])),
    truth: truthAcc.frames ? { frames: truthAcc.frames, predictionLipMaxMm: r3(truthAcc.predLip / truthAcc.frames), weightsLipMaxMm: r3(truthAcc.reconLip / truthAcc.frames),
      predictionMeanMm: r3(truthAcc.predMean / truthAcc.frames), weightsMeanMm: r3(truthAcc.reconMean / truthAcc.frames) } : null,
    cost: { nodeSolveMsMedian: r3(quantile(steady, 0.5)), nodeSolveMsP95: r3(quantile(steady, 0.95)), linearSolvesPerFrame: r3(mean(solves)),
      pageStageMsPerFrame: r3(pageStageMs / pageFrames), fittedShapes: basis.fitted.filter(Boolean).length, basisBuildMs: r3(Number(info.basisMs)) },
    unposedChangeWithBlendshapes: unposedChange,
    streamedAgainstOffline: streamChange,
    machine: { node: process.version, browser: info.userAgent },
  };
  writeFileSync(resolve(ROOT, 'docs/results/avatar.json'), JSON.stringify(result, null, 2) + '\n');
  writeFileSync(resolve(ROOT, 'docs/results/avatar.md'), report(result));
  console.log(report(result));
}

function report(r: Record<string, any>): string {
  const rows = Object.entries(r.regions as Record<string, Record<string, number>>).map(([name, x]) =>
    `| ${name} | ${x.vertices} | ${x.rmsMotionMm} | ${x.meanErrorMm} | ${x.rmsErrorMm} | ${x.maxErrorMm} | ${(100 * x.reproduced).toFixed(1)}% |`);
  const p = r.phones;
  return `# ARKit weights: how much of the predicted motion they reproduce

Written by \`npm run avatar-fit\` (scripts/avatar-fit.ts) on ${r.source}: ${r.frames} frames. The engine animated each
clip with \`blendshapes: true\` in headless Chromium; each frame's 52 weights were turned back into a displacement
(the neutral face plus the basis times the weights, src/avatar/) and compared with the model's own displacement.

## Fit, region by region (mm)

Motion: RMS of the predicted displacement from the neutral face (lips closed). Error: between the weights'
reconstruction and the prediction, mean and RMS over vertices and frames; max: the largest vertex error per frame,
averaged over frames (as E_vl). Reproduced: 1 - error^2 / motion^2, summed over the region.

| region | vertices | motion RMS | error mean | error RMS | max per frame | reproduced |
| --- | --- | --- | --- | --- | --- | --- |
${rows.join('\n')}

Regions: lips (the lip surface, as E_vl's), eyes (the lids' rig fields), brows (the brows' rig field), jaw (below
the mouth corners), rest (nose, cheeks, forehead, outline); face: all ${r.regions.face.vertices} vertices. The model
barely moves the eyes and brows (RMS ${r.regions.eyes.rmsMotionMm} and ${r.regions.brows.rmsMotionMm} mm: no blinks, which
audio does not predict), so the share reproduced there is a share of almost nothing; the sparse solver leaves such
motion at 0 rather than spend eyeBlink or brow weights on it.
${r.truth ? `
Against the ground truth (${r.truth.frames} frames with truth): the prediction's largest lip error per frame
${r.truth.predictionLipMaxMm} mm, the weights' reconstruction's ${r.truth.weightsLipMaxMm} mm (mean over all vertices
${r.truth.predictionMeanMm} and ${r.truth.weightsMeanMm} mm; displacements compared, the truth's subject has its own face).
` : ''}
## The weights on the phones (frames in the middle 60% of each segment)

| phones | frames | jawOpen | mouthClose | viseme_PP | viseme_aa |
| --- | --- | --- | --- | --- | --- |
| open vowels (AA AE AH AO AW AY) | ${p.open.frames} | ${p.open.jawOpen} | ${p.open.mouthClose} | ${p.open.viseme_PP} | ${p.open.viseme_aa} |
| /p b m/ | ${p.bilabial.frames} | ${p.bilabial.jawOpen} | ${p.bilabial.mouthClose} | ${p.bilabial.viseme_PP} | ${p.bilabial.viseme_aa} |

## Cost

The solver (bounded least squares over the ${r.cost.fittedShapes} fitted shapes, warm-started from the previous frame):
median ${r.cost.nodeSolveMsMedian} ms per frame, p95 ${r.cost.nodeSolveMsP95} ms (Node ${r.machine.node}, one thread,
the solve alone), ${r.cost.linearSolvesPerFrame} Cholesky solves per frame on average. The whole avatar stage in the page
(solve, visemes, head angles): ${r.cost.pageStageMsPerFrame} ms per frame. Building the basis and the solver once:
${r.cost.basisBuildMs} ms. The frames themselves do not change with the option on (largest difference:
${r.unposedChangeWithBlendshapes}); the weights of each clip streamed in 40 ms pieces equal the offline ones (largest
difference: ${r.streamedAgainstOffline}).
`;
}

if (opts['from-json']) {
  writeFileSync(resolve(ROOT, 'docs/results/avatar.md'), report(JSON.parse(readFileSync(resolve(ROOT, 'docs/results/avatar.json'), 'utf8'))));
} else await main();
