import { test, expect } from './fixtures';

/**
 * <talking-face>.recordVideo(): the last take played from its start and recorded with its sound, read back in the
 * page (the sound the take's length and not silent, the picture the element's canvas); before any take it rejects
 * with a TalkingFaceError, and a cancel rejects with the signal's reason and sends no error event.
 */
type FaceEl = HTMLElement & {
  speak(a: string): Promise<void>;
  recordVideo(o?: { signal?: AbortSignal; onProgress?: (s: number) => void }): Promise<Blob>;
  currentAnimation: { frames: number; fps: number } | null;
};

test('the element records its last take as a video with its sound; before a take, and cancelled, it says so', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/examples/embed.html');
  const face = page.locator('#left');
  await expect.poll(() => face.evaluate((el) => (el as FaceEl & { backend: string | null }).backend), { timeout: 60_000 }).toBe('cpu');
  const before = await face.evaluate((el) => (el as FaceEl).recordVideo().then(() => 'made', (e: Error & { stage?: string }) => `${e.name} ${e.stage}: ${e.message}`));
  expect(before).toBe('TalkingFaceError render: there is no take to record: speak() one first');

  await face.evaluate((el) => (el as FaceEl).speak('/examples/sample.wav'));
  const read = await face.evaluate(async (el) => {
    const f = el as FaceEl;
    const errors: string[] = [];
    f.addEventListener('error', (e) => errors.push((e as unknown as CustomEvent<{ message: string }>).detail.message));
    let progress = 0;
    const blob = await f.recordVideo({ onProgress: (s) => (progress = s) });
    const data = new Uint8Array(await blob.arrayBuffer());
    const sound = await new OfflineAudioContext(1, 1, 48000).decodeAudioData(data.buffer.slice(0));
    const peak = sound.getChannelData(0).reduce((m, x) => Math.max(m, Math.abs(x)), 0);
    const video = Object.assign(document.createElement('video'), { muted: true, src: URL.createObjectURL(blob) });
    await new Promise((resolve, reject) => { video.onloadedmetadata = resolve; video.onerror = () => reject(new Error('the video does not load')); });
    const canvas = el.shadowRoot!.querySelector('canvas')!;
    // Cancelled a moment in: rejected with the signal's reason, no error event.
    const stop = new AbortController();
    let ended = 0; // the cancelled recording's take stops: the face rests, and `ended` says so
    f.addEventListener('ended', () => ended++);
    const cancelled = f.recordVideo({ signal: stop.signal }).then(() => 'made', (e: Error) => e.name);
    setTimeout(() => stop.abort(), 500);
    const take = f.currentAnimation!;
    const cancelledEarly = await cancelled;
    const endedOnCancel = ended;
    // Cancelled in its half-second tail, once the take has played to its end (and said so): `ended` is not sent again.
    const late = new AbortController();
    f.addEventListener('ended', () => late.abort(), { once: true });
    ended = 0;
    const lateCancel = await f.recordVideo({ signal: late.signal }).then(() => 'made', (e: Error) => e.name);
    return { type: blob.type, magic: [...data.subarray(0, 4)], seconds: sound.duration, take: take.frames / take.fps, peak, progress,
      size: [video.videoWidth, video.videoHeight], canvas: [canvas.width, canvas.height], cancelled: cancelledEarly, endedOnCancel, lateCancel, endedOnLateCancel: ended, errors };
  });
  console.log(`element video: ${JSON.stringify(read)}`);
  expect(read.type).toMatch(/^video\/(webm|mp4)$/);
  expect(read.magic).toEqual([0x1a, 0x45, 0xdf, 0xa3]); // WebM (EBML) in Chromium
  expect(read.seconds).toBeGreaterThan(read.take - 0.3);
  expect(read.seconds).toBeLessThan(read.take + 1.5);
  expect(read.peak).toBeGreaterThan(0.05);
  expect(read.progress).toBeGreaterThan(0.5 * read.take);
  expect(read.size).toEqual(read.canvas);
  expect(read.cancelled).toBe('AbortError');
  expect(read.endedOnCancel).toBe(1);
  expect(read.lateCancel).toBe('AbortError');
  expect(read.endedOnLateCancel).toBe(1);
  expect(read.errors).toEqual([]);
});

test('once the avatar changes, the element has no take: currentAnimation is null and recordVideo() says so', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/examples/embed.html');
  const face = page.locator('#left');
  await expect.poll(() => face.evaluate((el) => (el as FaceEl & { backend: string | null }).backend), { timeout: 60_000 }).toBe('cpu');
  await face.evaluate((el) => (el as FaceEl).speak('/examples/sample.wav'));
  expect(await face.evaluate((el) => (el as FaceEl).currentAnimation?.frames)).toBeGreaterThan(0);
  const after = await face.evaluate(async (el) => {
    const f = el as FaceEl;
    const ready = new Promise((r) => f.addEventListener('ready', r, { once: true }));
    f.setAttribute('avatar', '/examples/avatars/arkit-face.glb');
    await ready;
    return { take: f.currentAnimation, record: await f.recordVideo().then(() => 'made', (e: Error) => e.message) };
  });
  expect(after).toEqual({ take: null, record: 'there is no take to record: speak() one first' });
});
