"""Real recorded human speech: Debian's asterisk-core-sounds-en-wav (CC-BY-SA-3.0).

One female speaker (Allison), 568 prompts, 8 kHz mono, with exact transcripts in
/usr/share/doc/asterisk-core-sounds-en/core-sounds-en.txt.gz ("name: text" per
line). Phone timings come from forced alignment (align.py).
"""
from __future__ import annotations

import gzip
from dataclasses import dataclass
from pathlib import Path

from ..wav import wav_seconds

SOUNDS_DIR = Path("/usr/share/asterisk/sounds/en_US_f_Allison")
TRANSCRIPTS = Path("/usr/share/doc/asterisk-core-sounds-en/core-sounds-en.txt.gz")
# The WAV files and the transcripts are two Debian packages (the second is only a Recommends of the first).
PACKAGES = ("asterisk-core-sounds-en-wav", "asterisk-core-sounds-en")
MISSING_HINT = (f"{SOUNDS_DIR} and {TRANSCRIPTS} come from the Debian packages {' and '.join(PACKAGES)}: "
                "install them with `scripts/py -m talkingface.corpus setup`")
LICENSE = "CC-BY-SA-3.0 (Debian package asterisk-core-sounds-en-wav, voice: Allison Smith)"


@dataclass(frozen=True)
class Recording:
    name: str
    text: str
    path: Path
    duration: float


def available() -> bool:
    return SOUNDS_DIR.is_dir() and TRANSCRIPTS.exists()


def recordings(min_words: int = 3, min_seconds: float = 1.0, max_seconds: float = 12.0) -> list[Recording]:
    """Prompts that are speech (not tones, silence or single letters), sorted by name."""
    out = []
    with gzip.open(TRANSCRIPTS, "rt", errors="replace") as f:
        for line in f:
            if not line.strip() or line.startswith(";"):
                continue
            name, sep, text = line.rstrip("\n").partition(":")
            name, text = name.strip(), text.strip()
            if not sep or "[" in text or name.startswith("silence/") or len(text.split()) < min_words:
                continue
            path = SOUNDS_DIR / f"{name}.wav"
            if not path.exists():
                continue
            duration = wav_seconds(path)
            if min_seconds <= duration <= max_seconds:
                out.append(Recording(name, text, path, duration))
    return sorted(out, key=lambda r: r.name)
