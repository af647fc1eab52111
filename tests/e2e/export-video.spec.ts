import { readFileSync } from 'node:fs';
import { test, expect } from './fixtures';
import { SPEECH, speechSamples } from './helpers/audio';

/**
 * "Export video": the take plays from the start and is saved as a video of the face with its sound (the browser's
 * MediaRecorder). The file is read back in the page: its sound is the take's length and not silent, its picture
 * the canvas's size; Escape cancels one being recorded, and nothing is saved.
 */
test('Export video saves the take playing, picture and sound; Escape cancels one being recorded', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  const { samples, rate } = speechSamples();
  const seconds = samples.length / rate;
  const download = page.waitForEvent('download', { timeout: 60_000 });
  await page.locator('#export-video').click();
  await expect(page.locator('#status')).toContainText(/Recording the video: \d+\.\d of \d+\.\d s/);
  // The face goes out of sight meanwhile (as scrolled away): it is still recorded (a view out of sight draws nothing).
  await page.evaluate(() => ((document.querySelector('#face-canvas') as HTMLElement).style.transform = 'translateX(-10000px)'));
  const saved = await download;
  expect(saved.suggestedFilename()).toBe('speech-kal.webm');
  await expect(page.locator('#status')).toContainText('Saved speech-kal.webm: the take as a video with its sound.');
  const bytes = readFileSync((await saved.path())!);
  expect([...bytes.subarray(0, 4)]).toEqual([0x1a, 0x45, 0xdf, 0xa3]); // WebM (EBML)
  const read = await page.evaluate(async (b64) => {
    const data = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const sound = await new OfflineAudioContext(1, 1, 48000).decodeAudioData(data.buffer.slice(0));
    const peak = sound.getChannelData(0).reduce((m, x) => Math.max(m, Math.abs(x)), 0);
    const video = document.createElement('video');
    video.muted = true;
    video.src = URL.createObjectURL(new Blob([data], { type: 'video/webm' }));
    await new Promise((resolve, reject) => { video.onloadedmetadata = resolve; video.onerror = () => reject(new Error('the video does not load')); });
    // Frames at 1.2 s and 2.4 s in (the face out of sight): the face, not a blank picture (the spread of the
    // pixels' brightness), and moving, not frozen (their mean difference).
    const still = Object.assign(document.createElement('canvas'), { width: video.videoWidth, height: video.videoHeight });
    const ctx = still.getContext('2d', { willReadFrequently: true })!;
    const frameAt = async (t: number) => {
      await video.play();
      await new Promise<void>((resolve) => { const check = () => (video.currentTime > t ? resolve() : requestAnimationFrame(check)); check(); });
      video.pause();
      ctx.drawImage(video, 0, 0);
      return ctx.getImageData(0, 0, still.width, still.height).data;
    };
    const early = await frameAt(1.2), late = await frameAt(2.4);
    let sum = 0, sq = 0, moved = 0;
    for (let i = 0; i < late.length; i += 4) {
      const l = (late[i] + late[i + 1] + late[i + 2]) / 3;
      sum += l; sq += l * l;
      moved += Math.abs(l - (early[i] + early[i + 1] + early[i + 2]) / 3);
    }
    const n = late.length / 4;
    const canvas = document.querySelector('#face-canvas') as HTMLCanvasElement;
    return { seconds: sound.duration, peak, width: video.videoWidth, height: video.videoHeight, canvas: [canvas.width, canvas.height],
      spread: Math.sqrt(sq / n - (sum / n) ** 2), moved: moved / n };
  }, bytes.toString('base64'));
  // The take and half a second after it (the face going back to rest), give or take the recorder's start.
  expect(read.seconds).toBeGreaterThan(seconds - 0.3);
  expect(read.seconds).toBeLessThan(seconds + 1.5);
  expect(read.peak).toBeGreaterThan(0.05);
  expect([read.width, read.height]).toEqual(read.canvas);
  expect(read.spread).toBeGreaterThan(10); // a face on the background (a blank frame: 0)
  console.log(`video read back: ${JSON.stringify(read)}`);
  expect(read.moved).toBeGreaterThan(0.2); // frozen: 0
  await page.evaluate(() => ((document.querySelector('#face-canvas') as HTMLElement).style.transform = ''));

  const later: string[] = [];
  page.on('download', (d) => later.push(d.suggestedFilename()));
  await expect(page.locator('#play-button')).toHaveText('Play'); // (the take played out)
  await page.locator('#export-video').click();
  await expect(page.locator('#status')).toContainText('Recording the video');
  await expect(page.locator('#play-button'), 'the take plays for the video: Pause would stop it').toHaveText('Pause');
  await page.keyboard.press('Escape');
  await expect(page.locator('#status')).toContainText('Video cancelled.');
  await expect(page.locator('#play-button')).toHaveText('Play');
  await page.waitForTimeout(500);
  expect(later).toEqual([]);
});
