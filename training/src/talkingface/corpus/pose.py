"""The head-pose attribute: rotation driven by prosody plus slow drift, smoothed like the paper's.

The paper adds a pose attribute to VOCASET by pose augmentation and smooths it
with a Gaussian (sigma 1, window 15 frames); we do the same to a track built
from the speech's own loudness and pitch accents (nods on stressed syllables,
a lift on pitch peaks) and Ornstein-Uhlenbeck drift (slow turns and tilts).
Fig. 4 of the paper: most frames move the head by a few degrees.
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


def euler_to_matrix(angles_deg: np.ndarray) -> np.ndarray:
    """(F, 3) degrees (x, y, z applied in that order: R = Rz Ry Rx) -> (F, 3, 3)."""
    ax, ay, az = np.radians(angles_deg).T
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    one, zero = np.ones_like(ax), np.zeros_like(ax)
    Rx = np.stack([one, zero, zero, zero, cx, -sx, zero, sx, cx], 1).reshape(-1, 3, 3)
    Ry = np.stack([cy, zero, sy, zero, one, zero, -sy, zero, cy], 1).reshape(-1, 3, 3)
    Rz = np.stack([cz, -sz, zero, sz, cz, zero, zero, zero, one], 1).reshape(-1, 3, 3)
    return Rz @ Ry @ Rx


def matrix_to_rotvec(R: np.ndarray) -> np.ndarray:
    """(F, 3, 3) rotations -> (F, 3) axis-angle vectors (radians); valid for angles below pi."""
    cos = np.clip((np.trace(R, axis1=1, axis2=2) - 1) / 2, -1, 1)
    angle = np.arccos(cos)
    axis = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], 1)
    s = np.sin(angle)
    small = s < 1e-8
    factor = np.where(small, 0.5, angle / (2 * np.where(small, 1.0, s)))
    return axis * factor[:, None]


def rotvec_to_matrix(rv: np.ndarray) -> np.ndarray:
    """(F, 3) axis-angle (radians) -> (F, 3, 3), Rodrigues' formula."""
    angle = np.linalg.norm(rv, axis=1)
    k = rv / np.maximum(angle, 1e-12)[:, None]
    K = np.zeros((len(rv), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K = K - K.transpose(0, 2, 1)
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3)[None] + s * K + (1 - c) * (K @ K)


def pose_about_pivot(angles_deg: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """(F, 3) Euler degrees turning the head about `pivot` -> (F, 6) [rotvec (rad), translation], y = R x + t."""
    R = euler_to_matrix(angles_deg)
    t = pivot[None, :] - (R @ pivot)
    return np.concatenate([matrix_to_rotvec(R), t], 1)


def apply_pose(vertices: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """(F, N, 3) unposed I + O and (F, 6) poses -> posed y = T_p (I + O) (Eq. 2)."""
    R = rotvec_to_matrix(pose[:, :3])
    return np.einsum("fij,fnj->fni", R, vertices) + pose[:, None, 3:]
