"""The model: the GAVA mask's semantics, the two attention implementations, variants, losses, metrics."""
import numpy as np
import pytest
import torch

from talkingface.model.attention import gava_dense_mask, neighbour_table
from talkingface.model.config import ModelConfig
from talkingface.model.gava import TalkingFace, count_parameters
from talkingface.model.geometry import apply_pose, rotvec_to_matrix
from talkingface.paths import TEMPLATE_DIR
from talkingface.template import load_template
from talkingface.train import losses, metrics

ROWS = ["G+MLP", "L+MLP", "LG+MLP", "L+GAVA", "G+GAVA", "LG+SA", "LG+GAVA"]


@pytest.fixture(scope="module")
def template():
    return load_template(TEMPLATE_DIR / "template.json")


def make(template, **kw):
    torch.manual_seed(0)
    return TalkingFace(ModelConfig(**kw), template).eval()


def test_augmented_adjacency_mask(template):
    table, pad = neighbour_table(template.adj_offsets, template.adj_indices, template.num_vertices)
    m = gava_dense_mask(table, pad)
    n = template.num_vertices
    allowed = m == 0
    for v in (0, 13, 200, n - 1):
        expect = set(template.neighbours(v).tolist()) | {v}
        assert set(torch.nonzero(allowed[v]).flatten().tolist()) == expect
    assert not allowed[:n, n].any(), "a vertex must never attend to the pose token"
    assert allowed[n].all(), "the pose token attends to every vertex and itself"


def test_neighbour_attention_equals_the_dense_formula(template):
    model = make(template)
    d = model.cfg.d_model
    x = torch.randn(3, template.num_vertices, d)
    p = torch.randn(3, d)
    with torch.no_grad():
        a = model.decode(x, p)
        b = model.decode(x, p, dense=True)
    torch.testing.assert_close(a[0], b[0], atol=1e-5, rtol=1e-5)
    torch.testing.assert_close(a[1], b[1], atol=1e-5, rtol=1e-5)


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


def test_gava_information_travels_one_ring_per_layer(template):
    """With L masked layers, a change at vertex v reaches exactly the vertices within L hops, and no vertex
    depends on the pose token; plain self-attention (SA) spreads everywhere."""
    n, v = template.num_vertices, 13
    dist = hops_from(template, v)
    d = ModelConfig().d_model
    x = torch.randn(1, n, d)
    p = torch.randn(1, d)
    x2 = x.clone()
    x2[0, v] += torch.randn(d)  # not a constant shift: LayerNorm would remove that before attention sees it
    model = make(template)

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
    sa = make(template, decoder="SA")
    with torch.no_grad():
        spread = (tokens_out(sa, x2, p) - tokens_out(sa, x, p))[:, :n].abs().amax(-1)[0] > 1e-6
    assert spread[dist > L].all()


@pytest.mark.parametrize("row", ROWS + ["released"])
def test_every_variant_runs_forward_and_backward(template, row):
    kw = {"variant": "released"} if row == "released" else dict(zip(("features", "decoder"), row.split("+")))
    model = make(template, **kw).train()
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


def test_pose_geometry():
    rv = torch.tensor([[0.0, 0.0, np.pi / 2]])
    R = rotvec_to_matrix(rv)[0]
    torch.testing.assert_close(R @ torch.tensor([1.0, 0, 0]), torch.tensor([0.0, 1, 0]), atol=1e-6, rtol=0)
    v = torch.randn(4, 10, 3)
    pose = torch.cat([torch.zeros(4, 3), torch.ones(4, 3)], -1)
    torch.testing.assert_close(apply_pose(v, pose), v + 1)


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


def test_metrics_on_known_errors(template):
    T, n = 4, template.num_vertices
    gt = np.zeros((T, n, 3))
    pred = gt.copy()
    lips = metrics.lip_region(template)
    assert set(template.regions["lips_outer"]) <= set(lips) and len(lips) > len(template.regions["lips_outer"])
    pred[:, lips[0], 1] = 2.0
    pred[1, lips[1], 1] = 5.0
    assert metrics.max_region_error(gt, pred, lips) == pytest.approx((2 + 5 + 2 + 2) / 4)
    up = template.regions["upper_face"]
    motion_gt = np.zeros((T, n, 3))
    motion_gt[:, up, 0] = np.array([0, 1, 0, 1])[:, None]  # std 0.5 on x
    assert metrics.fdd(motion_gt, np.zeros_like(motion_gt), up) == pytest.approx(0.5)
    assert metrics.afdd(motion_gt, np.zeros_like(motion_gt), up) == pytest.approx(0.5 / 3)
    assert metrics.afdd(motion_gt, -motion_gt, up) == pytest.approx(0.0)
    pose = np.zeros((5, 6))
    pose2 = pose.copy()
    pose2[:, 1] = np.radians(3)
    assert metrics.rotation_angle_deg(pose, pose2) == pytest.approx(np.full(5, 3.0))


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
