"""Two models on the same segments: which closures differ, and whether the difference is more than chance.

The val split decides between models, and it holds 190 /p b m/ segments: a difference of a few points in the share
closed is a handful of segments. Both models are judged on the same segments, so the test is paired (McNemar's): of
the segments on which they disagree, how many each one closes, and how likely a split at least that uneven is if
either were as likely to close them (exact binomial, two-sided). The same for closures in other speech. d' is
z(closed) - z(closed elsewhere), the discrimination that a bias towards closing does not raise.

  scripts/py -m talkingface.train.paired --corpus data/corpus models/checkpoint.pt runs/face/cal.pt [--split val] [--out F.json]

Each model with its own lip closure (as `evaluate` and the browser: model/lip_closure.py).
"""
from __future__ import annotations

import argparse
import json
import sys
from math import comb
from pathlib import Path
from statistics import NormalDist

import numpy as np
import torch

from ..cli import dataset_of, dataset_options
from ..model import lip_closure as lc
from ..phones import BILABIALS
from . import articulation as art
from .data import prepare
from .evaluate import animate_unposed
from .train import load_checkpoint


def closures(model, ck: dict, ds, split: str, progress=None) -> dict[str, np.ndarray]:
    """Per speech segment of `split`, in order: whether the model's lips close in it, for /p b m/ ("bilabial") and
    for every other segment ("other")."""
    reference, gain = lc.calibration(ck)
    closers = lc.Closers(ds.template, reference, gain) if reference is not None else None
    model.eval()
    flags = {"bilabial": [], "other": []}
    keys = ds.keys(split)
    for i, key in enumerate(keys):
        c = prepare(ds, key, model.audio)
        with torch.no_grad():
            unposed, _ = animate_unposed(model, c, closers)
        for p, _, _, g in art.speech_segments(art.inner_lip_gap(unposed, ds.template), c.segments, ds.fps):
            flags["bilabial" if p in BILABIALS else "other"].append(bool(g.min() < art.CLOSED_MM))
        if progress:
            progress(i + 1, len(keys))
    return {k: np.array(v, dtype=bool) for k, v in flags.items()}


def mcnemar(a: np.ndarray, b: np.ndarray) -> dict:
    """Paired yes/no outcomes of two models on the same items -> the discordant counts and McNemar's exact p."""
    if a.shape != b.shape:
        raise ValueError(f"the two models were measured on different segments ({a.shape} against {b.shape})")
    only_a, only_b = int((a & ~b).sum()), int((~a & b).sum())
    n = only_a + only_b
    p = min(1.0, 2 * sum(comb(n, k) for k in range(min(only_a, only_b) + 1)) / 2 ** n) if n else 1.0
    return {"n": int(len(a)), "first": float(a.mean()) if len(a) else 0.0, "second": float(b.mean()) if len(b) else 0.0,
            "only_first": only_a, "only_second": only_b, "p": p}


def d_prime(hit: float, false_alarm: float, n_hit: int, n_false: int) -> float:
    """z(hit) - z(false alarm), each rate kept half a trial from 0 and 1."""
    z = NormalDist().inv_cdf
    clamp = lambda r, n: min(max(r, 0.5 / max(n, 1)), 1 - 0.5 / max(n, 1))  # no trials (a subset without /p b m/): 0.5
    return z(clamp(hit, n_hit)) - z(clamp(false_alarm, n_false))


def compare(first: dict[str, np.ndarray], second: dict[str, np.ndarray]) -> dict:
    out = {"bilabial_closed": mcnemar(first["bilabial"], second["bilabial"]),
           "closed_in_other_speech": mcnemar(first["other"], second["other"])}
    b, o = out["bilabial_closed"], out["closed_in_other_speech"]
    out["d_prime"] = {"first": d_prime(b["first"], o["first"], b["n"], o["n"]),
                      "second": d_prime(b["second"], o["second"], b["n"], o["n"])}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.train.paired", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("first", help="a face checkpoint (e.g. the shipped one)")
    ap.add_argument("second", help="the face checkpoint to compare with it")
    ap.add_argument("--corpus", required=True, help="the dataset both were trained on")
    ap.add_argument("--split", default="val", choices=("train", "val", "test"),
                    help="the split both are measured on (default val, which decides)")
    ap.add_argument("--out", type=Path, help="also write the figures as JSON here")
    dataset_options(ap)
    args = ap.parse_args(argv)
    ds = dataset_of(args)
    if not ds.keys(args.split):
        ap.error(f"--split {args.split}: {args.corpus} has no clips in it")
    torch.set_num_threads(1)
    flags = []
    for path in (args.first, args.second):
        model, ck = load_checkpoint(Path(path), ds.template)
        flags.append(closures(model, ck, ds, args.split,
                              lambda i, n: i % 20 == 0 and print(f"  {path}: {i}/{n} clips", file=sys.stderr)))
    res = compare(*flags) | {"first": args.first, "second": args.second, "split": args.split}
    for name, key in (("/p b m/ closed", "bilabial_closed"), ("closed in other speech", "closed_in_other_speech")):
        r = res[key]
        print(f"{name}: {100 * r['first']:.1f}% against {100 * r['second']:.1f}% of {r['n']} segments; closed by the first "
              f"only {r['only_first']}, by the second only {r['only_second']}; McNemar exact p = {r['p']:.3f}")
    print(f"d': {res['d_prime']['first']:.2f} against {res['d_prime']['second']:.2f}")
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(res, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
