"""A procedural articulation rig on any template with the standard regions.

It plays the part of the paper's 4D capture: given per-frame articulation
parameters (visemes.PARAMS, plus blink and brow), it produces the displaced
face I + O for every frame, with exact geometry (lips that touch on /p b m/,
lids that meet on a blink). All magnitudes are relative to the mouth width, so
a template in cm, mm or metres, with 468 or 5023 vertices, moves alike.

Weights are harmonic functions on the mesh graph (solved once per template):
they follow the surface, so the upper lip and the lower lip, which face each
other across the opened mouth but are not connected, move independently.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..template import Template
from .visemes import P


@dataclass(frozen=True)
class RigScale:
    """How far each parameter moves at 1.0, as fractions of the inner mouth width W (about 45-50 mm)."""
    jaw_degrees: float = 8.0       # mandible rotation about the hinge (open vowels: ~10-15 mm between the lips)
    lip_open_upper: float = 0.06   # upper lip raise
    lip_open_lower: float = 0.05   # lower lip drop, beyond the jaw
    round_narrow: float = 0.28     # fraction of the lip half-width removed by full rounding
    round_forward: float = 0.04
    protrude: float = 0.09
    spread: float = 0.08
    labiodental_back: float = 0.07
    brow_raise: float = 0.08


def harmonic_weights(adj_offsets: np.ndarray, adj_indices: np.ndarray, fixed: dict[int, float]) -> np.ndarray:
    """Solve the graph Laplace equation: w is fixed on `fixed` and the mean of its neighbours everywhere else."""
    n = len(adj_offsets) - 1
    deg = np.diff(adj_offsets).astype(np.float64)
    rows = np.repeat(np.arange(n), np.diff(adj_offsets))
    L = np.zeros((n, n))
    L[rows, adj_indices] = -1.0
    L[np.arange(n), np.arange(n)] = deg
    w = np.zeros(n)
    known = np.zeros(n, dtype=bool)
    for v, value in fixed.items():
        w[v] = value
        known[v] = True
    free = ~known & (deg > 0)
    rhs = -L[np.ix_(free, known)] @ w[known]
    w[free] = np.linalg.solve(L[np.ix_(free, free)], rhs)
    return np.clip(w, 0.0, 1.0)


def _arc_by_x(vertices: np.ndarray, idx: np.ndarray) -> np.ndarray:
    return idx[np.argsort(vertices[idx, 0], kind="stable")]


class Rig:
    """Precomputed deformation fields of one template (one subject's neutral face)."""

    def __init__(self, template: Template, vertices: np.ndarray | None = None, scale: RigScale = RigScale()):
        self.template = template
        self.rest = np.asarray(template.vertices if vertices is None else vertices, dtype=np.float64)
        self.scale = scale
        r, v = template.regions, self.rest
        n = len(v)
        self.upper_lip = _arc_by_x(v, r["lips_inner_upper"])
        self.lower_lip = _arc_by_x(v, r["lips_inner_lower"])
        inner = np.union1d(self.upper_lip, self.lower_lip)
        self.mouth_center = v[inner].mean(0)
        self.W = float(v[inner, 0].max() - v[inner, 0].min())  # inner mouth width
        W = self.W
        corners = np.intersect1d(self.upper_lip, self.lower_lip)
        corner_y = v[corners, 1].mean() if len(corners) else self.mouth_center[1]

        d_inner = np.min(np.linalg.norm(v[:, None, :] - v[None, inner, :], axis=2), axis=1)
        far = d_inner > 0.55 * W
        # Each lip's tissue: 1 on its own contour (corners shared at 0.5), 0 on the other lip and far away.
        def lip_field(own, other):
            fixed = {int(i): 0.0 for i in np.flatnonzero(far)}
            fixed.update({int(i): 0.0 for i in other})
            fixed.update({int(i): 1.0 for i in own})
            fixed.update({int(i): 0.5 for i in corners})
            return harmonic_weights(template.adj_offsets, template.adj_indices, fixed)
        self.w_upper = lip_field(self.upper_lip, self.lower_lip)
        self.w_lower = lip_field(self.lower_lip, self.upper_lip)
        self.w_lips = np.maximum(self.w_upper, self.w_lower)

        # The mandible: everything well below the mouth and the lower lip turns with it;
        # the upper lip and everything above the cheekbones stays.
        fixed = {int(i): 1.0 for i in np.flatnonzero(v[:, 1] < corner_y - 0.45 * W)}
        fixed.update({int(i): 0.0 for i in np.flatnonzero(v[:, 1] > corner_y + 0.3 * W)})
        fixed.update({int(i): 1.0 for i in self.lower_lip})
        fixed.update({int(i): 0.0 for i in self.upper_lip})
        fixed.update({int(i): 0.5 for i in corners})
        self.w_jaw = harmonic_weights(template.adj_offsets, template.adj_indices, fixed)
        lips_z = v[inner, 2].mean()
        self.hinge = np.array([self.mouth_center[0], corner_y + 0.7 * W, lips_z - 2.0 * W])

        # Eyelids: upper lid contour 1, lower contour 0 (and vice versa), fading with distance.
        self.eyes = []
        for side in ("left", "right"):
            up = _arc_by_x(v, r[f"eye_{side}_upper"])
            lo = _arc_by_x(v, r[f"eye_{side}_lower"])
            eye_corners = np.intersect1d(up, lo)
            eye_all = np.union1d(up, lo)
            ew = float(v[eye_all, 0].max() - v[eye_all, 0].min())
            d_eye = np.min(np.linalg.norm(v[:, None, :] - v[None, eye_all, :], axis=2), axis=1)
            def lid_field(own, other, reach):
                fixed = {int(i): 0.0 for i in np.flatnonzero(d_eye > reach * ew)}
                fixed.update({int(i): 0.0 for i in other})
                fixed.update({int(i): 1.0 for i in np.setdiff1d(own, eye_corners)})
                fixed.update({int(i): 0.0 for i in eye_corners})
                return harmonic_weights(template.adj_offsets, template.adj_indices, fixed)
            self.eyes.append((up, lo, lid_field(up, lo, 0.45), lid_field(lo, up, 0.3)))

        brows = r["brows"]
        eye_all = np.concatenate([np.union1d(e[0], e[1]) for e in self.eyes])
        d_brow = np.min(np.linalg.norm(v[:, None, :] - v[None, brows, :], axis=2), axis=1)
        fixed = {int(i): 0.0 for i in np.flatnonzero(d_brow > 0.9 * W)}
        fixed.update({int(i): 0.0 for i in eye_all})
        fixed.update({int(i): 1.0 for i in brows})
        self.w_brow = harmonic_weights(template.adj_offsets, template.adj_indices, fixed)
        self.num_vertices = n

    def deform(self, params: np.ndarray, blink: np.ndarray, brow: np.ndarray) -> np.ndarray:
        """(F, len(PARAMS)) articulation, (F,) blink closure, (F,) brow raise -> (F, N, 3) vertices I + O."""
        F = params.shape[0]
        out = np.empty((F, self.num_vertices, 3), dtype=np.float64)
        for f in range(F):
            out[f] = self._frame(params[f], float(blink[f]), float(brow[f]))
        return out.astype(np.float32)

    def _frame(self, p: np.ndarray, blink: float, brow: float) -> np.ndarray:
        s, W, v0 = self.scale, self.W, self.rest
        v = v0.copy()
        c = self.mouth_center
        # Lip shape first (in the rest frame of the lips), then the jaw carries the lower face.
        dx_center = v0[:, 0] - c[0]
        v[:, 0] -= p[P["round"]] * s.round_narrow * dx_center * self.w_lips
        v[:, 2] += (p[P["round"]] * s.round_forward + p[P["protrude"]] * s.protrude) * W * self.w_lips
        half = 0.5 * W
        corner_w = self.w_lips * np.clip(np.abs(dx_center) / half, 0.0, 1.0) ** 2
        v[:, 0] += p[P["spread"]] * s.spread * W * np.sign(dx_center) * corner_w
        v[:, 1] += p[P["spread"]] * 0.02 * W * corner_w
        v[:, 2] -= p[P["spread"]] * 0.03 * W * corner_w
        v[:, 1] += p[P["lip_open"]] * (s.lip_open_upper * self.w_upper - s.lip_open_lower * self.w_lower) * W

        angle = np.radians(p[P["jaw"]] * s.jaw_degrees)
        if angle != 0.0:
            ca, sa = np.cos(angle), np.sin(angle)
            rel = v - self.hinge
            # Opening turns the chin (in front of the hinge, +z) down and back.
            rotated = np.stack([rel[:, 0], ca * rel[:, 1] - sa * rel[:, 2], sa * rel[:, 1] + ca * rel[:, 2]], 1)
            v += self.w_jaw[:, None] * (rotated + self.hinge - v)

        lab = p[P["labiodental"]]
        if lab > 0:
            gap = self._gap(v, self.upper_lip, self.lower_lip)
            v[:, 1] += lab * (gap + 0.02 * W) * self.w_lower
            v[:, 2] -= lab * s.labiodental_back * W * self.w_lower
        close = p[P["close"]]
        if close > 0:
            self._close(v, self.upper_lip, self.lower_lip, self.w_upper, self.w_lower, close, 0.5)
        if blink > 0:
            for up, lo, w_up, w_lo in self.eyes:
                self._close(v, up, lo, w_up, w_lo, blink, 0.85)
        if brow != 0:
            v[:, 1] += brow * s.brow_raise * W * self.w_brow
        return v

    @staticmethod
    def _gap(v: np.ndarray, upper: np.ndarray, lower: np.ndarray) -> np.ndarray:
        """Per vertex: the vertical distance between the two contours at that vertex's x (never negative)."""
        x = v[:, 0]
        yu = np.interp(x, v[upper, 0], v[upper, 1])
        yl = np.interp(x, v[lower, 0], v[lower, 1])
        return np.maximum(yu - yl, 0.0)

    def _close(self, v, upper, lower, w_up, w_lo, amount, upper_share):
        """Bring two facing contours together: the upper one takes `upper_share` of the gap, z meets halfway."""
        x = v[:, 0]
        yu = np.interp(x, v[upper, 0], v[upper, 1])
        yl = np.interp(x, v[lower, 0], v[lower, 1])
        zu = np.interp(x, v[upper, 0], v[upper, 2])
        zl = np.interp(x, v[lower, 0], v[lower, 2])
        gap = np.maximum(yu - yl, 0.0)
        meet_z = 0.5 * (zu + zl)
        v[:, 1] += amount * gap * (-upper_share * w_up + (1.0 - upper_share) * w_lo)
        v[:, 2] += amount * ((meet_z - zu) * w_up + (meet_z - zl) * w_lo)
