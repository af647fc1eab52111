"""A sample clip looped, as the e2e test tests/e2e/live-closure.spec.ts plays it through the fake microphone: the
closures the model itself makes on that audio, offline, on the face the page shows (the template), for each phase of
the loop against the 1/30 s frames (a take starts anywhere in a frame).

  scripts/py -m talkingface.train.looped --checkpoint models/checkpoint.pt --clip Synth15_sentence25

Each line: the loop's start within a frame, /p b m/ closed, and other speech closed (articulation.py's definitions),
counted over the passes after the first (the first has no loop before it, as a take never does); then the truth's own
closures in the other speech (the sample's lip_gap_mm).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import torch

from ..features import log_mel
from ..model import lip_closure as lc
from ..wav import read_wav
from . import articulation as art
from .train import checkpoint_template, load_checkpoint


def looped_counts(model, template, reference_gap: float, mouth_gain: float, audio: np.ndarray, sr: int, phones,
                  loops: int, phase_s: float, fps: float = 30.0) -> dict:
    """segment_counts of the gap the model gives `audio` looped `loops` times on the template's face, the loop
    starting `phase_s` into the first frame; passes 2.. counted."""
    d = int(round(phase_s * sr))
    x = np.concatenate([audio[len(audio) - d:] if d else audio[:0], np.tile(audio, loops)])
    face = (template.vertices * template.to_millimetres()).astype(np.float32)
    with torch.no_grad():
        out = model.animate(torch.from_numpy(log_mel(x, model.audio).astype(np.float32)), torch.from_numpy(face),
                            int(len(x) / sr * fps))
    offsets = out["offsets"].numpy()
    unposed = face[None] + (lc.Closers(template, reference_gap, mouth_gain)(face).apply(offsets) if reference_gap else offsets)
    gap = art.inner_lip_gap(unposed, template)
    L = len(audio) / sr
    shifted = [(p, a + k * L + d / sr, b + k * L + d / sr) for k in range(1, loops) for p, a, b in phones]
    return art.segment_counts(gap, shifted, fps)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.train.looped", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checkpoint", type=Path, default=Path("models/checkpoint.pt"))
    ap.add_argument("--samples", type=Path, default=Path("models/samples"), help="the exported sample clips (index.json)")
    ap.add_argument("--clip", required=True, help="a sample's name, e.g. Synth15_sentence25")
    ap.add_argument("--loops", type=int, default=5)
    ap.add_argument("--phases-ms", default="0,5,10,15,20,25,30", help="where in a frame the loop starts (ms), comma-separated")
    args = ap.parse_args(argv)
    index = json.loads((args.samples / "index.json").read_text())
    clip = next((c for c in index["clips"] if c["name"] == args.clip), None)
    if clip is None:
        ap.error(f"--clip: no sample {args.clip!r} in {args.samples / 'index.json'} (it has {', '.join(c['name'] for c in index['clips'])})")
    if args.loops < 2:
        ap.error("--loops: two or more (the first pass is not counted)")
    audio, sr = read_wav(args.samples / clip["audio"])
    model, ck = load_checkpoint(args.checkpoint)
    model.eval()
    template = checkpoint_template(ck)
    gap, gain = lc.calibration(ck)
    truth = art.segment_counts(np.asarray(clip["lip_gap_mm"], np.float64), clip["phones"], clip["fps"])
    print(f"{args.clip}, looped {args.loops} times on the template's face ({args.checkpoint}); passes 2-{args.loops} counted")
    def closed(c: dict) -> str:
        return (f"/p b m/ closed {c['bilabial_closed']}/{c['bilabial']}, "
                f"other speech closed {c['other_closed']}/{c['other']} ({c['other_closed'] / max(c['other'], 1):.0%})")
    for ms in (float(m) for m in args.phases_ms.split(",") if m):
        c = looped_counts(model, template, gap, gain, audio, sr, clip["phones"], args.loops, ms / 1000)
        print(f"  loop starts {ms:4.0f} ms into a frame: {closed(c)}")
    print(f"  the truth, one pass: {closed(truth)}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
