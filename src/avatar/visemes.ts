/**
 * The 15 Oculus visemes from the content encoder's phone posteriors: each viseme's weight at a frame is the
 * probability mass of the phones it stands for (the table below; docs/avatar.md says why each phone goes where
 * it goes). The classes are named by manifest.content_phones (ARPAbet, SIL, and the blank).
 */
import { VISEME_NAMES, type VisemeName } from './names';

/**
 * ARPAbet (CMUdict's 39 phones plus SIL) -> Oculus viseme, after Meta's viseme reference: PP p b m, FF f v, TH
 * (th), DD t d, kk k g, CH ch j sh, SS s z, nn n l, RR r, aa (father), E (bed), I (tip), O (toe), U (book).
 * Choices where the reference is silent: AH and the other open vowels the corpus opens the jaw for
 * (talkingface.phones.OPEN_VOWELS) -> aa; the diphthongs by their first, more open part (AW, AY -> aa; EY -> E;
 * OY -> O); ER -> RR (its lips are /r/'s); W -> U and Y -> I (their lips are UW's and IY's); NG -> nn (a nasal,
 * as HeadAudio's table has it); ZH -> CH (with SH); HH -> E (no lip shape of its own; the rig gives it a half-open
 * mouth).
 */
export const PHONE_TO_VISEME: Record<string, VisemeName> = {
  SIL: 'viseme_sil',
  P: 'viseme_PP', B: 'viseme_PP', M: 'viseme_PP',
  F: 'viseme_FF', V: 'viseme_FF',
  TH: 'viseme_TH', DH: 'viseme_TH',
  T: 'viseme_DD', D: 'viseme_DD',
  K: 'viseme_kk', G: 'viseme_kk',
  CH: 'viseme_CH', JH: 'viseme_CH', SH: 'viseme_CH', ZH: 'viseme_CH',
  S: 'viseme_SS', Z: 'viseme_SS',
  N: 'viseme_nn', NG: 'viseme_nn', L: 'viseme_nn',
  R: 'viseme_RR', ER: 'viseme_RR',
  AA: 'viseme_aa', AE: 'viseme_aa', AH: 'viseme_aa', AW: 'viseme_aa', AY: 'viseme_aa',
  EH: 'viseme_E', EY: 'viseme_E', HH: 'viseme_E',
  IH: 'viseme_I', IY: 'viseme_I', Y: 'viseme_I',
  AO: 'viseme_O', OW: 'viseme_O', OY: 'viseme_O',
  UH: 'viseme_U', UW: 'viseme_U', W: 'viseme_U',
};

/** The content class that is no phone: the front-end is trained frame-wise, so it carries almost no mass. */
const BLANK = '<blank>';

export class VisemeMap {
  /** Per content class: its viseme's index in VISEME_NAMES, or -1 for the blank. */
  readonly classViseme: Int8Array;

  constructor(contentPhones: readonly string[]) {
    const unknown = contentPhones.filter((p) => p !== BLANK && !(p in PHONE_TO_VISEME));
    if (unknown.length) throw new Error(`no viseme for the content classes ${unknown.join(', ')} (src/avatar/visemes.ts)`);
    this.classViseme = Int8Array.from(contentPhones, (p) => (p === BLANK ? -1 : VISEME_NAMES.indexOf(PHONE_TO_VISEME[p])));
  }

  /**
   * Viseme weights (frames x 15, each row summing to 1) from per-frame posteriors (frames x classes): each
   * viseme takes its phones' mass; the blank's share is spread over the rest in proportion.
   */
  weights(posteriors: Float32Array, frames: number, out = new Float32Array(frames * VISEME_NAMES.length), outAt = 0): Float32Array {
    const classes = this.classViseme.length;
    const V = VISEME_NAMES.length;
    for (let f = 0; f < frames; f++) {
      const row = out.subarray(outAt + f * V, outAt + (f + 1) * V);
      row.fill(0);
      let total = 0;
      for (let c = 0; c < classes; c++) {
        const v = this.classViseme[c];
        if (v < 0) continue;
        const p = posteriors[f * classes + c];
        row[v] += p;
        total += p;
      }
      if (total > 0) for (let v = 0; v < V; v++) row[v] /= total;
      else row[0] = 1; // only the blank heard: silence
    }
    return out;
  }
}
