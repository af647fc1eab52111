"""Log-Mel features, computed exactly as meyda's `melBands` does, so the browser sees what training saw.

meyda 5.6 (node_modules/meyda/dist/esm): symmetric Hann window; |FFT|^2 of the first
N/2 bins (no Nyquist bin); an HTK Mel filter bank (mel = 1125 ln(1 + f/700)) from
0 Hz to Nyquist with unnormalised triangles whose edges sit at
floor((N + 1) f / sr), the band edges computed in float32 as meyda stores them;
output ln(1 + energy). Frames are centred: feature frame k covers the samples
around t = k * hop / sr, zero-padded at the ends.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from . import constants


@dataclass(frozen=True)
class AudioConfig:
    sample_rate: int = constants.SAMPLE_RATE  # Hz
    frame_size: int = 512                     # samples per FFT frame (meyda bufferSize, a power of two): 32 ms
    hop: int = 160                            # samples between feature frames: 10 ms, 100 frames/s
    n_mels: int = 80                          # Mel bands (paper: F = 80)
    fps: int = constants.FPS                  # animation frames per second

    @property
    def feature_rate(self) -> float:
        return self.sample_rate / self.hop

    def to_dict(self) -> dict:
        return asdict(self)


def hann_symmetric(n: int) -> np.ndarray:
    """meyda's hanning(): 0.5 - 0.5 cos(2 pi i / (n - 1)), stored as float32."""
    i = np.arange(n, dtype=np.float64)
    return (0.5 - 0.5 * np.cos(2 * np.pi * i / (n - 1))).astype(np.float32)


def mel_filter_bank(n_mels: int, sample_rate: int, frame_size: int) -> np.ndarray:
    """(n_mels, frame_size // 2) float32, as meyda's createMelFilterBank (restricted to the bins melBands uses)."""
    f32 = np.float32
    upper = 1125.0 * np.log(1 + (sample_rate / 2) / 700.0)
    step = upper / (n_mels + 1)
    mel = (np.arange(n_mels + 2, dtype=np.float64) * step).astype(f32)             # Float32Array melValues
    hz = (700.0 * (np.exp(mel.astype(np.float64) / 1125.0) - 1)).astype(f32)      # Float32Array melValuesInFreq
    bins = np.floor((frame_size + 1) * hz.astype(np.float64) / sample_rate).astype(np.int64)
    bank = np.zeros((n_mels, frame_size // 2 + 1), dtype=np.float64)
    for j in range(n_mels):
        lo, mid, hi = bins[j], bins[j + 1], bins[j + 2]
        for i in range(lo, mid):
            bank[j, i] = (i - lo) / (mid - lo)
        for i in range(mid, hi):
            bank[j, i] = (hi - i) / (hi - mid)
    return bank[:, : frame_size // 2].astype(np.float32)


def frame_count(num_samples: int, cfg: AudioConfig) -> int:
    return num_samples // cfg.hop + 1


def log_mel(audio: np.ndarray, cfg: AudioConfig = AudioConfig()) -> np.ndarray:
    """(S,) mono float audio at cfg.sample_rate -> (K, n_mels) float32, K = S // hop + 1."""
    x = np.asarray(audio, dtype=np.float32)
    half = cfg.frame_size // 2
    padded = np.concatenate([np.zeros(half, np.float32), x, np.zeros(cfg.frame_size, np.float32)])
    k = frame_count(len(x), cfg)
    idx = np.arange(k)[:, None] * cfg.hop + np.arange(cfg.frame_size)[None, :]
    frames = padded[idx] * hann_symmetric(cfg.frame_size)[None, :]                 # (K, frame) float32
    spec = np.fft.rfft(frames.astype(np.float64), axis=1)[:, : half]
    amp = np.abs(spec).astype(np.float32)                                          # Float32Array ampSpectrum
    power = (amp.astype(np.float64) ** 2).astype(np.float32)
    energy = power.astype(np.float64) @ mel_filter_bank(cfg.n_mels, cfg.sample_rate, cfg.frame_size).T.astype(np.float64)
    return np.log(energy + 1.0).astype(np.float32)


def frame_to_mel_index(frames: np.ndarray, cfg: AudioConfig = AudioConfig()) -> np.ndarray:
    """Animation frame i shows t = i / fps; its Mel frame is round(t * feature_rate) (round half to even)."""
    return np.round(np.asarray(frames) / cfg.fps * cfg.feature_rate).astype(np.int64)


def warp_mel(mel: np.ndarray, factor: float) -> np.ndarray:
    """Stretch the Mel axis by `factor` (> 1: a shorter vocal tract, formants move up), edge values held."""
    n = mel.shape[1]
    src = np.clip(np.arange(n) / factor, 0, n - 1)
    lo = np.floor(src).astype(int)
    hi = np.minimum(lo + 1, n - 1)
    w = src - lo
    return mel[:, lo] * (1 - w) + mel[:, hi] * w
