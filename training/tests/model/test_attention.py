"""The GAVA mask's semantics, and the two attention implementations (neighbour gather, dense mask) agree."""
import torch

from talkingface.model.attention import gava_dense_mask, neighbour_table


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


def test_neighbour_attention_equals_the_dense_formula(template, make):
    model = make()
    d = model.cfg.d_model
    x = torch.randn(3, template.num_vertices, d)
    p = torch.randn(3, d)
    with torch.no_grad():
        a = model.decode(x, p)
        b = model.decode(x, p, dense=True)
    torch.testing.assert_close(a[0], b[0], atol=1e-5, rtol=1e-5)
    torch.testing.assert_close(a[1], b[1], atol=1e-5, rtol=1e-5)
