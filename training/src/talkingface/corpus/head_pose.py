"""The head-pose attribute: rotation driven by prosody plus slow drift, smoothed like the paper's.

The paper adds a pose attribute to VOCASET by pose augmentation and smooths it
with a Gaussian (sigma 1, window 15 frames); we do the same to a track built
from the speech's own loudness and pitch accents (nods on stressed syllables,
a lift on pitch peaks) and Ornstein-Uhlenbeck drift (slow turns and tilts).
Fig. 4 of the paper: most frames move the head by a few degrees. clip.py turns
the angles into poses about the neck (geometry/pose.py, pose_about_pivot).
"""
from __future__ import annotations

import numpy as np


def gaussian_smooth(x: np.ndarray, sigma: float = 1.0, window: int = 15) -> np.ndarray:
    """Smooth along axis 0 with a normalised Gaussian kernel of `window` taps (edges padded by reflection)."""
    half = window // 2
    k = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
    k /= k.sum()
    pad = np.pad(x, [(half, half)] + [(0, 0)] * (x.ndim - 1), mode="reflect" if len(x) > half else "edge")
    out = np.stack([np.convolve(pad[:, j], k, mode="valid") for j in range(pad.shape[1])], 1) if x.ndim == 2 else np.convolve(pad, k, mode="valid")
    return out


def ou_process(n: int, fps: float, tau: float, std: float, rng: np.random.Generator) -> np.ndarray:
    """Ornstein-Uhlenbeck drift with time constant tau (s) and stationary std."""
    a = np.exp(-1.0 / (fps * tau))
    noise = rng.normal(0.0, std * np.sqrt(1 - a * a), n)
    out = np.empty(n)
    out[0] = rng.normal(0.0, std)
    for i in range(1, n):
        out[i] = a * out[i - 1] + noise[i]
    return out


def head_pose_track(pitch_z: np.ndarray, energy_z: np.ndarray, speaking: np.ndarray, fps: float,
                    rng: np.random.Generator, liveliness: float = 1.0, max_degrees: float = 12.0) -> np.ndarray:
    """(F,) prosody z-scores and a speaking mask -> (F, 3) Euler angles in degrees: pitch (nod, +x), yaw (+y), roll (+z)."""
    n = len(pitch_z)
    accent = gaussian_smooth(np.where(speaking, energy_z, 0.0), sigma=3.0, window=19)
    lift = gaussian_smooth(np.where(speaking, np.clip(pitch_z, 0, None), 0.0), sigma=4.0, window=25)
    activity = gaussian_smooth(speaking.astype(np.float64), sigma=8.0, window=41)
    nod = -1.3 * accent + 0.9 * lift + ou_process(n, fps, 2.0, 1.2, rng)
    yaw = ou_process(n, fps, 3.0, 2.5, rng) * (0.6 + 0.4 * activity)
    roll = ou_process(n, fps, 2.5, 1.0, rng) + 0.3 * accent
    angles = np.stack([nod, yaw, roll], 1) * liveliness
    angles = max_degrees * np.tanh(angles / max_degrees)  # soft limit, keeps the track smooth
    return gaussian_smooth(angles, sigma=1.0, window=15)
