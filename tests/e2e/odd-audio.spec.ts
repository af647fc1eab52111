import { test, expect } from './fixtures';
import { SAMPLE_RATE, SPEECH, speechSamples, wav, lipGaps } from './helpers/audio';

/**
 * Audio that is not speech, or too little of it (issue 18): noise and a tone get a note and a face at rest; a clip
 * under half a second gets a note and no speed figure; a dropped file plays as soon as it is animated.
 */
test.describe('odd audio', () => {
  test.beforeEach(async ({ page }) => {
    await page.goto('/');
    await expect(page.locator('body')).toHaveAttribute('data-rest', 'shown', { timeout: 60_000 });
  });

  // mulberry32: uniform in [-1, 1), every sample independent (white).
  let seed = 7;
  const random = () => {
    seed = (seed + 0x6d2b79f5) | 0;
    let t = Math.imul(seed ^ (seed >>> 15), 1 | seed);
    t = (t + Math.imul(t ^ (t >>> 7), 61 | t)) ^ t;
    return (((t ^ (t >>> 14)) >>> 0) / 2 ** 32) * 2 - 1;
  };
  const cases: [string, () => Float32Array][] = [
    ['five seconds of white noise', () => Float32Array.from({ length: 5 * SAMPLE_RATE }, () => 0.3 * random())],
    ['three seconds of a 440 Hz tone', () => Float32Array.from({ length: 3 * SAMPLE_RATE }, (_, i) => 0.5 * Math.sin((2 * Math.PI * 440 * i) / SAMPLE_RATE))],
  ];
  for (const [name, make] of cases) {
    test(`${name}: "no speech", and the mouth stays at rest`, async ({ page }) => {
      await page.locator('#file-input').setInputFiles({ name: 'sound.wav', mimeType: 'audio/wav', buffer: wav([make()], SAMPLE_RATE) });
      await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
      await expect(page.locator('#status')).toContainText('no speech was found');
      await expect(page.locator('#details')).toContainText('no speech was found');
      const gaps = await lipGaps(page);
      console.log(`${name}: inner-lip gap at most ${Math.max(...gaps).toFixed(2)} mm over ${gaps.length} frames`);
      expect(Math.max(...gaps), 'largest inner-lip gap (mm)').toBeLessThan(1);
      expect(Math.max(...gaps) - Math.min(...gaps), 'the mouth does not move (mm)').toBeLessThan(0.01);
      // New head motion animates the clip again: the face stays at rest.
      await page.evaluate(() => Object.assign(globalThis, { previousTake: (globalThis as unknown as { talkingFace: { take: unknown } }).talkingFace.take }));
      await page.locator('#head-reroll').click();
      await page.waitForFunction(() => {
        const g = globalThis as unknown as { talkingFace: { take: unknown }; previousTake: unknown };
        return g.talkingFace.take !== g.previousTake && document.body.dataset.take === 'ready';
      }, null, { timeout: 60_000 });
      await expect(page.locator('#details'), 'the take\'s notes are kept with its new head').toContainText('no speech was found');
      const again = await lipGaps(page);
      expect(Math.max(...again) - Math.min(...again), 'after New head motion, the mouth does not move (mm)').toBeLessThan(0.01);
    });
  }

  test('speech on all six channels of a 5.1 file moves the mouth as the mono file does, with no clipping note', async ({ page }) => {
    const { samples, rate } = speechSamples();
    await page.locator('#file-input').setInputFiles({ name: 'mono.wav', mimeType: 'audio/wav', buffer: wav([samples], rate) });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    const mono = await lipGaps(page);
    await page.locator('#file-input').setInputFiles({ name: 'surround.wav', mimeType: 'audio/wav', buffer: wav(new Array(6).fill(samples), rate) });
    await expect(page.locator('#details')).toContainText('surround.wav', { timeout: 60_000 });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#details')).toContainText('6 channels mixed to mono');
    await expect(page.locator('#details')).not.toContainText('clipped'); // Web Audio's own 5.1 down-mix made it 3.4 times as loud
    const surround = await lipGaps(page);
    expect(Math.max(...surround.map((g, i) => Math.abs(g - mono[i]))), 'inner-lip gap, 5.1 against mono (mm)').toBeLessThan(0.05);
  });

  test('a minute of silence is the face at rest at once: the model is not run on it', async ({ page }) => {
    await page.locator('#file-input').setInputFiles({ name: 'silence.wav', mimeType: 'audio/wav', buffer: wav([new Float32Array(60 * SAMPLE_RATE)], SAMPLE_RATE) });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#status')).toContainText('the audio is silent');
    await expect(page.locator('#details')).toContainText('not run on silent audio');
    const times = await page.evaluate(() => (globalThis as unknown as { talkingFace: { engine: { times: Record<string, number> } } }).talkingFace.engine.times);
    expect(times.content + times.decoder, 'the content encoder and the decoder did not run').toBe(0);
    const gaps = await lipGaps(page);
    expect(gaps.length).toBe(60 * 30);
    expect(Math.max(...gaps) - Math.min(...gaps), 'the mouth does not move (mm)').toBeLessThan(0.01);
    const pose = await page.evaluate(() => Array.from((globalThis as unknown as { talkingFace: { take: { animation: { pose: Float32Array } } } }).talkingFace.take.animation.pose));
    expect(pose.every((x, i) => x === pose[i % 6]), 'the head still').toBe(true);
  });

  test('quiet speech (peak -45 dBFS) is raised for the model and said so, and moves the mouth as speech', async ({ page }) => {
    const { samples, rate } = speechSamples();
    const peak = Math.max(...samples.map(Math.abs));
    const quiet = samples.map((x) => (x / peak) * 10 ** (-45 / 20));
    await page.locator('#file-input').setInputFiles({ name: 'quiet.wav', mimeType: 'audio/wav', buffer: wav([quiet], rate) });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#details')).toContainText(/very quiet \(peak -45 dBFS\): raised by 39 dB/);
    await expect(page.locator('#details')).not.toContainText('no speech');
    const gaps = await lipGaps(page);
    expect(Math.max(...gaps) - Math.min(...gaps), 'speech moves the mouth (mm)').toBeGreaterThan(2);
  });

  test('a 0.2 s clip gets a note and no real-time factor', async ({ page }) => {
    const { samples, rate } = speechSamples();
    await page.locator('#file-input').setInputFiles({ name: 'tiny.wav', mimeType: 'audio/wav', buffer: wav([samples.subarray(rate, rate + rate / 5)], rate) });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#status')).toContainText('very short clip');
    await expect(page.locator('#details')).toContainText('no speed figure');
    await expect(page.locator('#details')).not.toContainText('real time');
  });

  test('a dropped file is animated and plays at once; speech still moves the mouth', async ({ page }) => {
    const bytes = (await import('node:fs')).readFileSync(SPEECH).toString('base64');
    await page.evaluate((b64) => {
      const file = new File([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], 'dropped.wav', { type: 'audio/wav' });
      const data = new DataTransfer();
      data.items.add(file);
      document.getElementById('stage')!.dispatchEvent(new DragEvent('drop', { dataTransfer: data, bubbles: true, cancelable: true }));
    }, bytes);
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#play-button')).toHaveText('Pause');
    await expect(page.locator('#status')).not.toContainText('no speech');
    const gaps = await lipGaps(page);
    expect(Math.max(...gaps) - Math.min(...gaps), 'speech moves the mouth (mm)').toBeGreaterThan(2);
  });

  test('files dropped on the controls, not the face, are taken too: of an image and a recording, the recording', async ({ page }) => {
    const bytes = (await import('node:fs')).readFileSync(SPEECH).toString('base64');
    const taken = await page.evaluate((b64) => {
      const data = new DataTransfer();
      data.items.add(new File([new Uint8Array([0x89, 0x50, 0x4e, 0x47])], 'cover.png', { type: 'image/png' }));
      data.items.add(new File([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], 'dropped-on-open.wav', { type: 'audio/wav' }));
      const target = document.querySelector('.file-button')!;
      target.dispatchEvent(new DragEvent('dragenter', { dataTransfer: data, bubbles: true, cancelable: true }));
      const hint = !document.getElementById('drop-hint')!.hidden;
      const over = !target.dispatchEvent(new DragEvent('dragover', { dataTransfer: data, bubbles: true, cancelable: true }));
      const drop = !target.dispatchEvent(new DragEvent('drop', { dataTransfer: data, bubbles: true, cancelable: true }));
      return { hint, over, drop, hintAfter: !document.getElementById('drop-hint')!.hidden };
    }, bytes);
    expect(taken, 'the drop hint shows while dragging; dragover and drop are taken (the browser does not open the file)').toEqual({ hint: true, over: true, drop: true, hintAfter: false });
    await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
    await expect(page.locator('#details')).toContainText('dropped-on-open.wav');
  });
});
