import { resolve } from 'node:path';
import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { framesOf, SAMPLE_RATE, SPEECH } from './helpers/audio';

/**
 * <talking-face>'s speakStream(): speech written in pieces as a streaming text-to-speech or a voice agent sends them,
 * animated and played as it comes. The take it leaves equals the offline animation of the same audio; 16-bit bytes at
 * 24 kHz cut anywhere give the same mouth; stop() ends it at once; bad input gets a clear message; a MediaStream (here the
 * fake microphone's, as a voice agent's WebRTC track would be) is followed, its tracks left running.
 */
const SAMPLE = resolve(import.meta.dirname, '../../examples/sample.wav');
test.use({ launchOptions: fakeMicrophone(SPEECH) });

interface Outcome { frames: number; streamFrames: number[]; ended: number; errors: string[]; late: number; delayMs: number; status: string;
  maxDiff: number; poseDiff: number; video: number }

test('pieces written as they come are played with the face, and leave the offline animation of the same audio', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/examples/embed.html');
  const outcome: Outcome = await page.evaluate(async (rate) => {
    type Stream = { write(p: unknown): boolean; end(): void; done: Promise<void>; late: { frames: number }; delayMs: number };
    type Animation = { frames: number; unposed: Float32Array; pose: Float32Array };
    const el = document.getElementById('left') as HTMLElement & { speakStream(o: object): Stream; currentAnimation: Animation | null; recordVideo(): Promise<Blob>;
      ready: Promise<{ animate(s: Float32Array, o: object): Promise<Animation> }> };
    const engine = await el.ready;
    const audio = await new OfflineAudioContext(1, 1, rate).decodeAudioData(await (await fetch('/examples/sample.wav')).arrayBuffer());
    const samples = audio.getChannelData(0).slice();
    const streamFrames: number[] = [];
    let ended = 0;
    const errors: string[] = [];
    el.addEventListener('frame', (e) => (e as CustomEvent).detail.mode === 'stream' && streamFrames.push((e as CustomEvent).detail.frame));
    el.addEventListener('ended', () => ended++);
    el.addEventListener('error', (e) => errors.push((e as unknown as CustomEvent).detail.message));
    const speech = el.speakStream({ sampleRate: rate });
    const piece = rate / 10;
    for (let at = 0; at < samples.length; at += piece) { // 0.1 s every 0.1 s: a service speaking in real time
      speech.write(samples.slice(at, at + piece));
      await new Promise((r) => setTimeout(r, 100));
    }
    speech.end();
    await speech.done;
    const take = el.currentAnimation!;
    const offline = await engine.animate(samples, { unposed: true });
    let maxDiff = 0, poseDiff = 0;
    for (let i = 0; i < offline.unposed.length; i++) maxDiff = Math.max(maxDiff, Math.abs(offline.unposed[i] - take.unposed[i]));
    for (let i = 0; i < offline.pose.length; i++) poseDiff = Math.max(poseDiff, Math.abs(offline.pose[i] - take.pose[i]));
    const status = el.shadowRoot!.querySelector('p.status')!.textContent!;
    const endedOnce = ended;
    const video = (await el.recordVideo()).size; // the take, with its sound at 16 kHz, recorded as after speak()
    return { frames: take.frames, streamFrames, ended: endedOnce, errors, late: speech.late.frames, delayMs: speech.delayMs, status, maxDiff, poseDiff, video };
  }, SAMPLE_RATE);
  const frames = framesOf(SAMPLE);
  console.log(`streamed ${frames} frames in 0.1 s pieces: ${outcome.streamFrames.length} frame events, delay ${Math.round(outcome.delayMs)} ms, `
    + `${outcome.late} frames late, first drawn ${outcome.streamFrames[0]}; largest difference from offline: ${outcome.maxDiff.toExponential(1)} (vertices), ${outcome.poseDiff.toExponential(1)} (pose)`);
  expect(outcome.errors).toEqual([]);
  expect(outcome.frames).toBe(frames);
  expect(outcome.maxDiff).toBeLessThan(1e-4);
  expect(outcome.poseDiff).toBeLessThan(1e-4);
  // Shown in order, from (about) the first frame to the last, each once; the sound ahead of the frames for few of them.
  // (Which frames a page draws depends on its speed: a frame event is sent for each frame drawn. The timing itself is
  // tested on a stand-in clock: tests/unit/player/stream-playback.test.ts.)
  // The first drawn from the start: frame 2 at most, or later by no more than the page's largest step between draws.
  const step = Math.max(...outcome.streamFrames.slice(1).map((f, i) => f - outcome.streamFrames[i]));
  expect(outcome.streamFrames[0]).toBeLessThanOrEqual(Math.max(2, step));
  expect(outcome.streamFrames.at(-1)).toBe(frames - 1);
  expect(outcome.streamFrames.every((f, i) => i === 0 || f > outcome.streamFrames[i - 1])).toBe(true);
  expect(outcome.streamFrames.length).toBeGreaterThan(10);
  expect(outcome.late).toBeLessThanOrEqual(frames / 4);
  expect(outcome.ended).toBe(1);
  expect(outcome.status).toMatch(/^Played streamed speech \(\d+\.\d s/);
  expect(outcome.video).toBeGreaterThan(10_000);
});

test('16-bit PCM bytes at 24 kHz, cut anywhere, before the model is ready, give the mouth of the same speech at the model rate', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/examples/embed.html');
  const { correlation, frames, rms } = await page.evaluate(async (modelRate) => {
    type Stream = { write(p: unknown): boolean; end(): void; done: Promise<void> };
    type Animation = { frames: number; unposed: Float32Array };
    type Face = HTMLElement & { speakStream(o: object): Stream; currentAnimation: Animation | null };
    const decode = async (rate: number) => (await new OfflineAudioContext(1, 1, rate).decodeAudioData(await (await fetch('/examples/sample.wav')).arrayBuffer())).getChannelData(0);
    const at24 = await decode(24000);
    const bytes = new Uint8Array(Int16Array.from(at24, (v) => Math.max(-32768, Math.min(32767, Math.round(v * 32768)))).buffer);
    // A new element: everything is written (and ended) while its model still loads.
    const el = document.createElement('talking-face') as Face;
    el.setAttribute('backend', 'cpu');
    document.body.append(el);
    const speech = el.speakStream({ sampleRate: 24000 });
    for (let at = 0; at < bytes.length; at += 4801) speech.write(bytes.slice(at, at + 4801).buffer); // odd: samples split between pieces
    speech.end();
    await speech.done;
    const a = el.currentAnimation!;
    const ref = document.getElementById('left') as Face;
    const s16 = ref.speakStream({ sampleRate: modelRate });
    s16.write((await decode(modelRate)).slice());
    s16.end();
    await s16.done;
    const b = ref.currentAnimation!;
    // How alike the two takes' motion is: the correlation of their displacements from their own mean face.
    const per = a.unposed.length / a.frames;
    const mean = (x: Float32Array) => Float32Array.from({ length: per }, (_, i) => { let s = 0; for (let f = 0; f < a.frames; f++) s += x[f * per + i]; return s / a.frames; });
    const [ma, mb] = [mean(a.unposed), mean(b.unposed)];
    let ab = 0, aa = 0, bb = 0, dd = 0;
    for (let k = 0; k < a.unposed.length; k++) {
      const [x, y] = [a.unposed[k] - ma[k % per], b.unposed[k] - mb[k % per]];
      [ab, aa, bb, dd] = [ab + x * y, aa + x * x, bb + y * y, dd + (x - y) ** 2];
    }
    return { correlation: ab / Math.sqrt(aa * bb), frames: [a.frames, b.frames], rms: Math.sqrt(dd / a.unposed.length) };
  }, SAMPLE_RATE);
  console.log(`24 kHz bytes against 16 kHz floats: motion correlation ${correlation.toFixed(4)}, rms difference ${rms.toExponential(2)}; frames ${frames}`);
  expect(Math.abs(frames[0] - frames[1])).toBeLessThanOrEqual(1);
  expect(correlation).toBeGreaterThan(0.999);
});

test('stop() ends a stream at once; bad pieces and options get clear messages; a new stream then plays', async ({ page, guard }) => {
  test.setTimeout(120_000);
  guard.allowConsoleError(/sampleRate must be/);
  await page.goto('/examples/embed.html');
  const r = await page.evaluate(async () => {
    type Stream = { write(p: unknown): boolean; end(): void; done: Promise<void>; open: boolean };
    const el = document.getElementById('left') as HTMLElement & { speakStream(o: unknown): Stream; stop(): void; ready: Promise<unknown>;
      currentAnimation: { frames: number } | null };
    await el.ready;
    const events: string[] = [];
    for (const type of ['ended', 'error']) el.addEventListener(type, (e) => events.push(type === 'error' ? `error:${(e as CustomEvent).detail.stage}` : type));
    const tone = (seconds: number) => Float32Array.from({ length: 16000 * seconds }, (_, i) => 0.3 * Math.sin(i / 9) * Math.sin(i / 3000));
    const messages: string[] = [];
    const caught = (run: () => unknown) => { try { run(); } catch (e) { messages.push(`${(e as Error).name}: ${(e as Error).message}`); } };
    const s = el.speakStream({ sampleRate: 16000 });
    caught(() => s.write('AAAA'));
    caught(() => s.write(Float32Array.of(0, Infinity)));
    s.write(tone(3));
    await new Promise((r) => setTimeout(r, 800)); // playing
    const status = () => el.shadowRoot!.querySelector('p.status')!.textContent!;
    const during = status();
    caught(() => el.speakStream({})); // bad options: said, and what plays goes on
    caught(() => el.speakStream({ sampleRate: 16000, delayMs: -5 }));
    const goesOn = s.open;
    el.stop();
    const stopped = await Promise.race([s.done.then(() => 'resolved'), new Promise((r) => setTimeout(() => r('pending'), 2000))]);
    const after = { written: s.write(tone(1)), status: status(), take: el.currentAnimation };
    const again = el.speakStream({ sampleRate: 16000 });
    again.write(tone(1));
    again.end();
    await again.done;
    return { messages, during, goesOn, stopped, after, events, frames: el.currentAnimation?.frames ?? 0 };
  });
  expect(r.messages).toEqual([
    expect.stringMatching(/^TypeError: SpeechStream\.write takes a Float32Array .*a string \(base64 text\? decode it to bytes first\)$/),
    expect.stringMatching(/^RangeError: SpeechStream\.write: sample 1 of the piece is Infinity/),
    expect.stringMatching(/^TalkingFaceError: speakStream: sampleRate must be the stream's rate in Hz, a whole number from 8000 to 96000 .* it was undefined$/),
    expect.stringMatching(/^TalkingFaceError: speakStream: delayMs must be from 0 to 10000 ms; it was -5$/),
  ]);
  expect(r.goesOn).toBe(true);
  expect(r.during).toMatch(/^Playing streamed speech \(\d+ ms behind it, cpu\)\.$/);
  expect(r.stopped).toBe('resolved');
  expect(r.after).toEqual({ written: false, status: 'Stopped.', take: null });
  expect(r.events).toEqual(['error:audio', 'error:audio', 'ended', 'ended']);
  expect(r.frames).toBe(30);
});

test('a MediaStream is followed with the face until its audio ends, its tracks left running; write() is refused on it', async ({ page }) => {
  test.setTimeout(150_000);
  await page.goto('/examples/embed.html');
  const r = await page.evaluate(async () => {
    type Stream = { write(p: unknown): boolean; end(): void; done: Promise<void>; seconds: number; delayMs: number };
    const el = document.getElementById('left') as HTMLElement & { speakStream(o: unknown): Stream; stop(): void; ready: Promise<unknown> };
    await el.ready;
    const media = await navigator.mediaDevices.getUserMedia({ audio: true });
    const frames: number[] = [];
    let ended = 0;
    el.addEventListener('frame', (e) => {
      const d = (e as CustomEvent).detail;
      if (d.mode === 'stream') frames.push(d.frame);
    });
    el.addEventListener('ended', () => ended++);
    const messages: string[] = [];
    for (const options of [{ media: 'not a stream' }, { media, sampleRate: 16000 }]) {
      try { el.speakStream(options); } catch (e) { messages.push((e as Error).message); }
    }
    const speech = el.speakStream({ media });
    try { speech.write(new Float32Array(10)); } catch (e) { messages.push((e as Error).message); }
    // Followed for 3 s at least, and until 11 frames were shown: a loaded machine draws few a second.
    const start = performance.now();
    while (performance.now() - start < 3000 || (frames.length <= 10 && performance.now() - start < 30_000)) {
      await new Promise((res) => setTimeout(res, 100));
    }
    const during = { frames: frames.length, seconds: speech.seconds, delay: speech.delayMs, status: el.shadowRoot!.querySelector('p.status')!.textContent, waited: Math.round(performance.now() - start) };
    media.getAudioTracks()[0].stop(); // the agent hangs up: the rest plays out
    const settled = await Promise.race([speech.done.then(() => 'resolved'), new Promise((res) => setTimeout(() => res('pending'), 10_000))]);
    const second = await navigator.mediaDevices.getUserMedia({ audio: true });
    const again = el.speakStream({ media: second });
    await new Promise((res) => setTimeout(res, 1500));
    el.stop();
    await again.done;
    return { messages, during, settled, ended, status: el.shadowRoot!.querySelector('p.status')!.textContent, left: second.getAudioTracks()[0].readyState };
  });
  console.log(`followed the fake microphone: ${JSON.stringify(r.during)}`);
  expect(r.messages).toEqual([
    "speakStream: media must be a MediaStream (a WebRTC track's stream, getUserMedia's, captureStream()'s)",
    'speakStream: give sampleRate (pieces written) or media (a MediaStream), not both',
    'SpeechStream.write: this stream follows a MediaStream; write() is for a stream opened with a sampleRate',
  ]);
  expect(r.during.frames).toBeGreaterThan(10);
  expect(r.during.seconds).toBeGreaterThan(1.5);
  expect(r.during.status).toMatch(/^Playing streamed speech \(\d+ ms behind it, cpu\)\.$/);
  expect(r.settled).toBe('resolved');
  expect(r.ended).toBe(2); // played out, then stopped
  expect(r.status).toBe('Stopped.');
  expect(r.left).toBe('live'); // stop() leaves the page's stream running
});
