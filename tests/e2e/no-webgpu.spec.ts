import { test, expect } from './fixtures';
import { CHROMIUM_ARGS } from '../../playwright.config';
import { SPEECH } from './helpers/audio';

/** A browser without WebGPU: the page says so, and animates on the CPU decoder. */
test.use({
  launchOptions: {
    executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium',
    args: CHROMIUM_ARGS.filter((a) => !a.includes('webgpu') && !a.includes('swiftshader')).concat(['--disable-features=WebGPU']),
  },
});

test('without WebGPU the CPU decoder animates, and the page says why', async ({ page }) => {
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(page.locator('#details')).toContainText('WebGPU: none');
  await expect(page.locator('#backend-select option[value="webgpu"]')).toBeDisabled();
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#details')).toContainText('Decoder cpu');
});
