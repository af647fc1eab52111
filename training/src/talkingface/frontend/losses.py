"""The front-end trainer's terms beside the cross-entropy against the labels (frontend/train.py): the two views'
disagreement (--consistency) and the distance from a teacher's posteriors (--teacher)."""
from __future__ import annotations

import torch


def view_disagreement(logits: torch.Tensor, real: torch.Tensor) -> torch.Tensor:
    """Symmetric KL divergence between the posteriors of a batch's two views (its halves), over the frames that
    are speech in both. logits (2B, K, D), real (2B, K) -> a scalar."""
    a, b = logits.log_softmax(-1).chunk(2)
    kl = (a.exp() * (a - b) + b.exp() * (b - a)).sum(-1) / 2                  # (B, K)
    m = real.chunk(2)[0]
    return (kl * m).sum() / m.sum().clamp(min=1)


def distillation(logits: torch.Tensor, teacher: torch.Tensor, real: torch.Tensor) -> torch.Tensor:
    """KL divergence from a teacher's log-posteriors to the student's, over the frames that are not padding.
    logits (B, K, D) the student's, teacher (B, K', D) log-posteriors, real (B, K) -> a scalar."""
    k = min(logits.shape[1], teacher.shape[1], real.shape[1])
    s, t = logits[:, :k].log_softmax(-1), teacher[:, :k]
    kl = (t.exp() * (t - s)).sum(-1)
    m = real[:, :k].float()
    return (kl * m).sum() / m.sum().clamp(min=1)
