"""The face template: the shipped one reads in Python as TypeScript wrote it; broken files say what is wrong."""
import json
import shutil

import numpy as np
import pytest

from talkingface.paths import TEMPLATE_DIR
from talkingface.template import REQUIRED_REGIONS, TemplateFormatError, build_adjacency, check_adjacency, load_template


def test_shipped_template_reads_in_python(template):
    assert template.id == "mediapipe-canonical-468"
    assert template.vertices.shape == (468, 3) and template.vertices.dtype == np.float32
    assert template.triangles.shape == (852, 3)
    assert template.uvs.shape == (468, 2)
    assert template.to_millimetres() == 10.0
    for name in REQUIRED_REGIONS:
        assert template.regions[name].size > 0


def test_python_adjacency_equals_the_one_typescript_wrote(template):
    offsets, indices = build_adjacency(template.num_vertices, template.triangles)
    np.testing.assert_array_equal(offsets, template.adj_offsets)
    np.testing.assert_array_equal(indices, template.adj_indices)
    edges = {tuple(e) for e in template.edges().tolist()}
    assert all((b, a) in edges for a, b in edges)
    assert all(a != b for a, b in edges)


def test_rings_the_attention_cannot_read_are_refused(template):
    import dataclasses
    off, idx, n = template.adj_offsets, template.adj_indices, template.num_vertices
    check_adjacency(template)

    def broken(edit, match):
        o, i = off.copy(), idx.copy()
        edit(o, i)
        with pytest.raises(TemplateFormatError, match=match):
            check_adjacency(dataclasses.replace(template, adj_offsets=o, adj_indices=i))
    broken(lambda o, i: o.__setitem__(2, o[1] - 1), "must rise from 0")
    broken(lambda o, i: i.__setitem__(off[0], 0), "lists itself")
    broken(lambda o, i: i.__setitem__(slice(off[0], off[0] + 2), i[off[0]:off[0] + 2][::-1].copy()), "not in ascending order")
    broken(lambda o, i: i.__setitem__(off[1] - 1, n - 1), "whose ring lacks it")


def test_corrupt_binary_is_reported(tmp_path):
    shutil.copy(TEMPLATE_DIR / "template.json", tmp_path / "template.json")
    blob = bytearray((TEMPLATE_DIR / "template.bin").read_bytes())
    blob[10] ^= 0xFF
    (tmp_path / "template.bin").write_bytes(bytes(blob))
    with pytest.raises(TemplateFormatError, match="corrupt"):
        load_template(tmp_path / "template.json")


def test_missing_file_and_missing_masks_are_reported(tmp_path):
    with pytest.raises(TemplateFormatError, match="does not exist"):
        load_template(tmp_path / "nope.json")
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(TemplateFormatError, match="masks file"):
        load_template(tmp_path / "m.obj")
    (tmp_path / "masks.json").write_text(json.dumps({"regions": {"jaw": [0]}}))
    with pytest.raises(TemplateFormatError, match="lacks the regions"):
        load_template(tmp_path / "m.obj", tmp_path / "masks.json")
