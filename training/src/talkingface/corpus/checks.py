"""Measurements of a built clip: what the tests assert and the dataset card plots."""
from __future__ import annotations

import numpy as np

from ..data.datasets import Clip
from ..template import Template
from .phonemes import BILABIALS, SILENCE

OPEN_VOWELS = frozenset(("AA", "AE", "AH", "AO", "AW", "AY"))


def contour_gap(frames: np.ndarray, upper: np.ndarray, lower: np.ndarray) -> np.ndarray:
    """(F, N, 3) -> (F,) largest vertical opening between two facing contours (each frame's own x order),
    measured at the upper contour's vertices away from the shared corners."""
    out = np.empty(len(frames))
    inner = np.setdiff1d(upper, lower)
    for f, v in enumerate(frames):
        lo = lower[np.argsort(v[lower, 0])]
        out[f] = np.max(v[inner, 1] - np.interp(v[inner, 0], v[lo, 0], v[lo, 1]))
    return out


def lip_gap_mm(clip: Clip, template: Template, mm_per_unit: float) -> np.ndarray:
    r = template.regions
    return contour_gap(clip.vertices, r["lips_inner_upper"], r["lips_inner_lower"]) * mm_per_unit


def eye_gap_mm(clip: Clip, template: Template, mm_per_unit: float) -> np.ndarray:
    r = template.regions
    gaps = [contour_gap(clip.vertices, r[f"eye_{s}_upper"], r[f"eye_{s}_lower"]) for s in ("left", "right")]
    return np.mean(gaps, axis=0) * mm_per_unit


def centre_frame(start: float, end: float, fps: float, n_frames: int) -> int:
    return int(np.clip(round(0.5 * (start + end) * fps), 0, n_frames - 1))


def gaps_at(clip: Clip, gap_mm: np.ndarray, phones: frozenset[str], min_duration: float = 0.0) -> list[tuple[str, float, float]]:
    """(phone, centre time, gap in mm at the frame nearest the centre) for each segment of `phones`."""
    return [(p, 0.5 * (a + b), float(gap_mm[centre_frame(a, b, clip.fps, clip.num_frames)]))
            for p, a, b in clip.phones or [] if p in phones and b - a >= min_duration]


def speech_bounds(audio: np.ndarray, sr: int, floor_db: float = -40.0, win: float = 0.01) -> tuple[float, float]:
    """First and last time the 10 ms RMS level is within `floor_db` of the clip's loudest window."""
    n = int(win * sr)
    frames = audio[: len(audio) // n * n].reshape(-1, n).astype(np.float64)
    level = 10 * np.log10(np.mean(frames ** 2, axis=1) + 1e-12)
    loud = np.flatnonzero(level > level.max() + floor_db)
    return (loud[0] * win, (loud[-1] + 1) * win) if len(loud) else (0.0, 0.0)


def label_bounds(clip: Clip) -> tuple[float, float]:
    speech = [(a, b) for p, a, b in clip.phones or [] if p != SILENCE]
    return (speech[0][0], speech[-1][1]) if speech else (0.0, 0.0)


def pose_degrees(pose: np.ndarray) -> np.ndarray:
    """(F, 6) -> (F,) rotation angle from the neutral pose, degrees."""
    return np.degrees(np.linalg.norm(pose[:, :3], axis=1))


def pose_step_degrees(pose: np.ndarray) -> np.ndarray:
    """(F, 6) -> (F-1,) rotation between consecutive frames, degrees (small-angle: difference of axis-angles)."""
    return np.degrees(np.linalg.norm(np.diff(pose[:, :3], axis=0), axis=1))
