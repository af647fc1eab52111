"""What the face model hears through a speech front-end trained apart: the front-end read from its file or from a face
checkpoint (`load_frontend`), and a voice it has not heard made by warping the Mel axis (`content_warp`)."""
from __future__ import annotations

import numpy as np
import torch

from ..cli import read_checkpoint
from ..features import warp_mel


def content_warp(mel: torch.Tensor, rng: np.random.Generator, lo: float, hi: float) -> torch.Tensor:
    """Each crop's Mel axis stretched by a factor in [lo, hi] or shrunk by its inverse (vocal-tract length).

    A frozen front-end hears the mesh corpus's training voices far better than voices it has never heard
    (measured on the shipped one: frame accuracy 82% on train clips, 64% on the test split's held-out voices).
    A decoder trained on its confident train posteriors learns to close the lips only on a confident P; on a
    new voice it might then miss bilabials the front-end did hear. A warp of 1.2 brings the train clips to the
    held-out voices' accuracy (66%), so the decoder learns to read the posteriors it will get from a stranger.
    Tried on the shipped model, it did not help: the decoder already closes what it hears on the val split
    (docs/results/README.md, "Tried next")."""
    out = mel.clone()
    for b in range(mel.shape[0]):
        f = rng.uniform(lo, hi)
        out[b] = torch.from_numpy(warp_mel(mel[b].numpy(), f if rng.random() < 0.5 else 1 / f))
    return out


def load_frontend(path: str) -> dict:
    """A front-end file (frontend.train's frontend.pt), or the content encoder of a face checkpoint in the same form
    (so a model can be fine-tuned on the shipped front-end after runs/, which holds the front-end's own run, is gone)."""
    ck = read_checkpoint(path, kind="any")
    if "content" in ck:
        return ck
    if "model" not in ck:
        raise SystemExit(f"--frontend: {path} is neither a front-end (frontend.pt) nor a face checkpoint")
    content = {k[len("content."):]: v for k, v in ck["model"].items() if k.startswith("content.")}
    return {"model_config": ck["model_config"], "content": content, "step": ck["step"]}
