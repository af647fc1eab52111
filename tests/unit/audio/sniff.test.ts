/**
 * undecodableReason (src/audio/sniff.ts): what a file the browser could not decode is, from its first bytes, on the
 * files people bring (as sox writes them: the WAVE header's format tag and sample size, the data chunk); and
 * statedSecondsIfCut: a WAV cut short, which the browser decodes without a word.
 */
import { describe, expect, it } from 'vitest';
import { statedSecondsIfCut, undecodableReason } from '../../../src/audio/sniff';

/** A RIFF/WAVE file: a fmt chunk with `tag` and `bits` (extensible: tag 0xFFFE carrying it as its sub-format), then `dataBytes` of data. */
function wav(tag: number, bits: number, dataBytes: number, extensible = false): ArrayBuffer {
  const fmtSize = extensible ? 40 : 16;
  const b = new DataView(new ArrayBuffer(12 + 8 + fmtSize + 8 + dataBytes));
  const put = (at: number, s: string) => [...s].forEach((c, i) => b.setUint8(at + i, c.charCodeAt(0)));
  put(0, 'RIFF');
  b.setUint32(4, b.byteLength - 8, true);
  put(8, 'WAVE');
  put(12, 'fmt ');
  b.setUint32(16, fmtSize, true);
  b.setUint16(20, extensible ? 0xfffe : tag, true);
  b.setUint16(22, 1, true); // channels
  b.setUint32(24, 8000, true);
  b.setUint16(34, bits, true);
  if (extensible) b.setUint16(44, tag, true); // the sub-format GUID's first two bytes
  put(20 + fmtSize, 'data');
  b.setUint32(24 + fmtSize, dataBytes, true);
  return b.buffer;
}

const bytes = (...x: number[]) => new Uint8Array([...x, ...new Array(60).fill(7)]).buffer;

describe('undecodableReason', () => {
  it('names the WAV encodings browsers do not read and says to convert', () => {
    expect(undecodableReason(wav(0x11, 4, 100))).toBe('it is a WAV file in IMA ADPCM, which this browser cannot decode: convert it to WAV (16-bit PCM), MP3, FLAC or Ogg and try again');
    expect(undecodableReason(wav(0x02, 4, 100))).toMatch(/^it is a WAV file in Microsoft ADPCM, .*convert it/);
    expect(undecodableReason(wav(0x31, 0, 100))).toMatch(/GSM 6\.10/);
    expect(undecodableReason(wav(3, 64, 100))).toMatch(/64-bit floating point/);
    expect(undecodableReason(wav(3, 64, 100, true))).toMatch(/64-bit floating point/);
    expect(undecodableReason(wav(0x99, 8, 100))).toMatch(/^it is a WAV file \(format 153, 8-bit\) that this browser cannot decode: convert/);
  });

  it('tells a WAV with no samples, or no format, from one the browser cannot read', () => {
    expect(undecodableReason(wav(1, 16, 0))).toBe('it is a WAV file with no audio in it');
    const noFmt = new TextEncoder().encode('RIFF\x10\x00\x00\x00WAVEnot really audio').buffer;
    expect(undecodableReason(noFmt)).toBe('it is a damaged WAV file: it has no format (fmt) chunk');
  });

  it('says an AIFF wants converting', () => {
    expect(undecodableReason(new TextEncoder().encode('FORM\x00\x00\x10\x00AIFFCOMM').buffer)).toMatch(/^it is an AIFF file, .*convert it/);
    expect(undecodableReason(new TextEncoder().encode('FORM\x00\x00\x10\x00AIFCFVER').buffer)).toMatch(/AIFF/);
  });

  it('says an image, a document or a text is not audio', () => {
    expect(undecodableReason(bytes(0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a))).toBe('it is a PNG image, not audio');
    expect(undecodableReason(bytes(0xff, 0xd8, 0xff, 0xe0))).toBe('it is a JPEG image, not audio');
    expect(undecodableReason(bytes(0x25, 0x50, 0x44, 0x46))).toBe('it is a PDF document, not audio');
    expect(undecodableReason(new TextEncoder().encode('Lines of notes,\nnot a recording. Ünïcödé\t😀'.repeat(200)).buffer)).toBe('it is a text file, not audio');
    expect(undecodableReason(new TextEncoder().encode('<!DOCTYPE html>\n<html><body>app</body></html>').buffer)).toBe('it is an HTML page, not audio (a wrong URL, which the site answered with a page?)');
    // With a UTF-8 byte-order mark before it, as some editors and hosts write.
    expect(undecodableReason(new TextEncoder().encode('\ufeff<!doctype html><html></html>').buffer)).toBe('it is an HTML page, not audio (a wrong URL, which the site answered with a page?)');
  });

  it('says nothing where the first bytes do not tell (the browser\'s reason is then given)', () => {
    expect(undecodableReason(new ArrayBuffer(64))).toBeNull();
    expect(undecodableReason(bytes(0x49, 0x44, 0x33, 0x04))).toBeNull(); // an MP3's ID3 tag: audio, damaged further on
    expect(undecodableReason(new ArrayBuffer(0))).toBeNull();
  });
});

describe('statedSecondsIfCut', () => {
  /** 16-bit mono PCM at 8 kHz (16,000 bytes a second) holding `present` bytes of data, its header stating `stated`. */
  const pcm = (present: number, stated: number) => {
    const b = wav(1, 16, present);
    const v = new DataView(b);
    v.setUint32(28, 16000, true); // byte rate
    v.setUint32(40, stated, true); // the data chunk's size
    return b;
  };

  it('says how long a WAV cut short claims to be', () => {
    expect(statedSecondsIfCut(pcm(8000, 32000))).toBe(2);
  });

  it('says nothing of a whole WAV, an open size, or another format', () => {
    expect(statedSecondsIfCut(pcm(8000, 8000))).toBeNull();
    expect(statedSecondsIfCut(pcm(8000, 0))).toBeNull(); // a recorder streaming: size not yet written
    expect(statedSecondsIfCut(pcm(8000, 0xffffffff))).toBeNull();
    expect(statedSecondsIfCut(pcm(8000, 0x7ffff000))).toBeNull(); // sox writing to a pipe (it cannot seek back)
    expect(statedSecondsIfCut(bytes(0x49, 0x44, 0x33, 0x04))).toBeNull();
    expect(statedSecondsIfCut(new ArrayBuffer(4))).toBeNull();
  });
});
