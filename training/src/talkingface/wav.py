"""Audio files and sample rates: the one WAV reader and writer of the toolkit, and its resampler.

Every stage that touches a waveform on disk comes through here: the corpus (recordings, synthesiser
output, its clips), the datasets, the speech set, the demo's sample clips.
"""
from __future__ import annotations

import subprocess
import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np

PCM, FLOAT, EXTENSIBLE = 1, 3, 0xFFFE  # WAVE format codes read_wav understands


class WavError(ValueError):
    """A WAV file is missing, is not a WAV file, or holds an encoding the reader does not know; the message says which."""


@dataclass(frozen=True)
class WavFormat:
    code: int          # PCM or FLOAT (EXTENSIBLE: its sub-format), or another the reader refuses
    channels: int
    sample_rate: int   # Hz
    bits: int          # per sample


def _chunks(path: Path) -> tuple[WavFormat, bytes]:
    """The fmt chunk and the data chunk's bytes of a RIFF/WAVE file."""
    if not path.exists():
        raise WavError(f"missing audio {path}")
    raw = path.read_bytes()
    if raw[:4] != b"RIFF" or raw[8:12] != b"WAVE":
        raise WavError(f"{path} is not a WAV file")
    pos, fmt, data = 12, None, None
    while pos + 8 <= len(raw):
        cid, size = raw[pos : pos + 4], int.from_bytes(raw[pos + 4 : pos + 8], "little")
        body = raw[pos + 8 : pos + 8 + size]
        if cid == b"fmt ":
            code = int.from_bytes(body[0:2], "little")
            if code == EXTENSIBLE and len(body) >= 26:  # its sub-format GUID begins with the code it stands for
                code = int.from_bytes(body[24:26], "little")
            fmt = WavFormat(code, int.from_bytes(body[2:4], "little"), int.from_bytes(body[4:8], "little"), int.from_bytes(body[14:16], "little"))
            if fmt.channels < 1 or fmt.sample_rate < 1:
                raise WavError(f"{path}: its fmt chunk is damaged ({fmt.channels} channels, {fmt.sample_rate} Hz)")
            if fmt.bits < 8 or fmt.bits % 8:  # (a compressed codec: ADPCM's 4 bits, GSM's 0)
                raise WavError(f"{path}: WAV encoding {fmt.code} with {fmt.bits} bits is not supported (use 16-bit PCM or float32)")
        elif cid == b"data":
            data = body
        pos += 8 + size + (size & 1)
    if fmt is None or data is None:
        raise WavError(f"{path}: WAV without fmt or data chunk")
    return fmt, data


def read_wav(path: Path) -> tuple[np.ndarray, int]:
    """16-bit PCM or 32-bit float WAV -> (mono float32 in [-1, 1], sample rate)."""
    fmt, data = _chunks(Path(path))
    if fmt.code == PCM and fmt.bits == 16:
        x = np.frombuffer(data[: len(data) // 2 * 2], "<i2").astype(np.float32) / 32768.0
    elif fmt.code == FLOAT and fmt.bits == 32:
        x = np.frombuffer(data[: len(data) // 4 * 4], "<f4").astype(np.float32)
    else:
        raise WavError(f"{path}: WAV encoding {fmt.code} with {fmt.bits} bits is not supported (use 16-bit PCM or float32)")
    if fmt.channels > 1:
        x = x[: len(x) // fmt.channels * fmt.channels].reshape(-1, fmt.channels).mean(1)
    return x, fmt.sample_rate


def wav_seconds(path: Path) -> float:
    """How long a WAV file plays, from its header and data size (whole sample frames)."""
    fmt, data = _chunks(Path(path))
    return len(data) // (fmt.channels * fmt.bits // 8) / fmt.sample_rate


def write_wav(path: Path, audio: np.ndarray, sr: int) -> None:
    """Mono float audio -> 16-bit PCM WAV (clipped to [-1, 1])."""
    pcm = (np.clip(audio, -1.0, 1.0) * 32767.0).round().astype("<i2")
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(sr)
        w.writeframes(pcm.tobytes())


def resample(audio: np.ndarray, sr_in: int, sr_out: int) -> np.ndarray:
    """Band-limited resampling by sox (its default very-high-quality rate converter); float32 either way."""
    if sr_in == sr_out:
        return audio.astype(np.float32)
    res = subprocess.run(
        ["sox", "-t", "f32", "-r", str(sr_in), "-c", "1", "-", "-t", "f32", "-r", str(sr_out), "-c", "1", "-", "rate", "-v"],
        input=audio.astype("<f4").tobytes(), capture_output=True, check=True)
    return np.frombuffer(res.stdout, "<f4").astype(np.float32)
