import { defineConfig } from '@playwright/test';

/**
 * Headless Debian Chromium (Playwright's own browser download does not work here).
 * Flags: see ../shared/platform.md. WebGPU runs on SwiftShader (software),
 * and the host-resolver rule makes any request to another host fail loudly.
 */
const PORT = Number(process.env.E2E_PORT ?? 4179);
export const CHROMIUM_ARGS = [
  '--no-sandbox',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--disable-quic',
  '--enable-unsafe-webgpu',
  '--enable-unsafe-swiftshader',
  '--autoplay-policy=no-user-gesture-required',
  '--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE localhost , EXCLUDE 127.0.0.1',
];

/** Chromium launch options with a fake microphone that plays `wav` (and grants it without a prompt). */
export function fakeMicrophone(wav: string): { executablePath: string; args: string[] } {
  return {
    executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium',
    args: [...CHROMIUM_ARGS, '--use-fake-ui-for-media-stream', '--use-fake-device-for-media-stream', `--use-file-for-fake-audio-capture=${wav}`],
  };
}

/**
 * A page init script (page.addInitScript) under which WebGL names a GPU as its renderer: the views then draw with
 * multisampling, as a visitor with a GPU sees them, where here (SwiftShader) they draw without (src/render/software-gl.ts).
 */
export function reportGpuRenderer(): void {
  const getParameter = WebGL2RenderingContext.prototype.getParameter;
  WebGL2RenderingContext.prototype.getParameter = function (this: WebGL2RenderingContext, p: GLenum) {
    return p === 0x9246 ? 'ANGLE (NVIDIA, NVIDIA GeForce RTX 3060 Direct3D11 vs_5_0 ps_5_0, D3D11)' : getParameter.call(this, p); // UNMASKED_RENDERER_WEBGL
  };
}

export default defineConfig({
  testDir: 'tests/e2e',
  timeout: 60_000,
  expect: { timeout: 20_000 },
  fullyParallel: false,
  forbidOnly: true, // a test.only left in would run alone and report success
  workers: 1,
  retries: 0,
  reporter: process.env.CI ? [['list']] : [['list']],
  outputDir: 'test-results/e2e',
  use: {
    baseURL: `http://127.0.0.1:${PORT}`,
    browserName: 'chromium',
    viewport: { width: 1100, height: 760 },
    launchOptions: {
      executablePath: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium',
      args: CHROMIUM_ARGS,
    },
  },
  webServer: {
    command: `npm run --silent build:test && npx vite preview --host 127.0.0.1 --port ${PORT} --strictPort`,
    url: `http://127.0.0.1:${PORT}/`,
    timeout: 300_000, // (it builds first: on a fresh clone, with nothing yet compressed, more than two minutes on a slow runner)
    reuseExistingServer: false,
  },
});
