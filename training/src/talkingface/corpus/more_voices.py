"""English voices of two more synthesiser families, for the speech front-end's training speech (issue 14).

The front-end hears worst the voices of synthesiser families it has heard little of (the test split's diphone and
clustergen voices), and its limit is how many voices it has heard. Debian packages two more families in its
contrib and non-free sections, both offline and permissively licensed:

- RHVoice (HTS statistical parametric voices, LGPL-2.1+): bdl (US male), clb and slt (US female). Not alan: he
  speaks Scottish English, the accent the mesh corpus's test split holds out (corpus/plan.py, is_test_voice); not
  evgeniy-eng and lyubov, whose licence (CC-BY-NC-ND) does not allow it.
- SVOX Pico (Apache-2.0): its US and UK English voices (both female).

Neither gives timings: the speech set force-aligns their speech, as it does Kokoro's. `setup()` adds the two
sections to apt's sources (a file of its own, SOURCES) and installs PACKAGES.

  scripts/py -m talkingface.corpus setup --more-voices
"""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from ..wav import read_wav, resample
from .speech import SpeechToolError, installed

PACKAGES = ("rhvoice", "rhvoice-english", "libttspico-utils")
SOURCES = Path("/etc/apt/sources.list.d/talking-face-contrib-non-free.sources")
SOURCES_TEXT = """Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: contrib non-free
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
"""
# (engine, voice): the engine's command line names the voice.
VOICES = (("rhvoice", "bdl"), ("rhvoice", "clb"), ("rhvoice", "slt"), ("pico", "en-US"), ("pico", "en-GB"))
TOOLS = {"rhvoice": "RHVoice-test", "pico": "pico2wave"}


def available() -> list[str]:
    """The voices whose tools are installed, as "engine:voice"."""
    return [f"{e}:{v}" for e, v in VOICES if shutil.which(TOOLS[e])]


def setup(packages: tuple[str, ...] = PACKAGES) -> None:
    """Add Debian's contrib and non-free sections (if apt has not got them) and install `packages`."""
    missing = [p for p in packages if not installed(p)]
    if not missing:
        return
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    if not SOURCES.exists():
        subprocess.run(sudo + ["tee", str(SOURCES)], input=SOURCES_TEXT, text=True, check=True, stdout=subprocess.DEVNULL)
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    subprocess.run(sudo + ["apt-get", "update", "-qq"], check=True, env=env)
    subprocess.run(sudo + ["apt-get", "install", "-y", "-qq", "--no-install-recommends", *missing], check=True, env=env)


def synthesize(name: str, text: str, sample_rate: int) -> np.ndarray:
    """Speech of `text` in voice "engine:voice" (one of VOICES), mono float32 at sample_rate."""
    engine, _, voice = name.partition(":")
    if (engine, voice) not in VOICES:
        raise ValueError(f"unknown voice {name!r}: one of {', '.join(f'{e}:{v}' for e, v in VOICES)}")
    if shutil.which(TOOLS[engine]) is None:
        raise SpeechToolError(f"{TOOLS[engine]} is missing: run `scripts/py -m talkingface.corpus setup --more-voices`")
    with tempfile.TemporaryDirectory(prefix="more-voices-") as tmp:
        wav = Path(tmp) / "out.wav"
        if engine == "rhvoice":
            cmd, stdin = ["RHVoice-test", "-p", voice, "-o", str(wav)], text
        else:  # pico2wave wants the file name to end in .wav and the text as an argument
            cmd, stdin = ["pico2wave", "-l", voice, "-w", str(wav), text], None
        r = subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=120)
        if r.returncode != 0 or not wav.exists() or wav.stat().st_size < 1000:
            raise SpeechToolError(f"{TOOLS[engine]} -p/-l {voice} failed ({r.returncode}): {r.stderr.strip()[-300:]}")
        audio, rate = read_wav(wav)
    return resample(audio, rate, sample_rate).astype(np.float32)
