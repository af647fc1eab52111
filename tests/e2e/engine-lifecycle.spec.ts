import { test, expect } from './fixtures';

/**
 * The engine's lifecycle on the demo's engine (docs/engine.md). An animateSpeech() aborted at any point gives no
 * result: also while a clip without speech is held at rest after its last chunk, or while a silent clip's rest frames
 * are made (the demo's Cancel, or another file dropped: the cancelled clip must not be shown). engine.dispose():
 * every later call that runs the model, or gives what it computed (restFace and restArkit, also where they were
 * computed before), rejects with EngineDisposedError; calling it again does nothing.
 */
test.setTimeout(120_000);

/** The demo with its engine loaded (window.talkingFace.engine). */
async function openDemo(page: import('@playwright/test').Page): Promise<void> {
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
}

test('animateSpeech aborted after its last chunk, or while a silent clip is made, rejects with the abort', async ({ page }) => {
  await openDemo(page);
  const outcome = await page.evaluate(async () => {
    const engine = (globalThis as unknown as { talkingFace: { engine: any } }).talkingFace.engine;
    const said = (p: Promise<unknown>) => p.then(() => 'resolved', (e: Error) => e.name);
    let seed = 1;
    const noise = Float32Array.from({ length: 16000 * 2 }, () => ((seed = (seed * 16807) % 2147483647) / 2147483647 - 0.5) * 0.6);
    const afterLast = new AbortController(); // aborted once the last chunk is in: while the noise is held at rest
    const held = await said(engine.animateSpeech(noise, { signal: afterLast.signal, onProgress: (done: number, all: number) => done === all && afterLast.abort() }));
    const whileMade = new AbortController();
    const silent = said(engine.animateSpeech(new Float32Array(16000 * 600), { signal: whileMade.signal })); // ten minutes of silence
    queueMicrotask(() => whileMade.abort()); // once it has begun: while its rest frames are made
    const control = await said(engine.animateSpeech(noise)); // not aborted: it resolves
    return { held, silent: await silent, control };
  });
  expect(outcome).toEqual({ held: 'AbortError', silent: 'AbortError', control: 'resolved' });
});

test('a disposed engine refuses every later call with EngineDisposedError, a rest computed before included', async ({ page }) => {
  await openDemo(page);
  const outcome = await page.evaluate(async () => {
    const engine = (globalThis as unknown as { talkingFace: { engine: any } }).talkingFace.engine;
    const before = [(await engine.restFace()).length > 0, (await engine.restArkit()).length]; // computed, and kept
    await engine.dispose();
    const said = (p: () => Promise<unknown>) => p().then(() => 'resolved', (e: Error) => `${e.name}: ${e.message}`);
    const samples = new Float32Array(16000).fill(0.01);
    return {
      before,
      animate: await said(() => engine.animate(samples)),
      restFace: await said(() => engine.restFace()),
      restArkit: await said(() => engine.restArkit()),
      stream: await said(async () => engine.createStream(() => undefined).push(samples)),
      again: await said(() => engine.dispose()),
    };
  });
  expect(outcome.before).toEqual([true, 52]);
  const refused = 'EngineDisposedError: this talking-face engine was disposed; load a new one';
  expect(outcome).toEqual({ before: [true, 52], animate: refused, restFace: refused, restArkit: refused, stream: refused, again: 'resolved' });
});
