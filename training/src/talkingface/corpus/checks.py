"""Measurements of a built clip: what the tests assert and the dataset card plots."""
from __future__ import annotations

import numpy as np

from ..data.datasets import Clip
from ..geometry.contours import eye_gaps, lip_gap
from ..phones import SILENCE
from ..template import Template


def lip_gap_mm(clip: Clip, template: Template, mm_per_unit: float) -> np.ndarray:
    return lip_gap(clip.vertices, template) * mm_per_unit


def eye_gap_mm(clip: Clip, template: Template, mm_per_unit: float) -> np.ndarray:
    return np.mean(eye_gaps(clip.vertices, template), axis=0) * mm_per_unit


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
