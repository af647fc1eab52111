"""MBROLA's voices of other languages speaking English: dozens more real speakers for the speech front-end.

What limits the front-end is how many voices it has heard (issue 14). Debian's non-free section holds MBROLA
voices for some thirty languages besides its four English ones (corpus/diphone_voices.py has those): about seventy,
each cut from one real speaker's recordings, men and women. They can say English as festival's foreign voices
do (corpus/foreign.py): the sentence's English phones and durations come from festival's English front end (the kal
voice's segments), each phone is said with the nearest phone the voice has, with a simple intonation at the voice's
pitch, and every frame is labelled with the English phone it stands for. MBROLA takes the phones, their durations
and pitch directly (a .pho file), so the labels' times are the ones given.

Which phones a voice has is not written down in one convention, so it is asked: every candidate symbol (SAMPA, in
CANDIDATES' order of preference for each English phone) is said between two vowels (consonants) or two consonants
(vowels), and MBROLA says which diphones it lacks. An English phone with no candidate the voice has is said as
its neighbour (foreign.segments). A voice that lacks /p/, /b/ or /m/, or a basic vowel, is not used. A diphone
missing in a sentence is replaced by silence (mbrola -e prints it): a clip where that touches a bilabial, or
happens more than foreign.MAX_MISSING times, is refused (SpeechToolError), and the speech set records it as skipped.

  scripts/py -m talkingface.corpus setup --mbrola-voices       # about 70 Debian packages, 600 MB

Their licence (/usr/share/doc/mbrola-*/copyright): speech synthesised with the MBROLA program only, and the
databases not sold nor put into a product that is sold; here they say training sentences, and nothing of them ships.
"""
from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..wav import read_wav, resample
from . import foreign, more_voices
from .speech import SpeechToolError, Voice, synthesize

ROOT = Path("/usr/share/mbrola")
SETUP = "scripts/py -m talkingface.corpus setup --mbrola-voices"
ENGLISH = ("en1", "us1", "us2", "us3")  # diphone_voices' (through festival)
FEMALE = frozenset("br2 br4 bz1 cn1 cz1 de1 de3 de5 de7 es3 fr2 fr4 hb2 in2 it2 it4 jp2 jp3 ma1 nl3 pl1 pt1 sw2 tl1 tr2".split())

# English (ARPAbet) -> SAMPA candidates, most English-like first; "a b" is two phones; "" drops the phone.
CANDIDATES = {
    "AA": ("A:", "A", "a:", "a"), "AE": ("{", "E", "e", "a"), "AH": ("V", "@", "6", "a"), "AO": ("O:", "O", "o:", "o"),
    "EH": ("E", "e"), "ER": ("3:", "@ r", "9 r", "e r", "@"), "IH": ("I", "i"), "IY": ("i:", "i"), "UH": ("U", "u"),
    "UW": ("u:", "u"), "AW": ("aU", "a U", "a u"), "AY": ("aI", "a I", "a i"), "EY": ("eI", "e I", "e i", "e"),
    "OW": ("@U", "oU", "o U", "o u", "o"), "OY": ("OI", "O I", "o i", "o j"),
    "P": ("p",), "B": ("b", "p"), "M": ("m",), "T": ("t",), "D": ("d", "t"), "K": ("k",), "G": ("g", "k"),
    "F": ("f",), "V": ("v", "f", "w"), "TH": ("T", "t", "s", "f"), "DH": ("D", "d", "z", "v"), "S": ("s",),
    "Z": ("z", "s"), "SH": ("S", "s"), "ZH": ("Z", "z", "S", "s"), "CH": ("tS", "t S", "ts", "t s"),
    "JH": ("dZ", "d Z", "dz", "d z"), "HH": ("h", "x", ""), "L": ("l",), "R": ("r\\", "r", "R", "4", "l"),
    "W": ("w", "u", "v"), "Y": ("j", "i"), "N": ("n",), "NG": ("N", "n g", "n"),
}
VOWELS = frozenset(k for k in CANDIDATES if k[0] in "AEIOU")
VOWEL_STARTS = "aeiouAEIOUV@{369"  # the first characters of the SAMPA vowels above (foreign.segments' intonation)
NEEDED = ("P", "B", "M", "AA", "IY", "UW")  # a voice without one of these own phones is not used


# The voices whose phones are SAMPA with /p b m/ and the basic vowels (usable(), asked of every voice Debian holds; a
# test checks it against the installed voices): the plan of a speech set must not depend on what a probe finds.
USABLE = tuple("""af1 br1 br2 br3 br4 bz1 ca1 ca2 cr1 cz1 cz2 de1 de2 de3 de4 de5 de6 de7 ee1 es1 es2 es3 es4 fr1 fr2 fr3 fr4
    fr5 fr6 fr7 gr1 gr2 hb1 hb2 hu1 it3 it4 la1 lt1 lt2 mx1 mx2 nl2 nl3 pl1 pt1 ro1 sw1 sw2 tl1""".split())


def database(name: str) -> Path:
    return ROOT / name / name


def available() -> list[str]:
    """The installed USABLE voices, as "mbrola:NAME"."""
    if shutil.which("mbrola") is None:
        return []
    return [f"mbrola:{name}" for name in USABLE if database(name).exists()]


def packages() -> tuple[str, ...]:
    """The Debian packages of every non-English MBROLA voice the archive holds (apt-cache), with mbrola itself."""
    r = subprocess.run(["apt-cache", "search", "--names-only", "^mbrola-[a-z][a-z][0-9]$"], capture_output=True, text=True)
    names = [ln.split()[0] for ln in r.stdout.splitlines() if ln.strip()]
    return ("mbrola", *(n for n in names if n.removeprefix("mbrola-") not in ENGLISH))


def setup() -> None:
    """Install packages() (Debian's non-free section, which more_voices.setup adds)."""
    more_voices.setup(packages())


def _say(name: str, pho: str, wav: Path | None = None) -> str:
    """MBROLA's warnings for .pho text said by voice `name` (into `wav` if given; else thrown away)."""
    with tempfile.TemporaryDirectory(prefix="mbrola-") as tmp:
        src = Path(tmp) / "in.pho"
        src.write_text(pho)
        out = wav or Path(tmp) / "out.wav"
        try:
            r = subprocess.run(["mbrola", "-e", str(database(name)), str(src), str(out)], capture_output=True, text=True, timeout=60)
        except subprocess.TimeoutExpired as e:
            raise SpeechToolError(f"mbrola {name} timed out") from e
        if r.returncode != 0:
            raise SpeechToolError(f"mbrola {name} failed ({r.returncode}): {r.stderr.strip()[-300:]}")
        return r.stderr


MISSING = re.compile(r"Warning: (\S+)-(\S+) unknown")


@lru_cache(maxsize=None)
def phone_table(name: str) -> dict[str, str]:
    """English phone -> the phones voice `name` says it with ("" for none), by asking MBROLA (see the docstring)."""
    def has(symbols: str, vowel: bool) -> bool:
        ctx = ("t", "t") if vowel else (vowel_a, vowel_a)
        body = "".join(f"{s} 90\n" for s in symbols.split())
        return not MISSING.search(_say(name, f"_ 50\n{ctx[0]} 80 50 120\n{body}{ctx[1]} 80\n_ 50\n"))
    vowel_a = next((a for a in ("a", "a:", "A", "A:") if not MISSING.search(_say(name, f"_ 50\nt 80\n{a} 100 50 120\nt 80\n_ 50\n"))), None)
    if vowel_a is None:
        return {}
    table = {}
    for phone, cands in CANDIDATES.items():
        table[phone] = next((c for c in cands if c == "" or has(c, phone in VOWELS)), "")
    return table


def usable(name: str) -> bool:
    table = phone_table(name)
    return bool(table) and all(table.get(p) for p in NEEDED) and table["P"] == "p" and table["B"] == "b" and table["M"] == "m"


BREAK_MS = 20  # the break put between two phones whose diphone the voice lacks


def _pho(segs: list[tuple[str, int, list[tuple[float, float]]]]) -> str:
    """MBROLA's input: one line per segment, its name, its milliseconds and its pitch targets (% of it, Hz)."""
    return "".join(f"{n} {ms}" + "".join(f" {min(100.0, 100000 * a / ms):.0f} {f:.0f}" for a, f in tg) + "\n" for n, ms, tg in segs)


def _break_pairs(segs, owner: list[int], pairs: set[tuple[str, str]]):
    """A BREAK_MS pause ("_") between consecutive segments named as a pair in `pairs`, its time taken from the longer of
    the two (so every English phone keeps its span: the pause belongs to the first phone)."""
    out, own = [list(segs[0])], [owner[0]]
    for (n, ms, tg), o in zip(segs[1:], owner[1:]):
        prev = out[-1]
        if (prev[0], n) in pairs and "_" not in (prev[0], n) and max(prev[1], ms) > BREAK_MS + 20:
            if prev[1] >= ms:
                prev[1] -= BREAK_MS
            else:
                ms -= BREAK_MS
            out.append(["_", BREAK_MS, []])
            own.append(own[-1])
        out.append([n, ms, tg])
        own.append(o)
    return [tuple(x) for x in out], own


def synthesize_mbrola(name: str, text: str, sample_rate: int, speed: float = 1.0, seed: int = 0
                      ) -> tuple[np.ndarray, list[tuple[str, float, float]]]:
    """`text` said in English by MBROLA voice "mbrola:NAME": (audio at sample_rate, English phones with times)."""
    engine, _, voice = name.partition(":")
    if engine != "mbrola" or not database(voice).exists():
        raise SpeechToolError(f"MBROLA voice {name!r} is not installed: run `{SETUP}`")
    if not usable(voice):
        raise SpeechToolError(f"MBROLA voice {voice} lacks /p b m/ or a basic vowel as SAMPA phones: not used")
    _, english = synthesize(Voice("festival", "kal"), text, sample_rate)  # the English phones and their durations
    rng = np.random.default_rng(seed)
    spec = foreign.ForeignVoice(voice, "mbrola", "_", 200.0 if voice in FEMALE else 110.0)
    segs, owner = foreign.segments(english, spec, speed, rng, phone_table(voice), VOWEL_STARTS)
    segs = [(n, max(int(round(1000 * d)), 10), tg) for n, d, tg in segs]   # whole milliseconds, as MBROLA reads them
    with tempfile.TemporaryDirectory(prefix="mbrola-x-") as tmp:
        wav = Path(tmp) / "out.wav"
        missing = MISSING.findall(_say(voice, _pho(segs), wav))
        if missing:  # a pair the voice never recorded (a cluster its language lacks): a short break between the two
            segs, owner = _break_pairs(segs, owner, set(missing))
            missing = MISSING.findall(_say(voice, _pho(segs), wav))
        audio, sr = read_wav(wav)
    foreign.refuse_missing(voice, missing, phone_table(voice))
    phones = foreign.english_spans(english, owner, (np.cumsum([ms for _, ms, _ in segs]) / 1000.0).tolist())
    audio = resample(audio, sr, sample_rate)[: int(round(phones[-1][2] * sample_rate))]
    return audio.astype(np.float32), phones
