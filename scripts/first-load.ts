/**
 * The demo's first load as a new visitor meets it (issue 18), measured in headless Chromium by npm run bench:
 * every file fetched with the bytes that crossed the wire (compressed body plus headers) and how often it was
 * fetched, and the time from navigation to the face shown and to the model ready. Each load is a fresh browser
 * context (an empty cache); the times are the median of `loads` loads.
 */
import type { Browser, Request } from '@playwright/test';

export interface FetchedFile {
  path: string;
  /** Bytes transferred: the (compressed) body plus the response headers. */
  bytes: number;
  /** Times the file crossed the network (a cache hit is not counted). */
  fetches: number;
  encoding: string;
}

export interface FirstLoad {
  total_bytes: number;
  total_mib: number;
  files: FetchedFile[];
  /** Paths fetched more than once in one load. */
  fetched_twice: string[];
  /** Navigation start -> the face drawn (body[data-ready]), and -> the model ready to animate (body[data-engine]). */
  face_shown_ms: number;
  ready_ms: number;
  /** Each load's ready_ms, in order. */
  ready_ms_each: number[];
  /**
   * The floor under ready_ms: the same time on dev/ort-start.html, which starts onnxruntime-web and the encoders'
   * sessions as the engine does and nothing else (no face, no decoder); median, and each load.
   */
  onnxruntime_alone_ms?: number;
  onnxruntime_alone_ms_each?: number[];
}

/** Records performance.now() when the page marks itself ready: works on any version of the demo page. */
const WATCH_READY = () => {
  const marks: Record<string, number> = {};
  (globalThis as unknown as { readyMarks: typeof marks }).readyMarks = marks;
  new MutationObserver(() => {
    const b = document.body;
    if (!b) return;
    if (b.dataset.ready && !marks.face) marks.face = performance.now();
    if (b.dataset.engine && !marks.engine) marks.engine = performance.now();
  }).observe(document, { subtree: true, attributes: true, attributeFilter: ['data-ready', 'data-engine'] });
};

async function oneLoad(browser: Browser, url: string): Promise<{ files: FetchedFile[]; face: number | undefined; engine: number }> {
  const context = await browser.newContext();
  const page = await context.newPage();
  await page.addInitScript(WATCH_READY);
  const seen = new Map<string, FetchedFile>();
  const pending: Promise<void>[] = [];
  const record = (req: Request) => pending.push((async () => {
    // (a request the context's close cut short rejects: counted as not fetched, not an unhandled rejection)
    const res = await req.response();
    const sizes = await req.sizes();
    // A worker's script reports no body size to Playwright: its Content-Length (set by the preview server) stands in.
    const body = sizes.responseBodySize || (sizes.responseHeadersSize > 0 ? Number((await res?.headerValue('content-length')) ?? 0) : 0);
    const transferred = body + sizes.responseHeadersSize;
    const path = new URL(req.url()).pathname;
    const f = seen.get(path) ?? { path, bytes: 0, fetches: 0, encoding: '' };
    if (transferred > 0) { // 0: served from the browser's cache
      f.bytes += transferred;
      f.fetches++;
    }
    f.encoding = (await res?.headerValue('content-encoding')) ?? 'identity';
    seen.set(path, f);
  })().catch(() => undefined)); // see above
  page.on('requestfinished', record);
  await page.goto(url);
  await page.waitForSelector('body[data-engine]', { timeout: 60_000 });
  const state = await page.evaluate(() => document.body.dataset.engine);
  if (state !== 'ready') throw new Error(`${url} did not get ready (data-engine=${state}${await page.evaluate(() => document.body.dataset.error ? `: ${document.body.dataset.error}` : '')})`);
  await page.waitForTimeout(500); // let late requests (the rest face's work, sample index) finish
  // Every request seen, those that finish while the first are awaited too; then no more are taken.
  for (let counted = 0; counted < pending.length; ) {
    const now = pending.length;
    await Promise.all(pending.slice(counted, now));
    counted = now;
  }
  page.off('requestfinished', record);
  const marks = await page.evaluate(() => (globalThis as unknown as { readyMarks: { face?: number; engine: number } }).readyMarks);
  await context.close();
  return { files: [...seen.values()].filter((f) => f.fetches > 0).sort((a, b) => b.bytes - a.bytes), face: marks.face, engine: marks.engine };
}

const median = (xs: number[]) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];

/** `loads` first loads of `url` (the demo page) in fresh contexts. */
export async function measureFirstLoad(browser: Browser, url: string, loads = 3): Promise<FirstLoad> {
  const runs = [];
  for (let i = 0; i < loads; i++) runs.push(await oneLoad(browser, url));
  const files = runs[0].files;
  const total = files.reduce((s, f) => s + f.bytes, 0);
  return {
    total_bytes: total,
    total_mib: total / 2 ** 20,
    files,
    fetched_twice: files.filter((f) => f.fetches > 1).map((f) => f.path),
    face_shown_ms: median(runs.map((r) => r.face ?? NaN)),
    ready_ms: median(runs.map((r) => r.engine)),
    ready_ms_each: runs.map((r) => r.engine),
  };
}

/**
 * Time to ready of dev/ort-start.html (`url`), `loads` fresh loads: onnxruntime-web started as the engine starts it,
 * with nothing else on the page. Added to `r` (the demo's first load, measured in the same browser just before).
 */
export async function measureOnnxAlone(browser: Browser, url: string, r: FirstLoad, loads = 5): Promise<void> {
  const each: number[] = [];
  for (let i = 0; i < loads; i++) each.push((await oneLoad(browser, url)).engine);
  r.onnxruntime_alone_ms = median(each);
  r.onnxruntime_alone_ms_each = each;
}

export function printFirstLoad(r: FirstLoad): void {
  console.log(`\nfirst load: ${(r.total_bytes / 2 ** 20).toFixed(2)} MiB transferred in ${r.files.length} files; face shown ${r.face_shown_ms.toFixed(0)} ms, ` +
    `ready ${r.ready_ms.toFixed(0)} ms (median of ${r.ready_ms_each.length}: ${r.ready_ms_each.map((t) => t.toFixed(0)).join(', ')} ms)`);
  if (r.onnxruntime_alone_ms !== undefined) {
    console.log(`  onnxruntime alone (dev/ort-start.html: its worker, runtime and the encoders' sessions, nothing else on the page): ready ` +
      `${r.onnxruntime_alone_ms.toFixed(0)} ms (median of ${r.onnxruntime_alone_ms_each!.length}: ${r.onnxruntime_alone_ms_each!.map((t) => t.toFixed(0)).join(', ')} ms)`);
  }
  for (const f of r.files) console.log(`  ${(f.bytes / 1024).toFixed(1).padStart(9)} KiB  ${f.fetches > 1 ? `x${f.fetches}` : '  '}  ${f.encoding.padEnd(8)}  ${f.path}`);
  if (r.fetched_twice.length) console.log(`  fetched more than once: ${r.fetched_twice.join(', ')}`);
}
