/**
 * Raw audio that arrives in pieces (a streaming text-to-speech, a voice agent's socket) as mono samples: float
 * samples in -1..1, 16-bit integers, or the bytes of 16-bit little-endian PCM as most speech services send them.
 */

/** What a piece of streamed speech may be (SpeechStream.write). */
export type PcmChunk = Float32Array | Int16Array | ArrayBuffer | SharedArrayBuffer | Uint8Array | DataView;

/** Where a stream's sample rate must lie: what an AudioBuffer accepts in every browser. */
export const MIN_STREAM_RATE = 8000;
export const MAX_STREAM_RATE = 96000;

/** Turns pieces into samples, keeping a byte that a piece of 16-bit PCM ended on for the next piece. */
export class PcmReader {
  private odd: number | null = null; // the first byte of a sample split between two pieces

  constructor(private readonly where: string) {}

  /** The piece as float samples (a new array); throws a TypeError or RangeError that says what was wrong. */
  read(chunk: unknown): Float32Array {
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

  /** Whether a byte is waiting for its pair (a stream ended on it is one byte short). */
  get pending(): boolean {
    return this.odd !== null;
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
