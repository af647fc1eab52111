/** The demo's names for takes in messages and for the files it saves (src/app/names.ts). */
import { describe, expect, it } from 'vitest';
import { fileBaseName, isolated } from '../../../src/app/names';

describe('isolated', () => {
  it('sets apart a name with right-to-left letters, and leaves others as they are', () => {
    expect(isolated('تسجيل صوتي ١.wav')).toBe('\u2068تسجيل صوتي ١.wav\u2069');
    expect(isolated('שלום.wav')).toBe('\u2068שלום.wav\u2069');
    expect(isolated('Grüße – 日本語.wav')).toBe('Grüße – 日本語.wav');
  });

  it('cuts a name longer than 60 characters in the middle, keeping its end, by characters (not UTF-16 units)', () => {
    const long = `${'a'.repeat(100)}_the_end.wav`;
    expect(isolated(long)).toBe(`${'a'.repeat(30)}…${'a'.repeat(17)}_the_end.wav`);
    expect([...isolated(long)]).toHaveLength(60);
    expect(isolated('x'.repeat(60))).toBe('x'.repeat(60));
    const emoji = '🎤'.repeat(70);
    expect([...isolated(emoji)]).toHaveLength(60);
    expect([...isolated(emoji)].every((c) => c === '🎤' || c === '…'), 'no character cut in half').toBe(true);
  });
});

describe('fileBaseName', () => {
  it('drops the extension, puts "_" for what file systems refuse, and says "take" when nothing is left', () => {
    expect(fileBaseName('speech.wav')).toBe('speech');
    expect(fileBaseName('take: v2*final?.wav')).toBe('take_ v2_final_');
    expect(fileBaseName('a/b\\c<d>"e|f.mp3')).toBe('a_b_c_d__e_f');
    expect(fileBaseName('.wav')).toBe('take');
    expect(fileBaseName('Grüße 日本語.wav')).toBe('Grüße 日本語');
  });

  it('keeps at most 200 bytes of UTF-8, cut between characters', () => {
    const long = '日本語'.repeat(100) + '.wav'; // 900 bytes
    const base = fileBaseName(long);
    expect(new TextEncoder().encode(base).length).toBeLessThanOrEqual(200);
    expect(base).toBe('日本語'.repeat(22)); // 198 bytes: one more character would pass 200
    expect(fileBaseName('a'.repeat(300))).toHaveLength(200);
  });
});
