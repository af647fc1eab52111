"""Measure speech front-ends by themselves, side by side: frame accuracy, /p b m/ heard, and both per voice.

  scripts/py -m talkingface.frontend.measure --corpus data/corpus [--split val,test] [--warps 0.92,1,1.08] FRONTEND [FRONTEND ...] [--out F.json]
  scripts/py -m talkingface.frontend.measure --corpus data/corpus --warps 0.86,0.9,0.94,0.97,1,1.03,1.06,1.1,1.14 --choose-warp entropy FRONTEND

Per voice it also says where the frames are lost: vowels, consonants, and how many speech frames were heard as a
phone of the right lip group (phones.LIP_GROUPS: what a viewer would see). With --choose-warp, each clip is heard
through one of the --warps instead of their average: the one whose posteriors are the most certain (entropy: what
a page could do, vocal-tract length normalisation without labels) or the one that scores best against the
alignment (oracle: a bound, not a method; how far a better guess of the voice's tract length could go).

Each FRONTEND is a front-end file (frontend.train's frontend.pt) or a face checkpoint, whose content encoder is read
(models/checkpoint.pt: the shipped one); A+B+... is their ensemble, the mean of their log-posteriors (what a student
distilled from them could hear at most, about). The numbers are those of `talkingface.train.evaluate`'s content encoder
tables (docs/results/default.md) without training or running a face: a few seconds per split, so a new front-end
can be compared with the shipped one on the held-out voices before a face is trained on it.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import torch

from ..cli import check_out_file, dataset_of, dataset_options
from ..features import AudioConfig, warp_mel
from ..model.config import ModelConfig
from ..model.encoders import ContentEncoder
from ..train import articulation as art
from ..train.data import prepare
from ..train.train import load_frontend


class Ensemble(torch.nn.Module):
    """Content encoders heard together: the mean of their log-posteriors, (1, K, n_mels) -> (1, Kc, D)."""

    def __init__(self, encoders: list[ContentEncoder]):
        super().__init__()
        self.members = torch.nn.ModuleList(encoders)

    def forward(self, mel: torch.Tensor) -> torch.Tensor:
        return torch.stack([e(mel).log_softmax(-1) for e in self.members]).mean(0)


def load_encoder(path: str) -> tuple[ContentEncoder | Ensemble, ModelConfig]:
    """The content encoder of a front-end file or a face checkpoint, its Mel normalisation included; for "A+B+...",
    their Ensemble (their content phones and strides must agree)."""
    if "+" in path and not Path(path).exists():
        members = [load_encoder(p) for p in path.split("+")]
        cfgs = {(c.content_classes, c.content_stride) for _, c in members}
        if len(cfgs) > 1:
            raise ValueError(f"{path}: the front-ends hear different phone sets or strides ({sorted(cfgs)}), they cannot be averaged")
        return Ensemble([e for e, _ in members]).eval(), members[0][1]
    ck = load_frontend(path)
    cfg = ModelConfig.from_dict(ck["model_config"])
    enc = ContentEncoder(cfg, AudioConfig().n_mels)
    enc.load_state_dict(ck["content"])
    return enc.eval(), cfg


@torch.no_grad()
def heard(enc: ContentEncoder | Ensemble, mel: np.ndarray, warps: tuple[float, ...] = (1.0,)) -> torch.Tensor:
    """(K, n_mels) log-Mel -> (Kc, D) logits; with several `warps`, the mean of the log-posteriors of the Mel axis
    warped by each (test-time averaging over vocal-tract lengths, as the training's frequency warp)."""
    if tuple(warps) == (1.0,):
        return enc(torch.from_numpy(mel)[None])[0]
    return torch.stack(warped_log_posteriors(enc, mel, warps)).mean(0)


def warped_log_posteriors(enc: ContentEncoder, mel: np.ndarray, warps: tuple[float, ...]) -> list[torch.Tensor]:
    """The clip's (Kc, D) log-posteriors with its Mel axis warped by each of `warps`."""
    return [enc(torch.from_numpy(warp_mel(mel, w).astype(np.float32))[None])[0].log_softmax(-1) for w in warps]


@torch.no_grad()
def heard_at_chosen_warp(enc: ContentEncoder, mel: np.ndarray, warps: tuple[float, ...], how: str,
                         labels: np.ndarray) -> tuple[torch.Tensor, float]:
    """The clip heard through the one of `warps` that `how` picks: "entropy", the lowest mean entropy of the
    posteriors over the clip's frames; "oracle", the highest frame accuracy against `labels` (the content frames'
    phones). -> ((Kc, D) log-posteriors, the warp)."""
    lps = warped_log_posteriors(enc, mel, warps)
    if how == "entropy":
        score = [float((lp.exp() * lp).sum(-1).mean()) for lp in lps]  # minus the entropy: higher is more certain
    elif how == "oracle":
        k = min(len(labels), len(lps[0]))
        score = [float((lp[:k].argmax(-1).numpy() == labels[:k]).mean()) for lp in lps]
    else:
        raise ValueError(f"choose a warp by 'entropy' or 'oracle', not {how!r}")
    best = int(np.argmax(score))
    return lps[best], warps[best]


def measure(enc: ContentEncoder, cfg: ModelConfig, clips, warps: tuple[float, ...] = (1.0,), choose: str | None = None) -> dict:
    """Over prepared clips: content_summary's figures for all of them, and voice_rows per voice; with `choose`
    (heard_at_chosen_warp), each clip at its chosen warp, and the mean warp chosen per voice."""
    tally = art.ContentTally(cfg.content_classes)
    chosen: dict[str, list[float]] = {}
    for c in clips:
        labels = c.phones[:: cfg.content_stride]
        if choose:
            logits, w = heard_at_chosen_warp(enc, c.mel, warps, choose, labels)
            chosen.setdefault(art.voice_family(c.voice), []).append(w)
        else:
            logits = heard(enc, c.mel, warps)
        tally.add(logits.numpy(), labels, c.voice)
    s = tally.summary()
    rows = tally.voices()
    for r in rows:
        if r["voice"] in chosen:
            r["mean_warp_chosen"] = float(np.mean(chosen[r["voice"]]))
    kept = ("frame_accuracy", "bilabial_segments_heard", "bilabial_segments", "vowel_frame_accuracy",
            "consonant_frame_accuracy", "lip_group_accuracy")
    return {**{k: s[k] for k in kept}, "by_voice": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.frontend.measure", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("frontends", nargs="+", help="front-end files (frontend.pt) or face checkpoints; A+B: their ensemble")
    ap.add_argument("--corpus", type=Path, required=True)
    ap.add_argument("--split", default="val,test", help="the corpus's splits to measure on, comma-separated (default: val,test)")
    ap.add_argument("--warps", default="1", help="Mel-axis warp factors whose log-posteriors are averaged, comma-separated "
                    "(default 1: the front-end as it runs; 0.92,1,1.08: test-time averaging over three vocal-tract lengths)")
    ap.add_argument("--choose-warp", choices=("entropy", "oracle"),
                    help="hear each clip through one of --warps, chosen by the posteriors' certainty (entropy) or against "
                         "the alignment (oracle: a bound), instead of averaging them")
    ap.add_argument("--out", type=Path, help="also write the figures here (JSON)")
    dataset_options(ap)
    args = ap.parse_args(argv)
    check_out_file(ap, args.out)
    args.split = [s for s in args.split.split(",") if s]
    try:
        warps = tuple(float(w) for w in args.warps.split(","))
    except ValueError:
        ap.error(f"--warps: {args.warps!r} is not a comma-separated list of numbers")
    if any(not 0.5 <= w <= 2 for w in warps):
        ap.error(f"--warps: factors between 0.5 and 2, not {args.warps}")
    if args.choose_warp and len(warps) < 2:
        ap.error("--choose-warp: give two or more --warps to choose from")
    ds = dataset_of(args)
    audio = AudioConfig()
    clips = {s: [prepare(ds, k, audio) for k in ds.keys(s)] for s in args.split}
    results = {}
    for path in args.frontends:
        enc, cfg = load_encoder(path)
        results[path] = {s: measure(enc, cfg, clips[s], warps, args.choose_warp) for s in args.split}
    pct = lambda x: f"{100 * x:.1f}%"
    for s in args.split:
        print(f"\n{s} split ({len(clips[s])} clips): frame accuracy, /p b m/ segments heard")
        for path, r in results.items():
            print(f"  {pct(r[s]['frame_accuracy']):>6}  {pct(r[s]['bilabial_segments_heard']):>6} of {r[s]['bilabial_segments']}  {path}")
        voices = [row["voice"] for row in results[args.frontends[0]][s]["by_voice"]]
        print(f"  per voice (frame accuracy; one column per front-end, in the order above):")
        for v in voices:
            cells = []
            for r in results.values():
                row = next(x for x in r[s]["by_voice"] if x["voice"] == v)
                cells.append(f"{pct(row['frame_accuracy']):>6} ({row['bilabial_segments_heard']}/{row['bilabial_segments']})")
            print(f"    {v:28s} {row['frames']:6d} frames  " + "  ".join(cells))
        print("  where the frames are lost (vowels / consonants / speech frames in the right lip group; one block per front-end):")
        for v in ["all", *voices]:
            cells = []
            for r in results.values():
                row = r[s] if v == "all" else next(x for x in r[s]["by_voice"] if x["voice"] == v)
                warp = f" warp {row['mean_warp_chosen']:.3f}" if "mean_warp_chosen" in row else ""
                cells.append(f"{pct(row['vowel_frame_accuracy']):>6} / {pct(row['consonant_frame_accuracy']):>6} / "
                             f"{pct(row['lip_group_accuracy']):>6}{warp}")
            print(f"    {v:28s} " + "   ".join(cells))
    if args.out:
        args.out.write_text(json.dumps(results, indent=1))
        print(f"\nwritten: {args.out}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
