import { test, expect } from './fixtures';
import { fakeMicrophone } from '../../playwright.config';
import { SPEECH } from './helpers/audio';

/**
 * Choosing the microphone: the demo's list beside Record (named once the page may use a microphone, the choice kept
 * for the next visit, not changeable while recording) and <talking-face>'s startMicrophone({ deviceId }). Chromium's
 * fake devices: a default and two inputs ("Fake Audio Input 1" and "2"), all playing the same speech.
 */
test.use({ launchOptions: fakeMicrophone(SPEECH) });

type Page = import('@playwright/test').Page;

/** The device each stream getUserMedia gives was opened on (window.opened), from the page's start. */
const WATCH = () => {
  const g = globalThis as unknown as { opened: string[]; streams: MediaStream[] };
  [g.opened, g.streams] = [[], []];
  const getUserMedia = navigator.mediaDevices.getUserMedia.bind(navigator.mediaDevices);
  navigator.mediaDevices.getUserMedia = async (c) => {
    const s = await getUserMedia(c);
    g.opened.push(s.getAudioTracks()[0].getSettings().deviceId ?? '?');
    g.streams.push(s);
    return s;
  };
};
const opened = (page: Page) => page.evaluate(() => (globalThis as unknown as { opened: string[] }).opened);

async function record(page: Page): Promise<void> {
  await page.locator('#record-button').click();
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
}

async function stopRecording(page: Page): Promise<void> {
  await page.locator('#record-button').click();
  await expect(page.locator('#record-button')).toHaveText('Record');
  await expect(page.locator('#record-button')).toBeEnabled({ timeout: 60_000 });
  await expect(page.locator('#microphone-select')).toBeEnabled({ timeout: 60_000 });
}

test('the demo records from the microphone chosen beside Record, and remembers it', async ({ page }) => {
  test.setTimeout(180_000);
  await page.addInitScript(WATCH);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  const select = page.locator('#microphone-select');
  await expect(select).toHaveValue('');
  const widthBefore = (await select.boundingBox())!.width;
  console.log(`before any recording the list holds ${await select.locator('option').count()} entries (the browser may hide them until allowed)`);

  // The first recording opens the system's default; the list then names every input.
  await record(page);
  await expect(select).toBeDisabled();
  await expect(select.locator('option')).toHaveText([/^default \(Fake Default Audio Input\)$/, 'Fake Audio Input 1', 'Fake Audio Input 2'], { timeout: 10_000 });
  expect((await select.boundingBox())!.width, 'the names filling the list move nothing').toBe(widthBefore);
  await stopRecording(page);
  expect(await opened(page)).toEqual(['default']);

  // A chosen input is the one opened.
  await select.selectOption({ label: 'Fake Audio Input 2' });
  const chosen = await select.inputValue();
  expect(chosen).not.toBe('');
  await record(page);
  await stopRecording(page);
  expect((await opened(page))[1], 'the second recording opened the chosen input').toBe(chosen);

  // The next visit: still chosen, and opened.
  await page.reload();
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(select).toHaveValue(chosen);
  await record(page);
  await stopRecording(page);
  expect(await opened(page)).toEqual([chosen]);

  // A browser that lists no input until the page is allowed one (as on a visit where permission was given only
  // "this time"): the earlier choice is still there and still asked for.
  const hiding = await page.context().newPage();
  await hiding.addInitScript(WATCH);
  await hiding.addInitScript(() => {
    navigator.mediaDevices.enumerateDevices = async () => [{ kind: 'audioinput', deviceId: '', label: '', groupId: '' } as MediaDeviceInfo];
  });
  await hiding.goto('/');
  await expect(hiding.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(hiding.locator('#microphone-select option')).toHaveText(['default', 'the one chosen before']);
  await expect(hiding.locator('#microphone-select')).toHaveValue(chosen);
  await record(hiding);
  await stopRecording(hiding);
  expect(await opened(hiding)).toEqual([chosen]);
  await hiding.close();
});

test('a remembered microphone that is gone, asked for while the browser hides the list, records from the default', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(WATCH);
  await page.addInitScript(() => {
    localStorage.setItem('talking-face:microphone', 'a-microphone-unplugged-since');
    navigator.mediaDevices.enumerateDevices = async () => [{ kind: 'audioinput', deviceId: '', label: '', groupId: '' } as MediaDeviceInfo];
  });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await expect(page.locator('#microphone-select')).toHaveValue('a-microphone-unplugged-since');
  await record(page);
  await expect(page.locator('#status')).toContainText('Recording');
  await stopRecording(page);
  expect(await opened(page)).toEqual(['default']);
});

test('the demo says so when the microphone stops sending sound while recording, and Stop recording keeps what was heard', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(WATCH);
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await record(page);
  await page.waitForTimeout(1500);
  await page.evaluate(() => (globalThis as unknown as { streams: MediaStream[] }).streams[0].getAudioTracks()[0].stop()); // as unplugged
  await expect(page.locator('#status')).toContainText('Recording, but the microphone stopped sending sound', { timeout: 5_000 });
  await expect(page.locator('#status')).toHaveClass(/error/);
  await stopRecording(page);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
});

test('a file opened while the microphone is being asked for is refused, not played over the recording', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(() => { // the browser's prompt, answered after three seconds
    const getUserMedia = navigator.mediaDevices.getUserMedia.bind(navigator.mediaDevices);
    navigator.mediaDevices.getUserMedia = async (c) => (await new Promise((r) => setTimeout(r, 3000)), getUserMedia(c));
  });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#record-button').click();
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('#status')).toContainText('The recording is starting (the browser may be asking for the microphone)');
  await expect(page.locator('body')).toHaveAttribute('data-recording', 'true', { timeout: 20_000 });
  await stopRecording(page);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#clip-info')).toContainText('Recording:'); // the take is the recording, not the file
});

test('Escape cancels a recording whose microphone prompt is unanswered; files open again, and a microphone given later is let go', async ({ page }) => {
  test.setTimeout(120_000);
  await page.addInitScript(() => { // the browser's prompt, answered when the test says (window.answer())
    const g = globalThis as unknown as { answer: () => void; given: MediaStream[] };
    g.given = [];
    const getUserMedia = navigator.mediaDevices.getUserMedia.bind(navigator.mediaDevices);
    navigator.mediaDevices.getUserMedia = async (c) => {
      await new Promise<void>((r) => { g.answer = r; });
      const s = await getUserMedia(c);
      g.given.push(s);
      return s;
    };
  });
  await page.goto('/');
  await expect(page.locator('body')).toHaveAttribute('data-engine', 'ready', { timeout: 60_000 });
  await page.locator('#record-button').click();
  await expect(page.locator('#status')).toContainText('Opening the microphone (the browser may ask you first; Escape cancels)');
  await page.keyboard.press('Escape');
  await expect(page.locator('#status')).toContainText('Recording cancelled before it started');
  await expect(page.locator('#record-button')).not.toHaveAttribute('aria-disabled', 'true');
  await page.locator('#file-input').setInputFiles(SPEECH);
  await expect(page.locator('body')).toHaveAttribute('data-take', 'ready', { timeout: 60_000 });
  await expect(page.locator('#clip-info')).not.toContainText('Recording');
  await page.evaluate(() => (globalThis as unknown as { answer: () => void }).answer()); // the prompt answered at last
  await expect.poll(() => page.evaluate(() => (globalThis as unknown as { given: MediaStream[] }).given
    .map((s) => s.getAudioTracks()[0].readyState)), { timeout: 5_000 }).toEqual(['ended']);
  await expect(page.locator('body')).not.toHaveAttribute('data-recording', 'true');
});

test('the element listens to the microphone it is given, and says so plainly when that one is not connected', async ({ page }) => {
  test.setTimeout(90_000);
  await page.addInitScript(WATCH);
  await page.goto('/examples/embed.html');
  await page.evaluate(() => (document.getElementById('left') as unknown as { ready: Promise<unknown> }).ready);
  const status = () => page.evaluate(() => document.getElementById('left')!.shadowRoot!.querySelector('p.status')!.textContent!);
  // listMicrophones() from the library the element came with.
  const inputs = await page.evaluate(async () => {
    const { listMicrophones } = await import('/lib/talking-face.js' as string) as { listMicrophones(): Promise<{ deviceId: string; label: string }[]> };
    return listMicrophones();
  });
  expect(inputs.map((d) => d.label)).toEqual(['Fake Default Audio Input', 'Fake Audio Input 1', 'Fake Audio Input 2']);
  const one = inputs[1].deviceId;

  const failure = await page.evaluate(async () => {
    const el = document.getElementById('left') as unknown as HTMLElement & { startMicrophone(o: { deviceId: string }): Promise<void> };
    const events: string[] = [];
    el.addEventListener('error', (e) => events.push(`${(e as unknown as CustomEvent).detail.stage}: ${(e as unknown as CustomEvent).detail.message}`));
    const rejected = await el.startMicrophone({ deviceId: 'not-a-device' }).then(() => 'resolved', (e: Error) => e.message);
    return { rejected, events };
  });
  expect(failure.rejected).toMatch(/the chosen microphone is not connected; plug it back in, or choose another/);
  expect(failure.events).toEqual([`microphone: ${failure.rejected}`]);
  expect(await status()).toMatch(/not connected/);

  await page.evaluate((deviceId) => void (document.getElementById('left') as unknown as { startMicrophone(o: { deviceId: string }): Promise<void> }).startMicrophone({ deviceId }), one);
  await expect.poll(status, { timeout: 20_000 }).toContain('Listening');
  expect(await opened(page), 'the failed try opened nothing; the second opened the input given').toEqual([one]);
  await page.evaluate(() => (document.getElementById('left') as unknown as { stop(): void }).stop());
});
