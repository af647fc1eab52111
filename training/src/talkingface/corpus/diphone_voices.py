"""English diphone voices of festival and MBROLA, for the speech front-end's training speech (issue 14).

The front-end hears worst the test split's voices of older synthesisers (festival's ked, a diphone voice; flite's
awb), and no voice of MBROLA, a diphone family of its own, was in its training. Debian holds six more English diphone
voices, each cut from one real speaker's recordings, all offline:

- festival's rab (British English male, RP) and don (a minimal British English male), Debian main;
- MBROLA's us1 (US female), us2 and us3 (US males) and en1 (British male), spoken through festival (festvox-us1 ...),
  Debian non-free (their licence, /usr/share/doc/mbrola-us1/copyright: speech synthesised with the MBROLA program
  only, and the database not sold nor put into a product that is sold; here they say training sentences, and
  nothing of them ships).

Not ked, kal and the others the corpus speaks with already (corpus/speech.py). festival's British voices use another
phone set, so the speech set force-aligns all six, as it does Kokoro's; `speed` stretches festival's durations.

  scripts/py -m talkingface.corpus setup --diphone-voices
"""
from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from ..wav import read_wav, resample
from . import more_voices
from .speech import SpeechToolError, festival_script, installed

# voice -> (festival's command that selects it, the Debian package that holds it)
VOICES = {"rab": ("voice_rab_diphone", "festvox-rablpc16k"), "don": ("voice_don_diphone", "festvox-don"),
          "us1": ("voice_us1_mbrola", "festvox-us1"), "us2": ("voice_us2_mbrola", "festvox-us2"),
          "us3": ("voice_us3_mbrola", "festvox-us3"), "en1": ("voice_en1_mbrola", "festvox-en1")}
PACKAGES = ("festival", "mbrola", *(pkg for _, pkg in VOICES.values()))
SETUP = "scripts/py -m talkingface.corpus setup --diphone-voices"


def available() -> list[str]:
    """The voices whose packages are installed, as "festival:voice"."""
    if shutil.which("festival") is None:
        return []
    return [f"festival:{v}" for v, (_, pkg) in VOICES.items() if installed(pkg)]


def setup() -> None:
    """Install PACKAGES (MBROLA's voices are in Debian's non-free section, which more_voices.setup adds)."""
    more_voices.setup(PACKAGES)


def synthesize(name: str, text: str, sample_rate: int, speed: float = 1.0) -> np.ndarray:
    """Speech of `text` in voice "festival:voice" (one of VOICES) at `speed`, mono float32 at sample_rate."""
    engine, _, voice = name.partition(":")
    if engine != "festival" or voice not in VOICES:
        raise ValueError(f"unknown voice {name!r}: one of {', '.join(f'festival:{v}' for v in VOICES)}")
    if shutil.which("festival") is None or not installed(VOICES[voice][1]):
        raise SpeechToolError(f"{VOICES[voice][1]} is missing: run `{SETUP}`")
    if not 0.5 <= speed <= 2.0:
        raise ValueError(f"speed {speed} is outside 0.5-2")
    with tempfile.TemporaryDirectory(prefix="diphone-") as tmp:
        wav, scm = Path(tmp) / "out.wav", Path(tmp) / "say.scm"
        scm.write_text(festival_script(VOICES[voice][0], text, wav, settings=f"(Parameter.set 'Duration_Stretch {1.0 / speed:.4f})\n"))
        r = subprocess.run(["festival", "-b", str(scm)], capture_output=True, text=True, timeout=120)
        if r.returncode != 0 or not wav.exists() or wav.stat().st_size < 1000:
            raise SpeechToolError(f"festival ({VOICES[voice][0]}) failed ({r.returncode}): {r.stderr.strip()[-300:]}")
        audio, rate = read_wav(wav)
    return resample(audio, rate, sample_rate).astype(np.float32)
