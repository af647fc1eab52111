/**
 * What a file the browser could not decode is, from its first bytes, so that the message says what to do: an image
 * or a text is not audio; a WAV in an encoding browsers do not read (ADPCM, GSM, 64-bit float), an AIFF (which
 * Chromium and Firefox do not read) wants converting; a WAV with no samples has nothing to animate. Library code.
 */

/** Where a file in a format that browsers read can be made: what every message about an unreadable format ends with. */
export const CONVERT = 'convert it to WAV (16-bit PCM), MP3, FLAC or Ogg and try again';

/** WAVE format tags (RFC 2361) browsers do not decode, by name. */
const WAV_ENCODINGS: Record<number, string> = {
  0x0002: 'Microsoft ADPCM',
  0x0011: 'IMA ADPCM',
  0x0031: 'GSM 6.10',
  0x0040: 'G.721 ADPCM',
  0x0064: 'G.726 ADPCM',
  0x0092: 'Dolby AC-3',
  0x0161: 'Windows Media Audio',
  0x0162: 'Windows Media Audio',
};

/** Signatures of files people drop by mistake. */
const NOT_AUDIO: [string, number[]][] = [
  ['a PNG image', [0x89, 0x50, 0x4e, 0x47]],
  ['a JPEG image', [0xff, 0xd8, 0xff]],
  ['a GIF image', [0x47, 0x49, 0x46, 0x38]],
  ['a PDF document', [0x25, 0x50, 0x44, 0x46]],
  ['a ZIP archive (or an Office document)', [0x50, 0x4b, 0x03, 0x04]],
];

/** `n` bytes of `b` from `at` as text (a chunk's id, a file's signature). */
export const ascii = (b: Uint8Array, at: number, n: number): string => String.fromCharCode(...b.subarray(at, at + n));

/** A WAV fmt chunk's format (the chunk's header at `at`; 24 bytes of it there): WAVE_FORMAT_EXTENSIBLE as its sub-format. */
export function wavFormat(v: DataView, at: number): { tag: number; channels: number; rate: number; bits: number } {
  const tag = v.getUint16(at + 8, true);
  return { tag: tag === 0xfffe && at + 34 <= v.byteLength ? v.getUint16(at + 32, true) : tag,
    channels: v.getUint16(at + 10, true), rate: v.getUint32(at + 12, true), bits: v.getUint16(at + 22, true) };
}

/**
 * Why `bytes` could not be decoded, as a clause for a message ("it is a PNG image, not audio"), or null where the
 * first bytes do not tell (then the browser's own reason is all there is).
 */
export function undecodableReason(bytes: ArrayBuffer): string | null {
  const b = new Uint8Array(bytes, 0, Math.min(bytes.byteLength, 4096));
  for (const [what, magic] of NOT_AUDIO) if (magic.every((x, i) => b[i] === x)) return `it is ${what}, not audio`;
  if (ascii(b, 0, 4) === 'RIFF' && ascii(b, 8, 4) === 'WAVE') return wavReason(new DataView(bytes));
  if (ascii(b, 0, 4) === 'FORM' && /^AIF[FC]$/.test(ascii(b, 8, 4))) return `it is an AIFF file, which this browser cannot decode: ${CONVERT}`;
  if (looksLikeText(b)) {
    // A URL that is not there often brings the site's index page (a host's fallback), not an error.
    // (decoded: a UTF-8 byte-order mark before the page, as some editors and hosts write, is dropped)
    return /^\s*<(!doctype html|html|head|body)/i.test(new TextDecoder().decode(b.subarray(0, 200)))
      ? 'it is an HTML page, not audio (a wrong URL, which the site answered with a page?)'
      : 'it is a text file, not audio';
  }
  return null;
}

/** A WAV's chunks: its encoding (the fmt chunk's tag and sample size) and whether it has samples (the data chunk). */
function wavReason(v: DataView): string {
  let tag = -1, bits = 0, data = -1;
  for (let at = 12; at + 8 <= v.byteLength;) {
    const id = String.fromCharCode(v.getUint8(at), v.getUint8(at + 1), v.getUint8(at + 2), v.getUint8(at + 3));
    const size = v.getUint32(at + 4, true);
    if (id === 'fmt ' && at + 24 <= v.byteLength) ({ tag, bits } = wavFormat(v, at));
    if (id === 'data') data = Math.min(size, v.byteLength - at - 8);
    at += 8 + size + (size % 2);
  }
  if (tag < 0) return 'it is a damaged WAV file: it has no format (fmt) chunk';
  if (data <= 0) return 'it is a WAV file with no audio in it';
  const encoding = WAV_ENCODINGS[tag] ?? (tag === 3 && bits === 64 ? '64-bit floating point' : null);
  if (encoding) return `it is a WAV file in ${encoding}, which this browser cannot decode: ${CONVERT}`;
  return `it is a WAV file (format ${tag}, ${bits}-bit) that this browser cannot decode: ${CONVERT}`;
}

/** A WAV data size from here up means "not known when written" (sox's 0x7FFFF000 to a pipe; 0xFFFFFFFF), not a length. */
const OPEN_SIZE = 0x7ffff000;

/**
 * How many seconds a WAV's header says its data chunk holds, where that is more than the file holds (a file cut
 * short while copying or recording: browsers decode what is there and say nothing); null otherwise, and for other
 * formats and for a data size left open (0, 0xFFFFFFFF, or sox's 0x7FFFF000 when it writes to a pipe, as recorders
 * that stream write it).
 */
export function statedSecondsIfCut(bytes: ArrayBuffer): number | null {
  const v = new DataView(bytes);
  if (v.byteLength < 12 || ascii(new Uint8Array(bytes, 0, 12), 0, 4) !== 'RIFF' || ascii(new Uint8Array(bytes, 0, 12), 8, 4) !== 'WAVE') return null;
  let byteRate = 0;
  for (let at = 12; at + 8 <= v.byteLength;) {
    const id = ascii(new Uint8Array(bytes, at, 4), 0, 4);
    const size = v.getUint32(at + 4, true);
    if (id === 'fmt ' && at + 20 <= v.byteLength) byteRate = v.getUint32(at + 16, true);
    if (id === 'data') {
      const present = v.byteLength - at - 8;
      if (size === 0 || size >= OPEN_SIZE || size <= present || !byteRate) return null;
      return size / byteRate;
    }
    at += 8 + size + (size % 2);
  }
  return null;
}

/** Printable text (UTF-8, tabs and line ends) throughout its first bytes. */
function looksLikeText(b: Uint8Array): boolean {
  if (b.length === 0) return false;
  try {
    // (stream: a character cut at the 4096th byte is not an error)
    return !/[\u0000-\u0008\u000e-\u001f\u007f]/.test(new TextDecoder('utf-8', { fatal: true }).decode(b, { stream: true }));
  } catch {
    return false; // not UTF-8: not text
  }
}
