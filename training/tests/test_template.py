import json
import shutil
import struct

import numpy as np
import pytest

from talkingface.paths import TEMPLATE_DIR
from talkingface.template import REQUIRED_REGIONS, TemplateFormatError, build_adjacency, load_template


@pytest.fixture(scope="module")
def shipped():
    return load_template(TEMPLATE_DIR / "template.json")


def test_shipped_template_reads_in_python(shipped):
    assert shipped.id == "mediapipe-canonical-468"
    assert shipped.vertices.shape == (468, 3) and shipped.vertices.dtype == np.float32
    assert shipped.triangles.shape == (852, 3)
    assert shipped.uvs.shape == (468, 2)
    assert shipped.to_millimetres() == 10.0
    for name in REQUIRED_REGIONS:
        assert shipped.regions[name].size > 0


def test_python_adjacency_equals_the_one_typescript_wrote(shipped):
    offsets, indices = build_adjacency(shipped.num_vertices, shipped.triangles)
    np.testing.assert_array_equal(offsets, shipped.adj_offsets)
    np.testing.assert_array_equal(indices, shipped.adj_indices)
    edges = {tuple(e) for e in shipped.edges().tolist()}
    assert all((b, a) in edges for a, b in edges)
    assert all(a != b for a, b in edges)


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


def _grid():
    verts = np.array([[i, j, 0.5 * i * j] for j in range(3) for i in range(3)], dtype=np.float32)
    tris = []
    for j in range(2):
        for i in range(2):
            a = 3 * j + i
            tris += [[a, a + 1, a + 4], [a, a + 4, a + 3]]
    return verts, np.array(tris)


@pytest.fixture
def masks(tmp_path):
    p = tmp_path / "masks.json"
    p.write_text(json.dumps({"units": "mm", "regions": {r: [k % 9] for k, r in enumerate(REQUIRED_REGIONS)}}))
    return p


def test_user_obj_template(tmp_path, masks):
    verts, tris = _grid()
    lines = [f"v {x} {y} {z}" for x, y, z in verts] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]
    (tmp_path / "head.obj").write_text("\n".join(lines))
    t = load_template(tmp_path / "head.obj", masks)
    assert t.num_vertices == 9 and t.units == "mm"
    np.testing.assert_array_equal(t.vertices, verts)
    assert t.neighbours(4).tolist() == [0, 1, 3, 5, 7, 8]


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian"])
def test_user_ply_template(tmp_path, masks, fmt):
    verts, tris = _grid()
    header = (
        f"ply\nformat {fmt} 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 8\nproperty list uchar int vertex_indices\nend_header\n"
    ).encode()
    if fmt == "ascii":
        body = "".join(f"{x} {y} {z}\n" for x, y, z in verts) + "".join(f"3 {a} {b} {c}\n" for a, b, c in tris)
        body = body.encode()
    else:
        body = verts.astype("<f4").tobytes() + b"".join(struct.pack("<Biii", 3, *map(int, t)) for t in tris)
    (tmp_path / "head.ply").write_bytes(header + body)
    t = load_template(tmp_path / "head.ply", masks)
    np.testing.assert_array_equal(t.vertices, verts)
    np.testing.assert_array_equal(t.triangles, tris)
    assert t.neighbours(4).tolist() == [0, 1, 3, 5, 7, 8]
