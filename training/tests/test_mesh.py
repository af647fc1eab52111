"""A user's own mesh as a template: OBJ, and PLY in ASCII and binary little-endian, read alike."""
import json
import struct

import numpy as np
import pytest

from talkingface.template import REQUIRED_REGIONS, TemplateFormatError, load_template


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


def test_a_mesh_the_reader_does_not_know_is_a_template_error(tmp_path, masks):
    (tmp_path / "head.ply").write_bytes(b"ply\nformat binary_big_endian 1.0\nelement vertex 0\nend_header\n")
    with pytest.raises(TemplateFormatError, match="binary_big_endian.* is not supported"):
        load_template(tmp_path / "head.ply", masks)


def test_an_ascii_ply_with_per_face_texture_coordinates_and_one_cut_short(tmp_path, masks):
    """Per-face float lists (texcoord, as MeshLab writes) are read as floats; a body cut short is a template error."""
    verts, tris = _grid()
    header = ("ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 8\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n")
    body = "".join(f"{x} {y} {z}\n" for x, y, z in verts) + "".join(f"3 {a} {b} {c} 6 0.5 0.25 0 1 1 0\n" for a, b, c in tris)
    (tmp_path / "head.ply").write_text(header + body)
    np.testing.assert_array_equal(load_template(tmp_path / "head.ply", masks).triangles, tris)
    (tmp_path / "cut.ply").write_text(header + body[: len(body) // 2])
    with pytest.raises(TemplateFormatError, match="cut.ply: the PLY body ends before the counts its header states"):
        load_template(tmp_path / "cut.ply", masks)


def test_a_masks_file_or_template_header_that_is_broken_is_a_template_error(tmp_path, masks):
    verts, tris = _grid()
    (tmp_path / "head.obj").write_text("\n".join([f"v {x} {y} {z}" for x, y, z in verts] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]))
    (tmp_path / "bad.json").write_text("{ not json")
    with pytest.raises(TemplateFormatError, match="masks file .*bad.json is not valid JSON"):
        load_template(tmp_path / "head.obj", tmp_path / "bad.json")
    (tmp_path / "template.json").write_text(json.dumps({"format": "talking-face-template", "version": 1, "id": "x"}))
    with pytest.raises(TemplateFormatError, match="template.json: the template header lacks or misstates 'binary'"):
        load_template(tmp_path / "template.json")
