"""Lip closure on the face's own lips: the model's closing motion retargeted to the neutral face's lip gap.

Why (issue 14; train/closure_causes.py measures it): the displacement that closes the lips is the neutral face's
own gap between them, and the model hears only audio. Trained on faces whose lips part by 4.9-7.3 mm, it learns
the closing displacement of their average; on a face with a smaller gap it presses the lips into each other, on
one with a larger gap it leaves them apart (the test split's two faces, 6.07 and 6.26 mm: 0.4-0.6 mm apart on the
/p b m/ the front-end heard).

What: at every x across the mouth, the model's own closing motion (how far the upper lip's offset comes down
towards the lower lip's) is read as a fraction c of the gap it was trained around, g_ref(x); the lips are then
brought together by c of the face's own gap g(x) instead, with the corpus rig's lip fields (1 on each inner-lip
contour, fading over the lip's tissue; corpus/rig.py). Where the model opens the lips (c = 0) nothing changes; where
it closes them fully (c = 1) they meet on any face:

    gap' = g - c g        c = clamp(-(du - dl) / g_ref, 0, 1)        g_ref(x) = g(x) * reference_gap / lip_gap(face)

Where the face's lips already touch (g(x) <= MIN_GAP_MM: a face modelled with its mouth shut, or beyond the mouth's
corners), g_ref is 0 and every closing motion is a full one: the model's closing there is taken out (the lips stay
touching, gap' = g), and an opening is the model's. Without that, a closed-lip face had its lips pressed through
each other by the whole closing motion the model learnt on parted lips (6.4 mm in silence with the shipped model).

du, dl: the model's vertical offsets of the upper and lower inner-lip contours interpolated at x. reference_gap is
how far the model itself closes: calibrated on the val split (voices and faces it was not trained on) as the gap
at which the lips just meet on the median /p b m/ segment the front-end heard. It is not the train faces' mean
gap: a regression closes short of its targets (the shipped model: about 5.4 mm against their 6.0). The command
writes it into the checkpoint; export puts it in the manifest, and the browser does the same
(src/engine/lip-closure.ts, tested against fixtures export.py writes).

  scripts/py -m talkingface.model.lip_closure --corpus data/corpus --checkpoint CK [--out CK2]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from ..corpus.rig import Rig
from ..geometry.contours import lip_gap
from ..template import Template

MIN_GAP_MM = 0.05  # at or below this the face's lips already touch at that x: the model's closing is taken out there


def interpolation_matrix(x: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """(N,) query x, (M,) ascending contour x -> (N, M) rows of np.interp's weights (ends clamped)."""
    out = np.zeros((len(x), len(xs)))
    k = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, len(xs) - 2)
    t = np.clip((x - xs[k]) / np.maximum(xs[k + 1] - xs[k], 1e-12), 0.0, 1.0)
    out[np.arange(len(x)), k] = 1.0 - t
    out[np.arange(len(x)), k + 1] += t
    return out


class LipClosure:
    """The retargeting of one face (template topology, neutral vertices in mm) to a reference gap in mm."""

    def __init__(self, template: Template, face_mm: np.ndarray, reference_gap_mm: float, mouth_gain: float = 1.0):
        rig = Rig(template, np.asarray(face_mm, np.float64))
        # The mouth's amplitude: the model's offsets on the lips' tissue and the jaw scaled by mouth_gain, fading to
        # 1 with the rig's fields (a regression opens the mouth by about three quarters of the truth's motion).
        self.mouth_gain = float(mouth_gain)
        self.gain = 1.0 + (self.mouth_gain - 1.0) * np.clip(np.maximum(rig.w_jaw, rig.w_lips), 0.0, 1.0)  # (N,)
        self.template = template
        self.lower_weight = rig.w_lower
        v = rig.rest
        self.upper, self.lower = rig.upper_lip, rig.lower_lip           # sorted by x
        x = v[:, 0]
        self.A_up = interpolation_matrix(x, v[self.upper, 0])           # (N, U)
        self.A_lo = interpolation_matrix(x, v[self.lower, 0])           # (N, L)
        self.gap = np.maximum(self.A_up @ v[self.upper, 1] - self.A_lo @ v[self.lower, 1], 0.0)  # g(x) at each vertex
        self.face_gap = float(lip_gap(v[None], template)[0])
        self.reference_gap = float(reference_gap_mm)
        self.ref = self.gap * (self.reference_gap / max(self.face_gap, 1e-6))  # g_ref(x)
        self.field = 0.5 * (rig.w_lower - rig.w_upper)                  # closing: the upper lip down, the lower up
        self.active = np.flatnonzero((self.field != 0) & (self.gap > MIN_GAP_MM))
        self.touching = np.flatnonzero((self.field != 0) & (self.gap <= MIN_GAP_MM))  # the lips meet here at rest

    def torch(self) -> "LipClosureTorch":
        """The same as differentiable torch ops (built once)."""
        if not hasattr(self, "_torch"):
            self._torch = LipClosureTorch(self)
        return self._torch

    def apply(self, offsets: np.ndarray) -> np.ndarray:
        """(F, N, 3) the model's offsets in mm -> the same, the mouth's amplitude scaled, with the lips closed by the
        face's own gap."""
        o = np.array(offsets, dtype=np.float64, copy=True) * self.gain[:, None]
        a, t = self.active, self.touching
        d = o[:, self.upper, 1] @ self.A_up[a].T - o[:, self.lower, 1] @ self.A_lo[a].T   # (F, |a|) du - dl
        d_touching = o[:, self.upper, 1] @ self.A_up[t].T - o[:, self.lower, 1] @ self.A_lo[t].T
        c = np.clip(-d / self.ref[a], 0.0, 1.0)
        o[:, a, 1] += c * (self.gap[a] - self.ref[a]) * self.field[a]
        o[:, t, 1] += np.minimum(d_touching, 0.0) * self.field[t]                            # no closing where they touch
        return o.astype(np.asarray(offsets).dtype)


class LipClosureTorch:
    """The same retargeting as differentiable torch ops, for training with it in the loss (train.py --lip-closure):
    the model then learns how far to close (c), and each face's own gap sets how far that is."""

    def __init__(self, lc: LipClosure):
        import torch
        a, t = lc.active, lc.touching
        f32 = lambda x: torch.as_tensor(np.asarray(x), dtype=torch.float32)
        self.upper, self.lower, self.active, self.touching = (torch.as_tensor(i) for i in (lc.upper, lc.lower, a, t))
        self.A_up, self.A_lo = f32(lc.A_up[a].T), f32(lc.A_lo[a].T)            # (U, |a|), (L, |a|)
        self.gap, self.ref, self.field = f32(lc.gap[a]), f32(lc.ref[a]), f32(lc.field[a])
        self.T_up, self.T_lo, self.field_touching = f32(lc.A_up[t].T), f32(lc.A_lo[t].T), f32(lc.field[t])
        self.gain = f32(lc.gain)[:, None]                                       # (N, 1)

    def apply(self, offsets):
        """(..., N, 3) offsets in mm -> the same, retargeted (a new tensor; gradients flow through c)."""
        scaled = offsets * self.gain
        y = scaled[..., 1]
        d = y[..., self.upper] @ self.A_up - y[..., self.lower] @ self.A_lo
        c = (-d / self.ref).clamp(0.0, 1.0)
        d_touching = y[..., self.upper] @ self.T_up - y[..., self.lower] @ self.T_lo
        out = scaled.clone()
        out[..., self.active, 1] += c * (self.gap - self.ref) * self.field
        out[..., self.touching, 1] += d_touching.clamp(max=0.0) * self.field_touching
        return out


class Closers:
    """The retargeting of each face met (keyed by its neutral vertices), built once per face."""

    def __init__(self, template: Template, reference_gap_mm: float, mouth_gain: float = 1.0):
        self.template, self.reference, self.mouth_gain = template, float(reference_gap_mm), float(mouth_gain)
        self._faces: dict[bytes, LipClosure] = {}

    def __call__(self, face_mm: np.ndarray) -> LipClosure:
        key = np.asarray(face_mm).tobytes()
        if key not in self._faces:
            self._faces[key] = LipClosure(self.template, face_mm, self.reference, self.mouth_gain)
        return self._faces[key]


def calibration(ck: dict) -> tuple[float | None, float]:
    """A checkpoint's lip closure as `main` calibrated it: (reference gap in mm, or None if it has none; mouth gain)."""
    closure = ck.get("lip_closure")
    if not closure:
        return None, 1.0
    return float(closure["reference_gap_mm"]), float(closure.get("mouth_gain", 1.0))


def reference_gap(ds, split: str = "train") -> tuple[float, int]:
    """Mean neutral inner-lip gap (mm) of the faces in `split`, each face counted once."""
    faces = {}
    for key in ds.keys(split):
        if ds.subject_of(key) not in faces:
            faces[ds.subject_of(key)] = np.asarray(ds.load(key).template) * ds.mm_per_unit
    gaps = [float(lip_gap(f[None], ds.template)[0]) for f in faces.values()]
    return float(np.mean(gaps)), len(gaps)


def heard_bilabials(model, ds, split: str, progress=None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Every /p b m/ segment of `split` the front-end heard (a P, B or M argmax at one of its content frames), as
    (face in mm, the model's offsets over the segment's frames): what fit() calibrates on."""
    import torch
    from ..phones import BILABIALS
    from ..train import articulation as art
    from ..train.data import prepare
    rate = model.audio.feature_rate / model.cfg.content_stride
    out, keys = [], ds.keys(split)
    for i, key in enumerate(keys):
        c = prepare(ds, key, model.audio)
        res = model.animate(torch.from_numpy(c.mel), torch.from_numpy(c.template), c.num_frames)
        calls = res["logits"].argmax(-1).numpy()
        offsets = res["offsets"].numpy()
        for p, a, b in c.segments:
            if p in BILABIALS and art.called_bilabial(calls, art.content_span(a, b, rate)):
                out.append((c.template, offsets[art.segment_frames(a, b, ds.fps, c.num_frames)]))
        if progress:
            progress(i + 1, len(keys))
    return out


def fit(segments, template: Template, lo: float = 2.0, hi: float = 12.0, mouth_gain: float = 1.0) -> tuple[float, float]:
    """The reference gap at which the lips just meet on the median heard /p b m/ segment (median of each segment's
    smallest inner-lip gap = 0) with the mouth's amplitude scaled by `mouth_gain`, by bisection (the gap grows with
    the reference). -> (reference mm, raw median mm: the model's own offsets)."""
    def median_gap(ref: float | None) -> float:
        closers = Closers(template, ref, mouth_gain) if ref is not None else None
        gaps = [lip_gap(face[None] + (closers(face).apply(o) if closers else o), template).min() for face, o in segments]
        return float(np.median(gaps))
    for _ in range(14):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if median_gap(mid) > 0 else (mid, hi)
    return 0.5 * (lo + hi), median_gap(None)


def main(argv=None) -> int:
    import torch
    from ..cli import check_out_file, dataset_of, dataset_options
    from ..train.train import load_checkpoint
    ap = argparse.ArgumentParser(prog="python -m talkingface.model.lip_closure", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", type=Path, required=True, help="the dataset the checkpoint was trained on")
    ap.add_argument("--checkpoint", type=Path, required=True, help="read, and written back with the reference gap")
    ap.add_argument("--out", type=Path, help="write here instead of back into --checkpoint")
    ap.add_argument("--split", default="val", help="the split to calibrate on (its voices unheard in training)")
    ap.add_argument("--mouth-gain", type=float, help="scale the mouth's amplitude (the lips' tissue and the jaw) by this "
                    "before closing (default: the checkpoint's, else 1; chosen on val: docs/results/README.md)")
    dataset_options(ap)
    args = ap.parse_args(argv)
    if args.mouth_gain is not None and not 0.5 <= args.mouth_gain <= 2.0:
        ap.error(f"--mouth-gain {args.mouth_gain}: expected a factor between 0.5 and 2")
    check_out_file(ap, args.out)
    torch.set_num_threads(1)
    ds = dataset_of(args)
    model, ck = load_checkpoint(args.checkpoint, ds.template)
    model.eval()
    gain = args.mouth_gain if args.mouth_gain is not None else float((ck.get("lip_closure") or {}).get("mouth_gain", 1.0))
    segs = heard_bilabials(model, ds, args.split, lambda i, n: i % 20 == 0 and print(f"  {i}/{n} clips", file=sys.stderr))
    if not segs:  # the median of nothing: a reference gap at the bisection's bound, written as if calibrated
        raise SystemExit(f"the front-end heard no /p b m/ segment on the {args.split} split, so there is nothing to calibrate the "
                         "closure on: is the model trained (and the split the one its voices are unheard in)? Nothing written")
    ref, raw = fit(segs, ds.template, mouth_gain=gain)
    train_mean, n = reference_gap(ds, "train")
    ck["lip_closure"] = {"reference_gap_mm": ref, "mouth_gain": gain, "split": args.split, "segments": len(segs),
                         "raw_median_smallest_gap_mm": raw, "train_faces_mean_gap_mm": train_mean}
    torch.save(ck, args.out or args.checkpoint)
    print(f"{len(segs)} heard /p b m/ segments on {args.split}: median smallest gap {raw:.2f} mm as the model closes, 0 "
          f"with a reference gap of {ref:.3f} mm and the mouth's amplitude x{gain:g} (the {n} train faces' mean "
          f"neutral gap: {train_mean:.3f} mm); "
          f"wrote {args.out or args.checkpoint}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
