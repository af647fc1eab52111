"""A front-end between two: the weights of a fine-tune interpolated with those it started from (issue 14).

A fine-tune of the shipped front-end on new voices hears the voices it was tuned for better and loses some of what
it heard before (on the val split, /p b m/ heard falls from 91% to 87-88% in every fine-tune tried). Two networks
of which one was fine-tuned from the other usually lie in one basin of the loss, so the straight line between their
weights holds networks that keep the first one's strengths and gain the second's: this is weight-space ensembling
(Wortsman et al., "Robust fine-tuning of zero-shot models", CVPR 2022, WiSE-FT). It costs nothing at run time: the
result is one network of the same size.

  scripts/py -m talkingface.frontend.soup models/checkpoint.pt runs/fe-diph/frontend.pt --alpha 0.5 --out runs/fe-soup.pt

writes (1 - alpha) * BASE + alpha * TUNED, weight by weight (its Mel normalisation included), as a front-end file
that `frontend.measure` reads and `talkingface.train.train --frontend` puts into a face. BASE and TUNED are front-end
files or face checkpoints (their content encoder), of one architecture; alpha is chosen on the val split. With
`--face CHECKPOINT` it writes that face checkpoint instead, its content encoder replaced by the result and nothing else
changed (its lip closure is then recalibrated: model/lip_closure.py); `--alpha 1` puts TUNED itself into the face.
"""
from __future__ import annotations

import argparse
import sys

import torch

from ..cli import check_out_file, read_checkpoint
from ..model.encoders import ContentEncoder
from ..train.train import load_frontend


def interpolate(base: dict, tuned: dict, alpha: float) -> dict:
    """(1 - alpha) * base + alpha * tuned for every floating-point tensor of the content encoder; any other tensor
    must be equal in both. base and tuned as `load_frontend` returns them."""
    if not 0.0 <= alpha <= 1.0:
        raise ValueError(f"alpha is a fraction of the way from BASE to TUNED, from 0 to 1 (got {alpha})")
    a, b = base["content"], tuned["content"]
    if a.keys() != b.keys():
        raise ValueError(f"the two front-ends differ in their layers: {sorted(a.keys() ^ b.keys())[:4]}")
    out = {}
    for k, t in b.items():
        if a[k].shape != t.shape:
            raise ValueError(f"the two front-ends differ in {k}: {tuple(a[k].shape)} against {tuple(t.shape)} "
                             "(a wider one cannot be interpolated with a narrower one)")
        if t.is_floating_point():
            out[k] = (1 - alpha) * a[k] + alpha * t
        elif torch.equal(a[k], t):
            out[k] = t.clone()
        else:
            raise ValueError(f"the two front-ends differ in {k}, which is not a weight")
    return out


def with_look_ahead_of(base: dict, tuned: dict) -> dict:
    """base as it is, or, where TUNED gained a look-ahead block in its fine-tune (frontend.train --ahead) that BASE
    lacks, BASE with that block at zero: the same function (frontend.train.look_further), so the line between them
    is defined."""
    from ..model.config import ModelConfig
    from .train import look_further
    b, t = (ModelConfig.from_dict(x["model_config"]) for x in (base, tuned))
    if b.content_ahead or not t.content_ahead:
        return base
    enc = ContentEncoder(b, base["content"]["norm.mean"].numel())
    enc.load_state_dict(base["content"])
    cfg = ModelConfig(**b.to_dict() | {"content_ahead": t.content_ahead})
    return {**base, "content": look_further(enc, cfg).state_dict(), "model_config": cfg.to_dict()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.frontend.soup", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("base", help="the front-end the fine-tune started from (a frontend.pt or a face checkpoint)")
    ap.add_argument("tuned", help="the fine-tuned front-end")
    ap.add_argument("--alpha", type=float, default=0.5, help="how far from BASE towards TUNED (default 0.5)")
    ap.add_argument("--face", help="write this face checkpoint with the result as its content encoder, not a front-end file")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    check_out_file(ap, args.out)
    tuned = load_frontend(args.tuned)
    base = with_look_ahead_of(load_frontend(args.base), tuned)
    try:
        content = interpolate(base, tuned, args.alpha)
    except ValueError as e:
        ap.error(str(e))
    made = {"base": args.base, "tuned": args.tuned, "alpha": args.alpha}
    if args.face:
        payload = read_checkpoint(args.face)
        model = payload["model"]
        face = with_look_ahead_of({"content": {k[len("content."):]: v for k, v in model.items() if k.startswith("content.")},
                                   "model_config": payload["model_config"]}, tuned)
        if face["content"].keys() != content.keys() or any(face["content"][k].shape != v.shape for k, v in content.items()):
            ap.error(f"--face: the content encoder of {args.face} is not of the front-ends' architecture")
        payload["model"] = {**model, **{"content." + k: v for k, v in content.items()}}
        payload["model_config"] = face["model_config"]
        payload["frontend_soup"] = made
    else:
        payload = {"content": content, "model_config": tuned["model_config"], "step": tuned.get("step", 0),
                   "audio_config": tuned.get("audio_config"), "history": [], "soup": made}
    torch.save(payload, args.out)
    into = f" in {args.face}" if args.face else ""
    print(f"front-end {1 - args.alpha:g} x {args.base} + {args.alpha:g} x {args.tuned}{into} -> {args.out}")
    if args.face and "lip_closure" in payload:  # calibrated on what the old front-end heard
        print(f"its lip closure is still {args.face}'s: calibrate it for this front-end (scripts/py -m talkingface.model.lip_closure "
              f"--corpus ... --checkpoint {args.out}) before exporting it", file=sys.stderr)
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
