"""The loss (Eq. 3-7 and the additions losses.py explains): zero on a perfect prediction, each term where it belongs."""
import pytest
import torch

from talkingface.geometry.pose_torch import apply_pose
from talkingface.train import losses


def test_losses_vanish_on_a_perfect_prediction():
    torch.manual_seed(0)
    v = torch.randn(2, 5, 20, 3)
    pose = torch.randn(2, 5, 6) * 0.1
    tpl = torch.randn(2, 20, 3)
    y = apply_pose(v, pose)
    out = {"vertices": y, "unposed": v, "pose": pose, "offsets": v - tpl[:, None], "content_logits": torch.zeros(2, 4, 41)}
    eye, lips = torch.arange(5), torch.arange(10, 14)
    _, parts = losses.total_loss(out, v, pose, tpl, torch.full((2, 4), -100), eye, lips)
    assert parts["rec"] < 1e-6 and parts["rec_unposed"] < 1e-6 and parts["rec_lips"] < 1e-6 and parts["vel"] < 1e-6 and parts["pose"] < 1e-6
    assert abs(parts["eye"]) < 1e-6
    out["vertices"] = y + torch.tensor([1.0, 0, 0])  # a posed-only error leaves the unposed terms at zero
    _, parts = losses.total_loss(out, v, pose, tpl, torch.full((2, 4), -100), eye, lips)
    assert parts["rec"] == pytest.approx(1.0, abs=1e-5) and parts["vel"] < 1e-6 and parts["rec_lips"] < 1e-6
    out["vertices"], out["unposed"] = y, v.clone()
    out["unposed"][..., 12, :] += torch.tensor([0.0, 2.0, 0.0])  # an error on one lip vertex: 2 mm / 4 lip vertices
    _, parts = losses.total_loss(out, v, pose, tpl, torch.full((2, 4), -100), eye, lips)
    assert parts["rec_lips"] == pytest.approx(0.5, abs=1e-5) and parts["rec_unposed"] == pytest.approx(0.1, abs=1e-5)
    pairs = torch.tensor([[12, 13], [11, 10]])  # the raised vertex 12 opens the first pair by 2 mm: mean |error| 1 mm
    _, parts = losses.total_loss(out, v, pose, tpl, torch.full((2, 4), -100), eye, lips, lip_pairs=pairs)
    assert parts["gap"] == pytest.approx(1.0, abs=1e-5)


def test_the_closure_weight_counts_missed_closures_more():
    torch.manual_seed(0)
    v = torch.zeros(1, 2, 4, 3)
    v[..., 0, 1] = 5.0                     # pair (0, 1): open 5 mm; pair (2, 3): closed (0 mm)
    pred = v.clone()
    pred[..., 2, 1] += 2.0                 # the closed pair left 2 mm open: a missed closure
    pairs = torch.tensor([[0, 1], [2, 3]])
    out = {"vertices": pred, "unposed": pred, "pose": torch.zeros(1, 2, 6), "offsets": pred, "content_logits": torch.zeros(1, 1, 41)}
    args = (v, torch.zeros(1, 2, 6), torch.zeros(1, 4, 3), torch.full((1, 1), -100), torch.arange(1), torch.arange(4))
    _, plain = losses.total_loss(out, *args, lip_pairs=pairs)
    _, weighted = losses.total_loss(out, *args, w=losses.LossWeights(closure=4.0), lip_pairs=pairs)
    assert plain["gap"] == pytest.approx(1.0) and weighted["gap"] == pytest.approx(2.0 * 5 / 6)
