/** A take's name as the demo shows it in a message and as the files it saves are named. */

/** The most characters of a name a message shows: a longer one is cut in the middle (its end and extension kept). */
export const SHOWN_NAME_LENGTH = 60;

/**
 * A file's name inside a message: at most SHOWN_NAME_LENGTH characters (a longer name would push the message's
 * reason out of the status line), set apart (Unicode's first-strong isolate) where it holds right-to-left letters, so
 * that the words and numbers around it keep their order ("Saved تسجيل.97x468x3.f32" would show the 97 before the name).
 */
export function isolated(name: string): string {
  const chars = [...name];
  const half = (SHOWN_NAME_LENGTH - 1) / 2;
  const shown = chars.length <= SHOWN_NAME_LENGTH ? name : `${chars.slice(0, Math.ceil(half)).join('')}…${chars.slice(-Math.floor(half)).join('')}`;
  return /[\u0590-\u08ff\ufb1d-\ufdff\ufe70-\ufefc]/.test(shown) ? `\u2068${shown}\u2069` : shown;
}

/**
 * The name a take's exports are saved under: its name without its extension, with the characters that file systems
 * refuse (Windows' < > : " / \\ | ? * and control characters) as "_", as the browser would save it (so the message names
 * the file on disk), and at most 200 bytes of UTF-8 (file systems allow 255; the suffix needs the rest); "take" where
 * nothing is left (a file named ".wav").
 */
export function fileBaseName(name: string): string {
  const plain = name.replace(/\.[^.]+$/, '').replace(/[<>:"/\\|?*\u0000-\u001f]/g, '_').trim();
  const utf8 = new TextEncoder();
  let out = '';
  let bytes = 0;
  for (const ch of plain) {
    bytes += utf8.encode(ch).length;
    if (bytes > 200) break;
    out += ch;
  }
  return out.trim() || 'take';
}
