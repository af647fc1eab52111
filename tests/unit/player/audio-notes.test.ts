/** The notes a person reads about a clip's audio (src/player/audio-notes.ts). */
import { describe, expect, it } from 'vitest';
import { audioNotes, LONG_CLIP_SECONDS, SHORT_CLIP_SECONDS } from '../../../src/player/audio-notes';
import { raiseIfQuiet } from '../../../src/audio/decode';

describe('audioNotes', () => {
  it('says silent, clipped and long, and nothing for ordinary speech', () => {
    const speech = Float32Array.from({ length: 16000 }, (_, i) => 0.3 * Math.sin(i / 7));
    expect(audioNotes(speech, 1)).toEqual([]);
    expect(audioNotes(new Float32Array(16000), 1).join()).toMatch(/silent/);
    const clipped = Float32Array.from(speech, (v) => Math.max(-1, Math.min(1, v * 10)));
    expect(audioNotes(clipped, 1).join()).toMatch(/clipped/);
    // A long clip's note is for while it is animated (it says Cancel stops it), not for the take once shown.
    expect(audioNotes(speech, LONG_CLIP_SECONDS + 1, { animating: true }).join()).toMatch(/long clip/);
    expect(audioNotes(speech, LONG_CLIP_SECONDS + 1)).toEqual([]);
    // A file cut short: how much of it there is, against what its header states.
    expect(audioNotes(speech, 1, { statedSeconds: 4 })).toEqual(['the file ends early: it holds 1.0 s of the 4.0 s its header states (cut short while copying or recording?)']);
    expect(audioNotes(speech, 1, { statedSeconds: null })).toEqual([]);
  });

  it('raises a quiet clip for the model and says by how much; leaves silence and ordinary levels alone', () => {
    const at = (peak: number) => Float32Array.from({ length: 16000 }, (_, i) => peak * Math.sin(i / 7));
    const quiet = raiseIfQuiet(at(0.01)); // -40 dBFS
    expect(quiet.gainDb).toBeCloseTo(20 * Math.log10(50), 2);
    expect(Math.max(...quiet.samples)).toBeCloseTo(0.5, 3);
    expect(audioNotes(at(0.01), 1, { raisedDb: quiet.gainDb })).toEqual(['very quiet (peak -40 dBFS): raised by 34 dB to animate it']);
    expect(audioNotes(at(0.01), 1, { raisedDb: quiet.gainDb, speech: false })[0]).toMatch(/^no speech was found/);
    for (const peak of [0, 5e-4, 0.05, 0.9]) {
      const r = raiseIfQuiet(at(peak));
      expect([r.gainDb, r.samples[3]], `peak ${peak}`).toEqual([0, at(peak)[3]]);
    }
  });

  it('says when no speech was found (not for a silent clip, already said) and when a clip is very short', () => {
    const sound = Float32Array.from({ length: 16000 }, (_, i) => 0.3 * Math.sin(i / 7));
    expect(audioNotes(sound, 1, { speech: false })).toEqual(['no speech was found in it (noise, music or a tone?), so the mouth stays at rest']);
    expect(audioNotes(new Float32Array(16000), 1, { speech: false }).join()).not.toMatch(/no speech/);
    expect(audioNotes(sound.subarray(0, 3200), 0.2).join()).toMatch(/very short clip \(0\.20 s\)/);
    expect(audioNotes(sound, SHORT_CLIP_SECONDS)).toEqual([]);
  });
});
