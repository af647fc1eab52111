"""The attention decoder: GAVA spreads information one ring per layer and never from the pose token; SA everywhere."""
import numpy as np
import torch

from talkingface.model.config import ModelConfig


def hops_from(template, v: int) -> np.ndarray:
    dist = np.full(template.num_vertices, -1)
    dist[v], frontier, d = 0, [v], 0
    while frontier:
        d += 1
        nxt = []
        for u in frontier:
            for w in template.neighbours(u):
                if dist[w] < 0:
                    dist[w] = d
                    nxt.append(int(w))
        frontier = nxt
    return dist


def test_gava_information_travels_one_ring_per_layer(template, make):
    """With L masked layers, a change at vertex v reaches exactly the vertices within L hops, and no vertex
    depends on the pose token; plain self-attention (SA) spreads everywhere."""
    n, v = template.num_vertices, 13
    dist = hops_from(template, v)
    d = ModelConfig().d_model
    x = torch.randn(1, n, d)
    p = torch.randn(1, d)
    x2 = x.clone()
    x2[0, v] += torch.randn(d)  # not a constant shift: LayerNorm would remove that before attention sees it
    model = make()

    def tokens_out(m, x, p):  # the decoder's output tokens (the heads are per token; the pose head starts at zero)
        return m.decoder(torch.cat([x, p[:, None]], 1), m.nbr_table, m.nbr_pad)[0]
    with torch.no_grad():
        out0 = tokens_out(model, x, p)
        out1 = tokens_out(model, x2, p)
        out2 = tokens_out(model, x, p + torch.randn(d))
    base, moved, other_pose = out0[:, :n], out1[:, :n], out2[:, :n]
    pose0, pose1 = out0[:, n], out1[:, n]
    change = (moved - base).abs().amax(-1)[0]
    L = model.cfg.layers
    assert (change[dist <= L] > 1e-6).all() and (change[dist > L] == 0).all()
    assert (pose1 - pose0).abs().max() > 0, "the pose token reads every vertex"
    assert torch.equal(other_pose, base), "vertices are independent of the pose token"
    sa = make(decoder="SA")
    with torch.no_grad():
        spread = (tokens_out(sa, x2, p) - tokens_out(sa, x, p))[:, :n].abs().amax(-1)[0] > 1e-6
    assert spread[dist > L].all()
