import { test, expect } from './fixtures';

/**
 * engine.dispose() (docs/engine.md): every later call that runs the model, or gives what it computed (restFace and
 * restArkit, also where they were computed before), rejects with EngineDisposedError; calling it again does nothing.
 * On the demo's engine, once its rest face is known.
 */
test('a disposed engine refuses every later call with EngineDisposedError, a rest computed before included', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
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
