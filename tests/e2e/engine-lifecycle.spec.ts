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

test('disposed while it animates: the animation rejects with EngineDisposedError whichever stage it was in; listen after it too', async ({ page }) => {
  await openDemo(page);
  const outcome = await page.evaluate(async () => {
    const engine = (globalThis as unknown as { talkingFace: { engine: any } }).talkingFace.engine;
    let seed = 7;
    const voice = Float32Array.from({ length: 16000 * 10 }, (_, i) => 0.3 * Math.sin(i / 8) * ((seed = (seed * 16807) % 2147483647) / 2147483647));
    const names: string[] = [];
    for (const delayMs of [0, 30, 120]) { // (the first chunk's stages: a dispose lands in the encoders or the decoder)
      const e = await (engine.constructor as { load(o: object): Promise<any> }).load({ backend: 'cpu', cpuWorkers: 0 });
      const animating = e.animate(voice, { chunkFrames: 300 }).then(() => 'resolved', (err: Error) => err.name);
      setTimeout(() => void e.dispose(), delayMs);
      names.push(await animating);
      names.push(await e.listen(new MediaStream(), () => undefined).then(() => 'listening', (err: Error) => err.name));
    }
    const refused = await engine.attentionAt(voice.subarray(0, 16000), 3, 3).then(() => 'resolved', (err: Error) => `${err.name}: ${err.message}`);
    return { names, refused };
  });
  expect(outcome.names).toEqual(Array.from({ length: 3 }, () => ['EngineDisposedError', 'EngineDisposedError']).flat());
  expect(outcome.refused).toMatch(/^RangeError: layer must be a whole number from 0 to 2/);
});

test('a head-motion seed changed while a clip is animated is for later clips: the clip under way keeps its own', async ({ page }) => {
  await openDemo(page);
  const same = await page.evaluate(async () => {
    const engine = (globalThis as unknown as { talkingFace: { engine: any } }).talkingFace.engine;
    const voice = Float32Array.from({ length: 16000 * 4 }, (_, i) => 0.3 * Math.sin(i / 8) * Math.sin(i / 3000));
    engine.headMotionSeed = 0;
    const whole = await engine.animate(voice, { chunkFrames: 30 });
    const changed = await engine.animate(voice, { chunkFrames: 30, onProgress: () => { engine.headMotionSeed = null; } });
    engine.headMotionSeed = 0;
    return whole.pose.every((x: number, i: number) => x === changed.pose[i]);
  });
  expect(same).toBe(true);
});
