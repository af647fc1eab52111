"""Subjects: a face identity (a smooth deformation of the template) and a speaking style.

The deformations are low-frequency and left-right symmetric (proportions, jaw
width, lip thickness, mouth width, nose), so every subject is a plausible face
with the template's topology and regions.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..template import Template
from .coarticulation import SpeakingStyle


@dataclass(frozen=True)
class Identity:
    scale: float
    width: float
    height: float
    depth: float
    jaw_width: float
    lip_thickness: float
    mouth_width: float
    nose: float
    bumps: tuple[tuple[float, float, float, float], ...]  # (x, y, z amplitude, radius) in units of face height


@dataclass(frozen=True)
class Subject:
    name: str
    identity: Identity
    style: SpeakingStyle

    def describe(self) -> dict:
        return {"name": self.name, "identity": asdict(self.identity), "style": asdict(self.style)}


def sample_subject(name: str, rng: np.random.Generator) -> Subject:
    identity = Identity(
        scale=rng.uniform(0.92, 1.08),
        width=rng.uniform(0.94, 1.06),
        height=rng.uniform(0.94, 1.06),
        depth=rng.uniform(0.92, 1.08),
        jaw_width=rng.uniform(-0.08, 0.08),
        lip_thickness=rng.uniform(0.8, 1.3),
        mouth_width=rng.uniform(0.92, 1.1),
        nose=rng.uniform(-0.04, 0.04),
        bumps=tuple((rng.uniform(0, 0.4), rng.uniform(-0.5, 0.5), rng.uniform(-0.015, 0.015), rng.uniform(0.12, 0.25)) for _ in range(4)),
    )
    lo = rng.uniform(1.8, 3.0)
    style = SpeakingStyle(
        amplitude=rng.uniform(0.8, 1.2),
        jaw_ratio=rng.uniform(0.75, 1.3),
        pose_liveliness=rng.uniform(0.5, 1.5),
        brow_expressiveness=rng.uniform(0.4, 1.3),
        blink_interval=(lo, lo + rng.uniform(2.0, 3.5)),
    )
    return Subject(name, identity, style)


def _smoothstep(x):
    x = np.clip(x, 0, 1)
    return x * x * (3 - 2 * x)


def apply_identity(template: Template, ident: Identity) -> np.ndarray:
    """The subject's neutral face (N, 3), float32, in the template's units."""
    v = template.vertices.astype(np.float64).copy()
    r = template.regions
    center = v.mean(0)
    H = float(v[:, 1].max() - v[:, 1].min())
    inner = np.union1d(r["lips_inner_upper"], r["lips_inner_lower"])
    mouth = v[inner].mean(0)
    mouth_w = float(v[inner, 0].max() - v[inner, 0].min())
    d_mouth = np.min(np.linalg.norm(v[:, None] - v[None, inner], axis=2), axis=1)
    w_lips = np.exp(-((d_mouth / (0.3 * mouth_w)) ** 2))

    # Lips: thickness about the mouth line, width about the mouth centre.
    v[:, 1] += (ident.lip_thickness - 1.0) * (v[:, 1] - mouth[1]) * w_lips
    v[:, 0] += (ident.mouth_width - 1.0) * (v[:, 0] - mouth[0]) * w_lips
    # Jaw width: the lower face widens or narrows, fading in below the mouth.
    below = _smoothstep((mouth[1] - v[:, 1]) / (0.25 * H) + 0.2)
    v[:, 0] *= 1.0 + ident.jaw_width * below
    # Nose: push the tip region forward or back.
    tip = v[r["nose_tip"][0]] if "nose_tip" in r else v[np.argmax(v[:, 2])]
    v[:, 2] += ident.nose * H * np.exp(-((np.linalg.norm(v - tip, axis=1) / (0.12 * H)) ** 2))
    # Symmetric smooth bumps in depth.
    for bx, by, amp, rad in ident.bumps:
        for sx in (1.0, -1.0):
            c = center + np.array([sx * bx * H, by * H, 0.0])
            d = np.linalg.norm((v - c)[:, :2], axis=1)
            v[:, 2] += amp * H * np.exp(-((d / (rad * H)) ** 2))
    # Proportions last, about the face centre.
    v = center + (v - center) * ident.scale * np.array([ident.width, ident.height, ident.depth])
    return v.astype(np.float32)
