"""From timed phones to per-frame articulation, blinks and brow raises.

Coarticulation after Cohen & Massaro (1993): each phone segment s exerts a
dominance D_s(t) = a_s * exp(-d_s(t) / w_s) on each parameter, where d_s is the
distance from the segment's core (its central 60%; a long pause holds its
target throughout), with a wider fall-off before the segment (anticipation)
than after; the parameter is the dominance-weighted mean of the targets. Bilabials then close the lips
fully for their whole duration, whatever the neighbours do.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..phones import BILABIALS, PHONE_INDEX, PHONES, VOWELS
from .visemes import DOMINANCE, P, TARGETS


@dataclass(frozen=True)
class Segment:
    phone: str   # ARPAbet (talkingface.phones)
    start: float  # seconds
    end: float


@dataclass(frozen=True)
class SpeakingStyle:
    """One subject's manner of speaking."""
    amplitude: float = 1.0        # overall articulation size
    jaw_ratio: float = 1.0        # > 1 opens with the jaw, < 1 with the lips
    pose_liveliness: float = 1.0  # head movement scale
    brow_expressiveness: float = 1.0
    blink_interval: tuple[float, float] = (2.0, 6.0)  # seconds between blinks (uniform)


def frame_times(n_frames: int, fps: float) -> np.ndarray:
    """Frame i shows the face at t = i / fps."""
    return np.arange(n_frames) / fps


def articulation_track(segments: list[Segment], n_frames: int, fps: float, style: SpeakingStyle = SpeakingStyle()) -> np.ndarray:
    """(n_frames, len(PARAMS)) parameters in [0, ~1.3]."""
    t = frame_times(n_frames, fps)[:, None]                       # (F, 1)
    ids = np.array([PHONE_INDEX[s.phone] for s in segments])
    start = np.array([s.start for s in segments])
    end = np.array([s.end for s in segments])
    centre = 0.5 * (start + end)[None, :]                         # (1, S)
    dur = np.maximum(end - start, 1e-3)[None, :]
    outside_core = np.maximum(np.abs(t - centre) - 0.3 * dur, 0.0)  # (F, S)
    # Anticipation reaches further than carry-over (lips round before a /u/ starts).
    width = np.where(t < centre, np.minimum(0.4 * dur, 0.06) + 0.04, np.minimum(0.3 * dur, 0.05) + 0.03)
    fall = np.exp(-outside_core / width)                          # (F, S)
    dom = fall[:, :, None] * DOMINANCE[ids][None, :, :]           # (F, S, Pn)
    track = (dom * TARGETS[ids][None, :, :]).sum(1) / np.maximum(dom.sum(1), 1e-12)  # (F, Pn)

    track[:, P["jaw"]] *= style.amplitude * style.jaw_ratio
    track[:, P["lip_open"]] *= style.amplitude / style.jaw_ratio
    for name in ("round", "protrude", "spread"):
        track[:, P[name]] *= style.amplitude
    track[:, P["close"]] = np.maximum(track[:, P["close"]], bilabial_closure(segments, n_frames, fps))
    return np.clip(track, 0.0, 1.3)


def bilabial_closure(segments: list[Segment], n_frames: int, fps: float, ramp: float = 0.05) -> np.ndarray:
    """1 through every /p b m/ (and at least on the frame nearest its centre), easing to 0 within `ramp` seconds."""
    t = frame_times(n_frames, fps)
    env = np.zeros(n_frames)
    for s in segments:
        if s.phone not in BILABIALS:
            continue
        nearest = np.clip(round(0.5 * (s.start + s.end) * fps), 0, n_frames - 1) / fps
        a, b = min(s.start, nearest), max(s.end, nearest)
        inside = (t >= a) & (t <= b)
        before = np.clip((t - (a - ramp)) / ramp, 0, 1)
        after = np.clip(((b + ramp) - t) / ramp, 0, 1)
        shape = np.where(inside, 1.0, np.where(t < a, _ease(before), _ease(after)))
        env = np.maximum(env, shape)
    return env


def _ease(x: np.ndarray) -> np.ndarray:
    return 0.5 - 0.5 * np.cos(np.pi * np.clip(x, 0, 1))


@dataclass(frozen=True)
class Blink:
    start: float
    duration: float
    amount: float  # 1 = lids meet, < 1 partial


def sample_blinks(duration: float, rng: np.random.Generator, style: SpeakingStyle = SpeakingStyle()) -> list[Blink]:
    """Blinks at uniform random intervals in style.blink_interval; ~120 ms each; one in five partial."""
    lo, hi = style.blink_interval
    # A clip starts at a random point of the blink cycle (a stationary renewal process), so short
    # clips show the same rate as long ones.
    blinks, t = [], rng.uniform(0.0, 1.0) * rng.uniform(lo, hi)
    while t < duration:
        amount = 1.0 if rng.random() > 0.2 else rng.uniform(0.5, 0.85)
        blinks.append(Blink(t, rng.uniform(0.1, 0.15), amount))
        t += rng.uniform(lo, hi)
    return blinks


def blink_track(blinks: list[Blink], n_frames: int, fps: float) -> np.ndarray:
    """Lid closure per frame: a fast close (35% of the blink), a slower open; the nearest frame to the peak is full."""
    t = frame_times(n_frames, fps)
    out = np.zeros(n_frames)
    for b in blinks:
        peak = b.start + 0.35 * b.duration
        rise = np.clip((t - b.start) / (peak - b.start), 0, 1)
        fall = np.clip((b.start + b.duration - t) / (b.start + b.duration - peak), 0, 1)
        shape = np.where(t <= peak, _ease(rise), _ease(fall))
        k = int(np.clip(round(peak * fps), 0, n_frames - 1))
        shape[k] = 1.0
        out = np.maximum(out, b.amount * shape)
    return out


def brow_track(segments: list[Segment], pitch: np.ndarray, energy: np.ndarray, fps: float, rng: np.random.Generator,
               style: SpeakingStyle = SpeakingStyle()) -> np.ndarray:
    """Brow raises on prominent vowels: where pitch and loudness peak above the clip's own level.

    pitch, energy: per-frame z-scores (0 where unvoiced/silent)."""
    n = len(pitch)
    t = frame_times(n, fps)
    out = np.zeros(n)
    for s in segments:
        if s.phone not in VOWELS or s.end - s.start < 0.06:
            continue
        k = slice(int(s.start * fps), max(int(s.end * fps), int(s.start * fps) + 1))
        prominence = 0.6 * np.max(pitch[k], initial=0) + 0.4 * np.max(energy[k], initial=0)
        if prominence < 1.0 or rng.random() < 0.35:
            continue
        amount = min(1.0, 0.35 * prominence) * style.brow_expressiveness
        c = 0.5 * (s.start + s.end)
        out = np.maximum(out, amount * np.exp(-0.5 * ((t - c) / 0.18) ** 2))
    return out


def segments_from_pairs(pairs: list[tuple[str, float, float]]) -> list[Segment]:
    segs = [Segment(p, float(a), float(b)) for p, a, b in pairs]
    for s in segs:
        if s.phone not in PHONES:
            raise ValueError(f"unknown phone {s.phone!r}")
    return segs
