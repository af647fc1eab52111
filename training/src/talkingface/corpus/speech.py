"""Speech with phone timings from many voices.

- festival (kal, ked diphone voices; slt HTS): exact segment end times from utt.save.segs;
- flite (slt, rms, awb): exact phone end times from -psdur;
- espeak-ng (dozens of accents x voice variants): no timings of its own, so
  they come from forced alignment (align.py), like any recorded speech.

All audio comes back as mono float32 at the corpus rate, all phones as ARPAbet.
"""
from __future__ import annotations

import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..wav import read_wav, resample
from ..phones import SILENCE, normalise_phone

FESTIVAL_VOICES = {"kal": "voice_kal_diphone", "ked": "voice_ked_diphone", "slt": "voice_cmu_us_slt_arctic_hts"}
FLITE_VOICES = ("slt", "rms", "awb")  # kal/kal16 cut the final pause (platform.md)
# espeak-ng accents and voice variants whose speech pocketsphinx aligns at least 60% of the time
# (survey: 3 sentences x 7 accents x 24 variants; en-gb, en-029 and variants such as m3, m7, Andrea,
# Tweaky mostly fail the first alignment pass). The builder retries a failed clip with another voice.
ESPEAK_ACCENTS = ("en-us", "en-gb-x-rp", "en-gb-x-gbclan", "en-gb-x-gbcwmd", "en-gb-scotland")
ESPEAK_VARIANTS = ("f1", "f2", "f3", "f4", "f5", "m1", "m2", "m5", "m6", "klatt", "klatt2", "klatt3", "Henrique")

ESPEAK_PAD = 0.2  # seconds of silence added before and after espeak-ng speech

# asterisk-core-sounds-en holds the recordings' transcripts; setup installs without Recommends, so it is named here.
DEBIAN_PACKAGES = ("festival", "festvox-kallpc16k", "festvox-kdlpc16k", "festvox-us-slt-hts", "flite", "espeak-ng", "sox",
                   "asterisk-core-sounds-en-wav", "asterisk-core-sounds-en")


class SpeechToolError(RuntimeError):
    """A synthesiser is missing or failed; the message names the Debian package or the command."""


@dataclass(frozen=True)
class Voice:
    engine: str          # "festival", "flite", "espeak" or "human"
    name: str            # engine voice, e.g. "kal", "en-gb+m3"
    rate: float = 1.0    # speaking-rate factor (espeak words per minute scale)
    pitch: int = 50      # espeak pitch 0-99

    @property
    def id(self) -> str:
        return f"{self.engine}:{self.name}".replace(" ", "_")

    @property
    def timing(self) -> str:
        """Where the phone times come from: the synthesiser itself, or forced alignment."""
        return "synthesiser" if self.engine in ("festival", "flite") else "aligned"


def all_voices() -> list[Voice]:
    voices = [Voice("festival", n) for n in FESTIVAL_VOICES] + [Voice("flite", n) for n in FLITE_VOICES]
    for a in ESPEAK_ACCENTS:
        for v in ESPEAK_VARIANTS:
            voices.append(Voice("espeak", f"{a}+{v}"))
    return voices


def tool_versions() -> dict[str, str]:
    """The versions the corpus's speech and alignments depend on: the Debian packages (dpkg) and pocketsphinx."""
    from importlib.metadata import PackageNotFoundError, version
    out = {}
    for p in DEBIAN_PACKAGES:
        r = subprocess.run(["dpkg-query", "-W", "-f=${Version}", p], capture_output=True, text=True)
        out[p] = r.stdout.strip() if r.returncode == 0 and r.stdout.strip() else "not installed"
    for p in ("pocketsphinx", "numpy"):
        try:
            out[p] = version(p)
        except PackageNotFoundError:  # the reason is the answer: meta.json records it
            out[p] = "not installed"
    return out


def installed(package: str) -> bool:
    """Whether dpkg has the Debian package installed."""
    return subprocess.run(["dpkg", "-s", package], capture_output=True).returncode == 0


def festival_script(select: str, text: str, wav: Path, segs: Path | None = None, settings: str = "") -> str:
    """The Scheme that makes festival say `text` with the voice `select` chooses (a command such as voice_kal_diphone),
    after `settings` (Scheme lines), into the RIFF file `wav`, and its segments' end times into `segs` if given."""
    quoted = text.replace("\\", " ").replace('"', "")
    return (f'({select})\n{settings}(set! u (utt.synth (Utterance Text "{quoted}")))\n(utt.save.wave u "{wav}" \'riff)\n'
            + (f'(utt.save.segs u "{segs}")\n' if segs is not None else ""))


def require_tools(*tools: str) -> None:
    missing = [t for t in tools if shutil.which(t) is None]
    if missing:
        raise SpeechToolError(
            f"missing {', '.join(missing)}: install the Debian packages with "
            f"`apt-get install {' '.join(DEBIAN_PACKAGES)}` (scripts/py -m talkingface.corpus setup does it)")


def _run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    try:
        return subprocess.run(cmd, check=True, capture_output=True, text=True, timeout=120, **kw)
    except subprocess.CalledProcessError as e:
        raise SpeechToolError(f"{' '.join(cmd[:3])} failed: {e.stderr.strip()[:300]}") from e
    except subprocess.TimeoutExpired as e:
        raise SpeechToolError(f"{' '.join(cmd[:3])} timed out after 120 s") from e


def synthesize(voice: Voice, text: str, sample_rate: int) -> tuple[np.ndarray, list[tuple[str, float, float]] | None]:
    """Speak `text`; return (audio, phones) — phones is None for voices whose timings need alignment."""
    with tempfile.TemporaryDirectory(prefix="tts-") as tmp:
        wav = Path(tmp) / "out.wav"
        if voice.engine == "festival":
            require_tools("festival")
            scm = Path(tmp) / "say.scm"
            scm.write_text(festival_script(FESTIVAL_VOICES[voice.name], text, wav, Path(tmp) / "out.segs"))
            _run(["festival", "-b", str(scm)])
            phones = _read_festival_segs(Path(tmp) / "out.segs")
        elif voice.engine == "flite":
            require_tools("flite")
            out = _run(["flite", "-voice", voice.name, "-psdur", "-t", text, "-o", str(wav)]).stdout
            phones = _read_flite_psdur(out)
        elif voice.engine == "espeak":
            require_tools("espeak-ng")
            wpm = int(round(160 * voice.rate))
            _run(["espeak-ng", "-v", voice.name, "-s", str(wpm), "-p", str(voice.pitch), "-w", str(wav), text])
            audio, sr = read_wav(wav)
            # espeak-ng speaks from the first sample; a recording has silence around the speech.
            pad = np.zeros(int(ESPEAK_PAD * sr), dtype=np.float32)
            return resample(np.concatenate([pad, audio, pad]), sr, sample_rate), None
        else:
            raise SpeechToolError(f"voice engine {voice.engine!r} cannot synthesise")
        audio, sr = read_wav(wav)
    audio = resample(audio, sr, sample_rate)
    if phones is not None:
        phones = merge_silences(phones)
        # festival's diphone voices write 20-28 ms of silence past their final pause label; that tail
        # belongs to no label, so it goes (sox resampling keeps lengths exact, so labels stay put).
        end = int(round(phones[-1][2] * sample_rate))
        if len(audio) > end:
            audio = audio[:end]
    return audio, phones


def _read_festival_segs(path: Path) -> list[tuple[str, float, float]]:
    """festival's segs file: a '#' line, then 'END_TIME 100 PHONE' per segment."""
    phones, start = [], 0.0
    for line in path.read_text().splitlines():
        parts = line.split()
        if len(parts) != 3 or parts[0] == "#":
            continue
        end = float(parts[0])
        phones.append((normalise_phone(parts[2]), start, end))
        start = end
    return phones


def _read_flite_psdur(out: str) -> list[tuple[str, float, float]]:
    """flite -psdur prints 'phone:end phone:end ...'."""
    phones, start = [], 0.0
    for tok in out.split():
        if ":" not in tok:
            continue
        name, end = tok.rsplit(":", 1)
        phones.append((normalise_phone(name), start, float(end)))
        start = float(end)
    return phones


def merge_silences(phones):
    """Drop empty segments and merge neighbouring silences."""
    merged = []
    for p, a, b in phones:
        if b <= a:
            continue
        if merged and p == SILENCE and merged[-1][0] == SILENCE:
            merged[-1] = (SILENCE, merged[-1][1], b)
        else:
            merged.append((p, a, b))
    return merged


def fit_to_duration(phones, duration: float):
    """Make the labels cover the audio exactly: the last segment ends with it (a silence is added if needed)."""
    merged = merge_silences(phones)
    if merged:
        last = merged[-1]
        if duration > last[2] and last[0] == SILENCE:
            merged[-1] = (SILENCE, last[1], duration)
        elif duration > last[2]:
            merged.append((SILENCE, last[2], duration))
        elif duration < last[2]:
            merged[-1] = (last[0], last[1], max(duration, last[1] + 1e-3))
    return merged
