/**
 * Raw audio that arrives in pieces (a streaming text-to-speech, a voice agent's socket) as mono samples: float
 * samples in -1..1, 16-bit integers, or the bytes of 16-bit little-endian PCM as most speech services send them.
 */
import { ascii, wavFormat } from './sniff';

/** What a piece of streamed speech may be (SpeechStream.write). */
export type PcmChunk = Float32Array | Int16Array | ArrayBuffer | SharedArrayBuffer | Uint8Array | DataView;

/** Where a stream's sample rate must lie: what an AudioBuffer accepts in every browser. */
export const MIN_STREAM_RATE = 8000;
export const MAX_STREAM_RATE = 96000;

/** The most bytes a WAV header at a stream's start may take before its data: beyond, it is not one (a stream is refused). */
const MAX_WAV_HEADER = 65536;

/**
 * Turns pieces into samples, keeping a byte that a piece of 16-bit PCM ended on for the next piece. Bytes that begin
 * with a WAV header (as some services send their "PCM": Google's LINEAR16, OpenAI's `wav`) have it read and skipped,
 * not played as samples (a click): it must say mono 16-bit PCM at `sampleRate` (where given), else a RangeError says
 * what it is.
 */
export class PcmReader {
  private odd: number | null = null; // the first byte of a sample split between two pieces
  private head: Uint8Array | null = new Uint8Array(0); // the stream's first bytes while they may be a WAV header; null after
  private refused: RangeError | null = null; // a WAV header it cannot play: every later piece is refused too (not read as PCM)

  constructor(private readonly where: string, private readonly sampleRate?: number) {}

  /** The piece as float samples (a new array); throws a TypeError or RangeError that says what was wrong. */
  read(chunk: unknown): Float32Array {
    if (this.refused) throw this.refused;
    if (chunk instanceof Float32Array || chunk instanceof Int16Array) this.head = null; // samples: no header to come
    if (chunk instanceof Float32Array) return finite(chunk.slice(), this.where);
    if (chunk instanceof Int16Array) return fromInt16(chunk);
    if (chunk instanceof ArrayBuffer || (typeof SharedArrayBuffer !== 'undefined' && chunk instanceof SharedArrayBuffer)) return this.bytes(new Uint8Array(chunk));
    if (chunk instanceof Uint8Array || chunk instanceof DataView) return this.bytes(new Uint8Array(chunk.buffer, chunk.byteOffset, chunk.byteLength));
    throw new TypeError(`${this.where} takes a Float32Array (samples in -1..1), an Int16Array, or the bytes of 16-bit little-endian PCM `
      + `(an ArrayBuffer, SharedArrayBuffer, Uint8Array or DataView); it was given ${describe(chunk, 'base64 text? decode it to bytes first')}`
      + (typeof Blob !== 'undefined' && chunk instanceof Blob ? ` (a WebSocket's message: set socket.binaryType = 'arraybuffer' first)` : ''));
  }

  /** Bytes of 16-bit little-endian PCM; a byte left over waits for the next piece. */
  private bytes(piece: Uint8Array): Float32Array {
    if (this.head) {
      const start = new Uint8Array(this.head.length + piece.length);
      start.set(this.head);
      start.set(piece, this.head.length);
      const found = wavData(start);
      if (found === 'more' && start.length > MAX_WAV_HEADER) throw new RangeError(`${this.where}: the stream begins as a WAV file but has no data chunk in its first ${MAX_WAV_HEADER} bytes`);
      this.head = found === 'more' ? start : null;
      if (found === 'more') return new Float32Array(0); // the rest of the header is still to come
      try {
        if (found) this.check(found.format);
      } catch (e) {
        throw (this.refused = e as RangeError);
      }
      piece = start.subarray(found ? found.data : 0);
    }
    let bytes = piece;
    if (this.odd !== null) {
      bytes = new Uint8Array(piece.length + 1);
      bytes[0] = this.odd;
      bytes.set(piece, 1);
    }
    const out = new Float32Array(bytes.length >> 1);
    for (let s = 0; s < out.length; s++) {
      const v = bytes[2 * s] | (bytes[2 * s + 1] << 8);
      out[s] = (v >= 0x8000 ? v - 0x10000 : v) / 32768;
    }
    this.odd = bytes.length % 2 ? bytes[bytes.length - 1] : null;
    return out;
  }

  /** A WAV header's format: mono 16-bit PCM at the stream's rate, else a RangeError saying what it is. */
  private check(f: WavFormat): void {
    const pcm = f.tag === 1 && f.bits === 16 && f.channels === 1;
    if (pcm && (this.sampleRate === undefined || f.rate === this.sampleRate)) return;
    const what = !f.channels ? 'with no format (fmt) chunk before its data' : `${f.channels === 1 ? 'mono' : `${f.channels} channels`}, ${f.bits}-bit ${f.tag === 3 ? 'float' : f.tag === 1 ? 'PCM' : `format ${f.tag}`}, ${f.rate} Hz`;
    throw new RangeError(`${this.where}: the stream is a WAV file ${f.channels ? `(${what})` : what}; it takes mono 16-bit PCM at the stream's sampleRate`
      + `${this.sampleRate ? ` (${this.sampleRate} Hz)` : ''}: ask the service for that, or open the stream with its rate`);
  }

  /** Whether a byte is waiting for its pair (a stream ended on it is one byte short). */
  get pending(): boolean {
    return this.odd !== null;
  }
}

type WavFormat = ReturnType<typeof wavFormat>;

/**
 * Where a WAV header at the start of `b` ends (its data chunk's first byte) and the format it states; 'more' while
 * the bytes so far may still be one; null where they are not one (raw PCM).
 */
function wavData(b: Uint8Array): { data: number; format: WavFormat } | 'more' | null {
  const riff = [0x52, 0x49, 0x46, 0x46]; // "RIFF"
  if (b.length < 12) return riff.every((c, i) => i >= b.length || b[i] === c) ? 'more' : null;
  if (ascii(b, 0, 4) !== 'RIFF' || ascii(b, 8, 4) !== 'WAVE') return null;
  const v = new DataView(b.buffer, b.byteOffset, b.byteLength);
  let format: WavFormat | null = null;
  for (let at = 12; ; ) {
    if (at + 8 > b.length) return 'more';
    const size = v.getUint32(at + 4, true);
    if (ascii(b, at, 4) === 'data') return { data: at + 8, format: format ?? { tag: 0, channels: 0, rate: 0, bits: 0 } }; // (none: refused)
    if (ascii(b, at, 4) === 'fmt ') {
      if (at + 24 > b.length) return 'more';
      format = wavFormat(v, at);
    }
    at += 8 + size + (size % 2);
  }
}

function fromInt16(chunk: Int16Array): Float32Array {
  const out = new Float32Array(chunk.length);
  for (let i = 0; i < chunk.length; i++) out[i] = chunk[i] / 32768;
  return out;
}

function finite(samples: Float32Array, where: string): Float32Array {
  for (let i = 0; i < samples.length; i++) {
    // (The engine refuses beyond 1e12 too, engine/checks.ts: far beyond any audio scale.)
    if (!(Math.abs(samples[i]) <= 1e12)) throw new RangeError(`${where}: sample ${i} of the piece is ${samples[i]}; samples must be finite numbers (-1..1)`);
  }
  return samples;
}

/** What `value` is, for a message; `ifString`: what a string there probably is. */
function describe(value: unknown, ifString: string): string {
  if (value === null || value === undefined) return String(value);
  if (typeof value === 'string') return `a string (${ifString})`;
  const name = typeof value === 'object' ? (value as object).constructor?.name ?? 'object' : typeof value;
  return `${/^[aeiou]/i.test(name) ? 'an' : 'a'} ${name}`;
}

/** A stream's sample rate, checked: a whole number of Hz that an AudioBuffer can hold. */
export function checkedStreamRate(rate: unknown, where: string): number {
  if (typeof rate !== 'number' || !Number.isInteger(rate) || rate < MIN_STREAM_RATE || rate > MAX_STREAM_RATE) {
    throw new RangeError(`${where}: sampleRate must be the stream's rate in Hz, a whole number from ${MIN_STREAM_RATE} to ${MAX_STREAM_RATE} `
      + `(24000 for most speech services' 16-bit PCM); it was ${typeof rate === 'number' ? rate : describe(rate, `${JSON.stringify(rate)}: give a number`)}`);
  }
  return rate;
}
