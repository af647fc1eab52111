/** What <talking-face>'s attributes and speak()'s argument mean, checked: a bad value warns and falls back. */
import { MAX_HEAD_MOTION_SCALE, type Backend } from '../engine/engine';
import { checkedBackend } from '../engine/checks';
import { fetchBody } from '../model/fetch-body';

/** The `backend` attribute: auto (absent or empty), cpu or webgpu (the engine's names); anything else warns and means auto. */
export function backendAttribute(value: string | null): 'auto' | Backend {
  const v = value?.trim() ?? '';
  try {
    return v ? checkedBackend(v) : 'auto';
  } catch (e) {
    console.warn(`<talking-face> backend="${v}": ${(e as Error).message}; using auto`);
    return 'auto';
  }
}

/**
 * How the `avatar` is bound: `avatar-head-bone` (the node turned with the head; default Head or head, or a VRM's
 * humanoid head) and `avatar-facing` (+z, glTF's convention, or -z; absent, the file decides: -z for VRM 0.x, else
 * +z; another value warns and is left to the file likewise).
 */
export function avatarAttributes(el: Element): { headBone: string | null; facing: '+z' | '-z' | undefined } {
  const v = el.getAttribute('avatar-facing')?.trim() ?? '';
  if (v && v !== '+z' && v !== '-z') console.warn(`<talking-face> avatar-facing="${v}" is not +z or -z; ignored (the file decides: -z for VRM 0.x, else +z)`);
  return { headBone: el.getAttribute('avatar-head-bone'), facing: v === '-z' || v === '+z' ? v : undefined };
}

/**
 * What an element's face is made from, as it means it: the model (`defaultModel` where none is named), template,
 * backend ('auto' where none), avatar and its head bone and facing. The same again: nothing to load again.
 */
export function loadKey(el: Element, defaultModel: string): string[] {
  const a = (name: string) => el.getAttribute(name)?.trim() ?? '';
  return [a('model') || defaultModel, a('template'), a('backend') || 'auto', a('avatar'), a('avatar-head-bone'), a('avatar-facing')];
}

/** What differs between two loadKeys: the model or template, else the avatar, else the backend only; or null. */
export function loadChange(was: string[], now: string[]): 'model' | 'avatar' | 'backend' | null {
  const changed = (from: number, to: number) => now.slice(from, to).some((v, i) => v !== was[from + i]);
  return changed(0, 2) ? 'model' : changed(3, 6) ? 'avatar' : changed(2, 3) ? 'backend' : null;
}

/**
 * Whether a boolean attribute is on: present, and not "false" (React 18 writes `autoplay={false}` as
 * autoplay="false"; the HTML way, absent, is off too).
 */
export function isOn(value: string | null): boolean {
  return value !== null && value.trim().toLowerCase() !== 'false';
}

/** A property that reflects its attribute: a string sets it, null or undefined removes it. */
export function reflect(el: Element, name: string, value: string | null | undefined): void {
  if (value == null) el.removeAttribute(name);
  else el.setAttribute(name, String(value));
}

/** The `head-motion` attribute for the next animation or session (one outside 0-3 warns and is ignored). */
export function headMotionAttribute(value: string | null): number | undefined {
  const v = value?.trim(), x = Number(v);
  if (v && Number.isFinite(x) && x >= 0 && x <= MAX_HEAD_MOTION_SCALE) return x;
  if (v) console.warn(`<talking-face> head-motion="${v}" is not a number from 0 to ${MAX_HEAD_MOTION_SCALE}; using the model's own motion (1)`);
  return undefined;
}

/**
 * What the attributes ask of each animation or live session: ARKit weights and visemes with an avatar or when the
 * page asks (`blendshapes`); the head's own motion's scale (`head-motion`), read at each speak() and startMicrophone().
 */
export function frameOptions(el: Element): { blendshapes: boolean; headMotionScale: number | undefined } {
  return { blendshapes: el.hasAttribute('avatar') || isOn(el.getAttribute('blendshapes')), headMotionScale: headMotionAttribute(el.getAttribute('head-motion')) };
}

/** A URL as a person wrote it ("Grüße.wav", not "Gr%C3%BC%C3%9Fe.wav"); as it is where it holds a malformed %-sequence. */
function readable(url: string): string {
  try {
    return decodeURI(url);
  } catch (e) {
    if (e instanceof URIError) return url;
    throw e;
  }
}

/**
 * speak()'s audio as something decodeAudio takes: a URL is fetched (the message names it, with its host when it is
 * another origin's); `signal` cancels the download.
 */
export async function audioInput(audio: Blob | AudioBuffer | URL | string, signal?: AbortSignal): Promise<Blob | AudioBuffer> {
  if (audio instanceof Blob || (typeof AudioBuffer !== 'undefined' && audio instanceof AudioBuffer)) return audio;
  if (!(typeof audio === 'string' || audio instanceof URL) || audio === '') {
    const got = audio === null ? 'null' : audio === '' ? 'an empty string' : typeof audio === 'object' ? (audio as object).constructor?.name ?? 'an object' : typeof audio;
    throw new TypeError(`speak() takes a Blob or File, an AudioBuffer, or a URL (got ${got})`);
  }
  const url = new URL(String(audio), document.baseURI);
  const shown = readable(url.origin === location.origin ? url.pathname : url.href);
  const res = await fetchBody(url, { signal }).catch((e: Error) => {
    if (signal?.aborted) throw e;
    throw new Error(`could not fetch ${shown}: ${e.message}`);
  });
  if (!res.ok) throw new Error(`could not fetch ${shown}: HTTP ${res.status}`);
  return new Blob([res.bytes]);
}
