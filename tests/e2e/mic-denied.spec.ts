import { test, expect } from './fixtures';
import { CHROMIUM_ARGS } from '../../playwright.config';

/** A microphone exists but the visitor refuses it (no permission granted): a clear message, nothing stuck. */
test.use({
  launchOptions: {
    executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium',
    args: [...CHROMIUM_ARGS, '--use-fake-device-for-media-stream', '--deny-permission-prompts'],
  },
});

test('a denied microphone: the demo and the component both say what to do', async ({ page }) => {
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'error', { timeout: 20_000 });
  await expect(page.locator('#status')).toContainText('microphone access was denied');
  await expect(page.locator('#record-button')).toHaveText('Record');

  await page.goto('/examples/embed.html');
  const message = await page.evaluate(async () => {
    const el = document.getElementById('right') as HTMLElement & { startMicrophone(): Promise<void> };
    const event = new Promise<string>((resolve) => el.addEventListener('error', (e) => resolve((e as unknown as CustomEvent).detail.message)));
    await el.startMicrophone().catch(() => undefined);
    return event;
  });
  expect(message).toContain('microphone access was denied');
});
