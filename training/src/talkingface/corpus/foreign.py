"""festival's other-language voices speaking English: more voices of the kind the speech front-end hears worst.

The front-end recognises phones worst in the older synthesisers' voices it never heard (issue 14: on the test
split, flite's awb 55% of frames, festival's ked 64%, against 72% on recorded speech), and the English voices of
those synthesisers that the registries hold are in training already. Debian also packages festival voices for
other languages, diphone voices recorded by other speakers (Italian, Czech, Finnish: three men and three women).
They can say English the way Kokoro's accented voices do: the sentence's English phones and durations come from
festival's own English front end (the kal voice's segments), each phone is said with the nearest phone of the
voice's language (PHONE_MAPS; diphthongs as two), with a simple intonation (a declining line with accents on some
vowels, at the voice's pitch), and the label of every frame is the English phone it stands for. /p b m/ and the
other labials exist in every language here, so the phones that close the lips are said as they are; the sounds a
language lacks (the dental fricatives, /h/ in Italian) are said as its speakers would, as an accent.

Times are festival's own (utt.save.segs of the segments it was given), so labels are exact like the English
festival voices'. A diphone the voice lacks is replaced by silence (festival prints "using default diphone"):
a clip where that touches a bilabial, or happens more than MAX_MISSING times, is refused (SpeechToolError), and
the speech set records it as skipped.

  scripts/py -m talkingface.corpus setup --foreign-voices      # the Debian packages (FOREIGN_PACKAGES)
"""
from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..phones import BILABIALS, SILENCE
from ..wav import read_wav, resample
from .speech import SpeechToolError, Voice, _run, require_tools, synthesize

FOREIGN_PACKAGES = ("festvox-italp16k", "festvox-itapc16k", "festvox-czech-dita", "festvox-czech-machac",
                    "festvox-suopuhe-lj", "festvox-suopuhe-mv")
MAX_MISSING = 2  # diphones replaced by silence that a clip may have (none touching /p b m/)

# English (ARPAbet) -> the voice language's phones. Vowels take the nearest quality; diphthongs are two phones.
_IT = {"AA": "a", "AE": "E", "AH": "a", "AO": "O", "AW": "a u", "AY": "a i", "B": "b", "CH": "tS", "D": "d",
       "DH": "d", "EH": "E", "ER": "E r", "EY": "e i", "F": "f", "G": "g", "HH": "", "IH": "i", "IY": "i",
       "JH": "dZ", "K": "k", "L": "l", "M": "m", "N": "n", "NG": "ng", "OW": "o u", "OY": "O i", "P": "p",
       "R": "r", "S": "s", "SH": "S", "T": "t", "TH": "t", "UH": "u", "UW": "u", "V": "v", "W": "w", "Y": "j",
       "Z": "z", "ZH": "Z"}
_CS = {"AA": "a:", "AE": "e", "AH": "a", "AO": "o:", "AW": "a u", "AY": "a j", "B": "b", "CH": "c~", "D": "d",
       "DH": "d", "EH": "e", "ER": "e r", "EY": "e j", "F": "f", "G": "g", "HH": "h", "IH": "i", "IY": "i:",
       "JH": "dz~", "K": "k", "L": "l", "M": "m", "N": "n", "NG": "n", "OW": "o u", "OY": "o j", "P": "p",
       "R": "r", "S": "s", "SH": "s~", "T": "t", "TH": "t", "UH": "u", "UW": "u:", "V": "v", "W": "u", "Y": "j",
       "Z": "z", "ZH": "z~"}
_FI = {"AA": "a:", "AE": "@", "AH": "a", "AO": "o:", "AW": "a u", "AY": "a i", "B": "b", "CH": "t s", "D": "d",
       "DH": "d", "EH": "e", "ER": "7 r", "EY": "e i", "F": "f", "G": "g", "HH": "h", "IH": "i", "IY": "i:",
       "JH": "d j", "K": "k", "L": "l", "M": "m", "N": "n", "NG": "N", "OW": "o u", "OY": "o i", "P": "p",
       "R": "r", "S": "s", "SH": "s", "T": "t", "TH": "T", "UH": "u", "UW": "u:", "V": "v", "W": "v", "Y": "j",
       "Z": "s", "ZH": "s"}
PHONE_MAPS = {"it": _IT, "cs": _CS, "fi": _FI}
# Czech obstruents in voiced / voiceless pairs: Czech speakers voice or devoice a cluster to its last obstruent and
# devoice before a pause, and the Czech voices hold only the diphones that follow that rule.
_CS_PAIRS = (("b", "p"), ("d", "t"), ("g", "k"), ("z", "s"), ("z~", "s~"), ("v", "f"), ("dz~", "c~"), ("d~", "t~"), ("h", "ch"))
_CS_VOICELESS = {v: u for v, u in _CS_PAIRS}
_CS_VOICED = {u: v for v, u in _CS_PAIRS if v not in ("v", "h")}  # f and ch voice only rarely


def assimilate(names: list[str], silence: str) -> list[str]:
    """Czech voicing assimilation on a phone sequence: regressive within obstruent clusters, devoiced before a pause."""
    out = list(names)
    for i in range(len(out) - 1, -1, -1):
        nxt = out[i + 1] if i + 1 < len(out) else silence
        if out[i] in _CS_VOICELESS and (nxt == silence or nxt in _CS_VOICED.keys()):
            out[i] = _CS_VOICELESS[out[i]]
        elif out[i] in _CS_VOICED and nxt in _CS_VOICELESS and nxt not in ("v", "h"):
            out[i] = _CS_VOICED[out[i]]
    return out


@dataclass(frozen=True)
class ForeignVoice:
    name: str        # festival's voice (voice_NAME)
    language: str    # a key of PHONE_MAPS
    silence: str     # the voice's pause phone
    f0: float        # typical pitch (Hz)


FOREIGN_VOICES = {v.name: v for v in (
    ForeignVoice("pc_diphone", "it", "#", 110.0), ForeignVoice("lp_diphone", "it", "#", 200.0),
    ForeignVoice("czech_machac", "cs", "#", 110.0), ForeignVoice("czech_dita", "cs", "#", 210.0),
    ForeignVoice("hy_fi_mv_diphone", "fi", "#", 105.0), ForeignVoice("suo_fi_lj_diphone", "fi", "#", 195.0))}


def available() -> list[str]:
    """The foreign voices installed here (festival's voice folders)."""
    root = Path("/usr/share/festival/voices")
    have = {p.name for p in root.glob("*/*")} if root.exists() else set()
    return [n for n in FOREIGN_VOICES if n in have]


VOWEL_STARTS = "aeiouyE@7O"  # the first letters of the vowels of PHONE_MAPS


def segments(phones: list[tuple[str, float, float]], voice: ForeignVoice, speed: float, rng: np.random.Generator,
             table: dict[str, str] | None = None, vowel_starts: str = VOWEL_STARTS
             ) -> tuple[list[tuple[str, float, list[tuple[float, float]]]], list[int]]:
    """English phones with times -> the voice's segments (name, duration s, F0 targets (time in segment, Hz)) and,
    per segment, the index of the English phone it says. An English phone the language lacks (an empty map) is
    said by its neighbour: its time goes to the next phone's first segment (or the previous one at the end).
    `table`: English phone -> the voice's phones (space-separated), PHONE_MAPS[voice.language] unless given;
    a segment whose name starts with one of `vowel_starts` is a vowel and carries the intonation."""
    table = PHONE_MAPS[voice.language] if table is None else table
    total = sum(b - a for _, a, b in phones) / speed
    base = voice.f0 * rng.uniform(0.85, 1.15)
    segs: list[list] = []
    owner: list[int] = []
    carry = 0.0
    t = 0.0
    for i, (p, a, b) in enumerate(phones):
        dur = (b - a) / speed + carry
        carry = 0.0
        names = [voice.silence] if p == SILENCE else table[p].split()
        if not names:
            carry = dur
            continue
        for k, n in enumerate(names):
            d = dur / len(names)
            targets = []
            if n[0] in vowel_starts:  # a vowel: the intonation's line at its middle, accented on some
                line = base * (1.15 - 0.3 * (t + d / 2) / max(total, 1e-6))
                targets = [(round(d / 2, 4), round(line * (1.18 if rng.random() < 0.35 else 1.0), 1))]
            segs.append([n, d, targets])
            owner.append(i)
            t += d
    if carry and segs:
        segs[-1][1] += carry
    if voice.language == "cs":
        for seg, n in zip(segs, assimilate([x[0] for x in segs], voice.silence)):
            seg[0] = n
    if segs and not segs[0][2]:
        segs[0][2] = [(0.0, round(base * 1.1, 1))]
    return [(n, d, tg) for n, d, tg in segs], owner


def _scheme(voice: ForeignVoice, segs, wav: Path, out_segs: Path) -> str:
    items = " ".join(f"({n} {d:.4f}" + "".join(f" ({a} {f})" for a, f in tg) + ")" for n, d, tg in segs)
    return (f"(voice_{voice.name})\n(set! u (utt.synth (Utterance Segments ({items}))))\n"
            f"(utt.save.wave u \"{wav}\" 'riff)\n(utt.save.segs u \"{out_segs}\")\n")


def synthesize_foreign(name: str, text: str, sample_rate: int, speed: float = 1.0, seed: int = 0
                       ) -> tuple[np.ndarray, list[tuple[str, float, float]]]:
    """`text` said in English by festival's foreign voice `name`: (audio at sample_rate, English phones with times)."""
    if name not in FOREIGN_VOICES:
        raise SpeechToolError(f"unknown foreign voice {name!r} (one of {', '.join(FOREIGN_VOICES)})")
    voice = FOREIGN_VOICES[name]
    if name not in available():
        raise SpeechToolError(f"festival voice {name} is not installed: `scripts/py -m talkingface.corpus setup --foreign-voices`")
    require_tools("festival")
    _, english = synthesize(Voice("festival", "kal"), text, sample_rate)  # the English phones and their durations
    segs, owner = segments(english, voice, speed, np.random.default_rng(seed))
    with tempfile.TemporaryDirectory(prefix="tts-x-") as tmp:
        wav, seg_file, scm = Path(tmp) / "out.wav", Path(tmp) / "out.segs", Path(tmp) / "say.scm"
        scm.write_text(_scheme(voice, segs, wav, seg_file))
        r = _run(["festival", "-b", str(scm)])
        missing = re.findall(r"using default diphone \S+ for (\S+)-(\S+)", r.stdout + r.stderr)
        if not wav.exists():
            raise SpeechToolError(f"festival wrote no audio for voice {name}: {(r.stderr or r.stdout).strip()[:300]}")
        said = [ln.split() for ln in seg_file.read_text().splitlines()]
        ends = [float(x[0]) for x in said if len(x) == 3 and x[0] != "#"]
        audio, sr = read_wav(wav)
    refuse_missing(name, missing, PHONE_MAPS[voice.language])
    if len(ends) != len(segs):
        raise SpeechToolError(f"festival said {len(ends)} segments of {len(segs)}")
    phones = english_spans(english, owner, ends)
    audio = resample(audio, sr, sample_rate)[: int(round(phones[-1][2] * sample_rate))]
    return audio, phones


def refuse_missing(name: str, missing: list[tuple[str, str]], table: dict[str, str]) -> None:
    """SpeechToolError if the diphones voice `name` lacked in a sentence touch a bilabial (as `table` says them) or
    are more than MAX_MISSING."""
    bil = {p for e in BILABIALS for p in table[e].split()}
    if len(missing) > MAX_MISSING or any(a in bil or b in bil for a, b in missing):
        raise SpeechToolError(f"voice {name} lacks diphones {missing[:4]} for this sentence")


def english_spans(english: list[tuple[str, float, float]], owner: list[int], ends: list[float]) -> list[tuple[str, float, float]]:
    """The English phones with the times they were said: segment j, ending at ends[j], says English phone owner[j],
    and an English phone ends where its last segment ends."""
    phones, start = [], 0.0
    for j, end in enumerate(ends):
        if j + 1 == len(ends) or owner[j + 1] != owner[j]:
            phones.append((english[owner[j]][0], start, end))
            start = end
    return phones
