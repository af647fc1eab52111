"""Per-frame prosody of a waveform: loudness and pitch, which drive head pose and brows."""
from __future__ import annotations

import numpy as np


def frame_energy(audio: np.ndarray, sr: int, n_frames: int, fps: float, win: float = 0.04) -> np.ndarray:
    """RMS level in dB around each frame time (frame i at t = i / fps)."""
    half = int(win * sr / 2)
    out = np.empty(n_frames)
    for i in range(n_frames):
        c = int(round(i * sr / fps))
        seg = audio[max(0, c - half) : c + half]
        out[i] = 10 * np.log10(np.mean(seg.astype(np.float64) ** 2) + 1e-10) if len(seg) else -100.0
    return out


def frame_pitch(audio: np.ndarray, sr: int, n_frames: int, fps: float, fmin: float = 70.0, fmax: float = 400.0,
                win: float = 0.04, threshold: float = 0.15) -> np.ndarray:
    """F0 in Hz per frame by the YIN difference function (de Cheveigné & Kawahara 2002); 0 where unvoiced."""
    n = int(win * sr)
    tau_min, tau_max = int(sr / fmax), min(int(sr / fmin), n - 1)
    out = np.zeros(n_frames)
    x = audio.astype(np.float64)
    for i in range(n_frames):
        c = int(round(i * sr / fps))
        seg = x[max(0, c - n // 2) : max(0, c - n // 2) + n + tau_max]
        if len(seg) < n + tau_max or np.sqrt(np.mean(seg ** 2)) < 1e-3:
            continue
        d = np.array([np.sum((seg[:n] - seg[tau : tau + n]) ** 2) for tau in range(tau_max + 1)])
        cmnd = d[1:] * np.arange(1, tau_max + 1) / np.maximum(np.cumsum(d[1:]), 1e-12)
        cands = np.flatnonzero(cmnd[tau_min - 1 :] < threshold)
        if len(cands):
            tau = cands[0] + tau_min
            while tau < tau_max and cmnd[tau] < cmnd[tau - 1]:  # walk down to the local minimum
                tau += 1
            out[i] = sr / tau
    return out


def zscore_voiced(values: np.ndarray, voiced: np.ndarray) -> np.ndarray:
    """Standardise over voiced frames (the clip's own level), 0 elsewhere."""
    out = np.zeros_like(values, dtype=np.float64)
    if voiced.sum() >= 2:
        v = values[voiced]
        out[voiced] = (v - v.mean()) / (v.std() + 1e-6)
    return out
