"""How far apart two facing contours of the face are: the inner lips, an eye's lids.

What the corpus checks, the articulation measures, the rest-face search of training and the demo's
timeline (src/template/lip-gap.ts, tested against this on the sample clips) all measure.
"""
from __future__ import annotations

import numpy as np

from ..template import Template


def contour_gap(frames: np.ndarray, upper: np.ndarray, lower: np.ndarray) -> np.ndarray:
    """(F, N, 3) -> (F,) largest vertical opening between two facing contours (each frame's own x order),
    measured at the upper contour's vertices away from the shared corners."""
    out = np.empty(len(frames))
    inner = np.setdiff1d(upper, lower)
    for f, v in enumerate(frames):
        lo = lower[np.argsort(v[lower, 0])]
        out[f] = np.max(v[inner, 1] - np.interp(v[inner, 0], v[lo, 0], v[lo, 1]))
    return out


def lip_gap(frames: np.ndarray, template: Template) -> np.ndarray:
    """(F, N, 3) -> (F,) inner-lip gap, in the units of `frames`."""
    r = template.regions
    return contour_gap(frames, r["lips_inner_upper"], r["lips_inner_lower"])


def eye_gaps(frames: np.ndarray, template: Template) -> list[np.ndarray]:
    """(F, N, 3) -> [(F,) left, (F,) right] opening between each eye's lids, in the units of `frames`."""
    r = template.regions
    return [contour_gap(frames, r[f"eye_{s}_upper"], r[f"eye_{s}_lower"]) for s in ("left", "right")]
