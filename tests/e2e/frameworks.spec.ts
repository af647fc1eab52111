import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { test, expect } from './fixtures';

/**
 * <talking-face> as frameworks set its attributes. React 19 sets a prop on a custom element as a property where the
 * element has one (`name in element`), else as an attribute (true: "", false: removed); React 18 writes every prop
 * as an attribute, false as "false". For every attribute the declarations type (src/component/element-types.ts), both
 * ways: nothing throws (a getter without a setter would, in a module's strict code) and the attribute ends up as the
 * element reads it. Then React 18's "false": an element with autoplay="false" and hide-status="false" does not play
 * and shows its status. And an avatar switched on from state after an autoplayed take does not speak it again, while
 * one set at once after the element is added does not keep it from being autoplayed.
 */
const JSX = readFileSync(resolve(import.meta.dirname, '../../src/component/element-types.ts'), 'utf8');
const start = JSX.indexOf('export interface TalkingFaceAttributes');
const block = JSX.slice(start, JSX.indexOf('\n}\n', start));
const ATTRIBUTES = [...block.matchAll(/^\s+'?([a-z-]+)'?\?:\s*([^;]+);/gm)].map(([, name, type]) => ({ name, boolean: type.trim() === 'boolean' }));

/** A value of each kind to set: both booleans, else one the attribute takes. */
const SAMPLE: Record<string, string | number> = { backend: 'cpu', 'avatar-facing': '-z', 'head-motion': 1.5 };
const CASES = ATTRIBUTES.flatMap(({ name, boolean }) => (boolean ? [true, false] : [SAMPLE[name] ?? '/x']).map((value) => ({ name, value })));
const label = (name: string, value: unknown, react: number, attribute: string) => `${name}=${JSON.stringify(value)} (React ${react}): ${attribute}`;

test('every declared attribute, set as React 19 and React 18 set props, reaches the element as an attribute', async ({ page }) => {
  expect(ATTRIBUTES.map((a) => a.name)).toEqual(expect.arrayContaining(['src', 'backend', 'autoplay', 'live', 'avatar', 'avatar-facing', 'blendshapes', 'head-motion']));
  await page.goto('/examples/embed.html');
  const results = await page.evaluate((cases) => cases.flatMap(({ name, value }) => [19, 18].map((react) => {
    const el = document.createElement('talking-face') as unknown as HTMLElement & Record<string, unknown>;
    try {
      if (react === 19 && name in el) el[name] = value;
      else if (react === 19 && value === true) el.setAttribute(name, '');
      else if (react === 19 && value === false) el.removeAttribute(name);
      else el.setAttribute(name, String(value));
      return JSON.stringify(el.getAttribute(name));
    } catch (e) {
      return `threw ${(e as Error).message}`;
    }
  })), CASES);
  // React 19: true "", false removed, else the value; React 18: every value as a string.
  const expected = CASES.flatMap(({ name, value }) => [
    label(name, value, 19, JSON.stringify(value === true ? '' : value === false ? null : String(value))),
    label(name, value, 18, JSON.stringify(String(value))),
  ]);
  expect(CASES.flatMap(({ name, value }, i) => [19, 18].map((react, k) => label(name, value, react, results[2 * i + k])))).toEqual(expected);
});

test('autoplay="false" does not play and hide-status="false" shows the status, as React 18 writes them', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/examples/embed.html');
  const seen = await page.evaluate(() => new Promise<{ frames: number; status: string; shown: boolean }>((resolve) => {
    document.querySelectorAll('talking-face').forEach((e) => e.remove());
    const el = document.createElement('talking-face');
    for (const [k, v] of [['backend', 'cpu'], ['src', '/examples/sample.wav'], ['autoplay', 'false'], ['hide-status', 'false']]) el.setAttribute(k, v);
    let frames = 0;
    el.addEventListener('frame', () => frames++);
    el.addEventListener('ready', () => setTimeout(() => {
      const status = el.shadowRoot!.querySelector('.status') as HTMLElement;
      resolve({ frames, status: status.textContent ?? '', shown: getComputedStyle(status).display !== 'none' });
    }, 2500));
    document.body.append(el);
  }));
  expect(seen.frames, 'no playback').toBe(0);
  expect(seen.status).toMatch(/^Ready/);
  expect(seen.shown, 'the status line shows').toBe(true);
});

test('another avatar does not speak an autoplayed src again', async ({ page }) => {
  test.setTimeout(180_000);
  await page.goto('/examples/embed.html');
  const framesAfter = await page.evaluate(() => new Promise<number>((resolve, reject) => {
    document.querySelectorAll('talking-face').forEach((e) => e.remove());
    const el = document.createElement('talking-face');
    for (const [k, v] of [['backend', 'cpu'], ['src', '/examples/sample.wav'], ['autoplay', '']]) el.setAttribute(k, v);
    let frames = 0, switched = false;
    el.addEventListener('frame', () => frames++);
    el.addEventListener('error', (e) => reject(new Error((e as CustomEvent).detail.message)));
    el.addEventListener('ended', () => {
      if (switched) return resolve(-1); // it played again
      switched = true;
      frames = 0;
      // Neither frames nor a take being made (speak() says "Decoding audio…" at once) 3 s after the avatar is shown.
      el.addEventListener('ready', () => setTimeout(() => {
        const status = el.shadowRoot!.querySelector('.status')!.textContent ?? '';
        resolve(/^Ready/.test(status) ? frames : -2);
      }, 3000));
      el.setAttribute('avatar', '/examples/avatars/arkit-face.glb');
    });
    document.body.append(el);
  }));
  expect(framesAfter, 'frames played after the avatar came').toBe(0);
});

test('an avatar set at once after the element is added does not keep src from being autoplayed', async ({ page }) => {
  test.setTimeout(120_000);
  await page.goto('/examples/embed.html');
  const ended = await page.evaluate(() => new Promise<boolean>((resolve, reject) => {
    document.querySelectorAll('talking-face').forEach((e) => e.remove());
    const el = document.createElement('talking-face');
    for (const [k, v] of [['backend', 'cpu'], ['src', '/examples/sample.wav'], ['autoplay', '']]) el.setAttribute(k, v);
    el.addEventListener('ended', () => resolve(true));
    el.addEventListener('error', (e) => reject(new Error((e as CustomEvent).detail.message)));
    document.body.append(el);
    el.setAttribute('avatar', '/examples/avatars/arkit-face.glb'); // as a framework binding it after mounting does
    setTimeout(() => resolve(false), 60_000);
  }));
  expect(ended, 'the clip was spoken').toBe(true);
});
