"""Why a model misses /p b m/ closures: per subject, the neutral face's lip gap, how often the front-end heard the
segment, and how often the lips closed when it did; and closure against the front-end's confidence.

  scripts/py -m talkingface.train.closure_causes --corpus data/corpus --checkpoint models/checkpoint.pt --split val

With the checkpoint's lip closure (model/lip_closure.py) unless --raw.

Heard: a P, B or M argmax at a content frame of the segment; closed: inner-lip gap < 1 mm at one of its frames
(the definitions of evaluate.py / articulation.py).
"""
from __future__ import annotations

import argparse
import collections
import sys

import numpy as np
import torch

from ..cli import dataset_of, dataset_options
from ..phones import BILABIALS, PHONES
from . import articulation as art
from ..model import lip_closure as lc
from .data import prepare
from .evaluate import animate_unposed
from .train import load_checkpoint


def segments(model, ds, split: str, reference_gap: float | None = None, mouth_gain: float = 1.0) -> list[dict]:
    """`reference_gap`: retarget the closure to each face with it, the mouth's amplitude scaled by `mouth_gain`
    (model/lip_closure.py, as evaluate does), or None."""
    bil = [PHONES.index(p) for p in BILABIALS]
    rate = model.audio.feature_rate / model.cfg.content_stride
    closers = lc.Closers(ds.template, reference_gap, mouth_gain) if reference_gap is not None else None
    rows = []
    for key in ds.keys(split):
        c = prepare(ds, key, model.audio)
        unposed, out = animate_unposed(model, c, closers)
        gap = art.inner_lip_gap(unposed, ds.template)
        face_gap = float(art.inner_lip_gap(c.template[None], ds.template)[0])
        post = out["logits"].softmax(-1).numpy()
        for p, a, b in c.segments:
            if p not in BILABIALS:
                continue
            frames = art.segment_frames(a, b, ds.fps, len(gap))
            span = art.content_span(a, b, rate)
            rows.append({"subject": ds.subject_of(key), "face_gap": face_gap,
                         "heard": art.called_bilabial(post.argmax(-1), span),
                         "confidence": float(post[span][:, bil].sum(-1).max()) if span.stop <= len(post) else 0.0,
                         "closed": bool(gap[frames].min() < art.CLOSED_MM), "min_gap": float(gap[frames].min())})
    return rows


def report(rows: list[dict]) -> list[str]:
    lines = ["| subject | neutral lip gap (mm) | /p b m/ | heard | closed | closed when heard | median smallest gap when heard (mm) |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    by = collections.defaultdict(list)
    for r in rows:
        by[r["subject"]].append(r)
    for s, rs in sorted(by.items()):
        h = [r for r in rs if r["heard"]]
        when_heard = (f"{np.mean([r['closed'] for r in h]):.0%} | {np.median([r['min_gap'] for r in h]):.2f}" if h
                      else "- | -")  # none heard: nothing to average
        lines.append(f"| {s} | {rs[0]['face_gap']:.2f} | {len(rs)} | {np.mean([r['heard'] for r in rs]):.0%} | "
                     f"{np.mean([r['closed'] for r in rs]):.0%} | {when_heard} |")
    lines += ["", "| front-end's largest P+B+M posterior in the segment | segments | closed | median smallest gap (mm) |",
              "| --- | --- | --- | --- |"]
    for lo, hi in ((0, .3), (.3, .5), (.5, .7), (.7, .9), (.9, 1.01)):
        sel = [r for r in rows if lo <= r["confidence"] < hi]
        if sel:
            lines.append(f"| {lo:.1f}-{min(hi, 1):.1f} | {len(sel)} | {np.mean([r['closed'] for r in sel]):.0%} | "
                         f"{np.median([r['min_gap'] for r in sel]):.2f} |")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.train.closure_causes", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", required=True)
    ap.add_argument("--checkpoint", required=True)
    ap.add_argument("--split", default="val")
    ap.add_argument("--raw", action="store_true", help="the model's offsets as they are, without the checkpoint's lip closure")
    ap.add_argument("--reference-gap", type=float, help="retarget the closure with this reference gap (mm) instead of the checkpoint's")
    dataset_options(ap)
    args = ap.parse_args(argv)
    torch.set_num_threads(1)
    ds = dataset_of(args)
    model, ck = load_checkpoint(args.checkpoint, ds.template)
    model.eval()
    reference, gain = (None, 1.0) if args.raw else lc.calibration(ck)  # with the gain it was calibrated with
    reference = None if args.raw else args.reference_gap or reference
    print("\n".join(report(segments(model, ds, args.split, reference, gain))))
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
