import { test, expect } from './fixtures';

/**
 * <talking-face>'s volume and muted (examples/embed.html): what reaches the speakers, measured after the element's
 * own audio graph (every connection to a context's destination goes through an analyser first), while the face
 * moves in sync either way.
 */
type Page = import('@playwright/test').Page;

/**
 * Every AudioContext's destination (not an OfflineAudioContext's: decoding renders through those) is a recorder in front
 * of it; window.level() is the root of the energy of all the sound that reached it since the last call (0 for silence;
 * half for a clip played whole at half the volume).
 */
const PROBE = () => {
  const g = globalThis as unknown as { level(): number; energy: number; samples: number };
  [g.energy, g.samples] = [0, 0];
  const real = Object.getOwnPropertyDescriptor(BaseAudioContext.prototype, 'destination')!.get!;
  const probes = new WeakMap<BaseAudioContext, AudioNode>();
  Object.defineProperty(AudioContext.prototype, 'destination', {
    get(this: AudioContext) {
      let p = probes.get(this);
      if (!p) {
        const recorder = this.createScriptProcessor(4096, 1, 1);
        recorder.onaudioprocess = (e) => {
          for (const v of e.inputBuffer.getChannelData(0)) g.energy += v * v;
          g.samples += e.inputBuffer.length;
        };
        recorder.connect(real.call(this) as AudioNode);
        probes.set(this, (p = recorder));
      }
      return p;
    },
  });
  g.level = () => { const root = Math.sqrt(g.energy); [g.energy, g.samples] = [0, 0]; return root; };
};

const level = (page: Page) => page.evaluate(() => (globalThis as unknown as { level(): number }).level());
type Face = HTMLElement & { speak(src: string): Promise<void>; volume: number; muted: boolean };

/** Speak the sample on the left face and return the root of the energy heard while it played. */
async function heard(page: Page): Promise<number> {
  await page.waitForTimeout(300); // the recorder's last block (85 ms) past the last take's end
  await level(page);
  await page.evaluate(() => (document.getElementById('left') as Face).speak('/examples/sample.wav'));
  return level(page);
}

test('muted plays silently with the face in sync, volume scales the sound, both at once while playing', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(PROBE);
  await page.goto('/examples/embed.html');
  await page.evaluate(() => (document.getElementById('left') as unknown as { ready: Promise<unknown> }).ready);
  const full = await heard(page);
  await page.evaluate(() => ((document.getElementById('left') as Face).volume = 0.5));
  const half = await heard(page);
  await page.evaluate(() => ((document.getElementById('left') as Face).muted = true));
  expect(await page.evaluate(() => document.getElementById('left')!.hasAttribute('muted')), 'muted reflects its attribute').toBe(true);
  await page.evaluate(() => {
    const g = globalThis as unknown as { framesShown: number };
    g.framesShown = 0;
    document.getElementById('left')!.addEventListener('frame', () => g.framesShown++);
  });
  const muted = await heard(page);
  console.log(`root energy heard: volume 1 ${full.toFixed(2)}, volume 0.5 ${half.toFixed(2)} (ratio ${(half / full).toFixed(3)}), muted ${muted.toExponential(1)}`);
  expect(full, 'the sample is heard').toBeGreaterThan(1);
  expect(half / full, 'half the volume, half the amplitude').toBeGreaterThan(0.48);
  expect(half / full).toBeLessThan(0.52);
  expect(muted, 'muted: nothing reaches the speakers').toBeLessThan(1e-6);
  const shown = await page.evaluate(() => (globalThis as unknown as { framesShown: number }).framesShown);
  expect(shown, 'the face moved through the muted take (frame events, 25 a second of its 3.2 s)').toBeGreaterThan(20);

  // Unmuted by the attribute while it plays: heard from then on, at the volume set.
  await level(page);
  const playing = page.evaluate(() => (document.getElementById('left') as Face).speak('/examples/sample.wav'));
  await expect.poll(() => page.evaluate(() => (document.getElementById('left') as Face).shadowRoot!.querySelector('p.status')!.textContent), { timeout: 30_000 }).toMatch(/^Playing/);
  await page.waitForTimeout(300);
  expect(await level(page), 'still muted').toBeLessThan(1e-6);
  await page.evaluate(() => document.getElementById('left')!.removeAttribute('muted'));
  await playing;
  expect(await level(page), 'heard once unmuted').toBeGreaterThan(0.2 * half);
  expect(await page.evaluate(() => (document.getElementById('left') as Face).muted)).toBe(false);

  // A volume outside 0-1 is refused and changes nothing.
  const refused = await page.evaluate(() => {
    const el = document.getElementById('left') as Face;
    try { el.volume = 2; return 'set'; } catch (e) { return `${(e as Error).name}: ${(e as Error).message} (volume ${el.volume})`; }
  });
  expect(refused).toBe('RangeError: volume must be a number from 0 to 1, not 2 (volume 0.5)');
});
