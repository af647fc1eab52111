"""The whole model: every ablation row and the released-code variant run forward and backward within the size budget."""
import pytest
import torch

from talkingface.model.gava import count_parameters

ROWS = ["G+MLP", "L+MLP", "LG+MLP", "L+GAVA", "G+GAVA", "LG+SA", "LG+GAVA"]


@pytest.mark.parametrize("row", ROWS + ["released"])
def test_every_variant_runs_forward_and_backward(template, make, row):
    kw = {"variant": "released"} if row == "released" else dict(zip(("features", "decoder"), row.split("+")))
    model = make(**kw).train()
    mel = torch.randn(2, 80, 80)
    idx = torch.arange(30, 30 + 6 * 3, 3)[None].repeat(2, 1)
    tpl = torch.from_numpy(template.vertices * 10)[None].repeat(2, 1, 1)
    out = model(mel, idx, tpl)
    assert out["vertices"].shape == (2, 6, template.num_vertices, 3)
    out["vertices"].sum().backward()
    assert count_parameters(model) * 4 <= 5e6, "the whole exported model must stay within 5 MB"
    if row == "G+GAVA":
        # A global feature copied to every vertex gives every vertex the same displacement (paper, Sec. IV-C).
        o = out["offsets"][0, 0]
        assert torch.allclose(o, o[:1].expand_as(o), atol=1e-5)
