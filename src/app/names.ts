/** A take's name as the demo shows it in a message and as the files it saves are named. */

/**
 * A file's name inside a message, set apart (Unicode's first-strong isolate) where it holds right-to-left letters, so
 * that the words and numbers around it keep their order ("Saved تسجيل.97x468x3.f32" would show the 97 before the name).
 */
export function isolated(name: string): string {
  return /[\u0590-\u08ff\ufb1d-\ufdff\ufe70-\ufefc]/.test(name) ? `\u2068${name}\u2069` : name;
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
