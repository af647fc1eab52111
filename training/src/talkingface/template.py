"""The face template I (Eq. 2): neutral vertices, triangles, 1-ring adjacency, named regions.

Reads the repository's template format (template.json + template.bin, written by
scripts/extract-template.ts and scripts/import-template.ts) and, with a masks
file, a user's own OBJ or PLY mesh (a FLAME head from VOCASET, a Multiface
mesh; mesh.py reads those). Nothing here assumes a vertex count.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .mesh import MeshFormatError, read_obj, read_ply

TEMPLATE_FORMAT = "talking-face-template"
TEMPLATE_FORMAT_VERSION = 1
REQUIRED_REGIONS = (
    "lips_inner_upper",
    "lips_inner_lower",
    "lips_outer",
    "eye_left_upper",
    "eye_left_lower",
    "eye_right_upper",
    "eye_right_lower",
    "brows",
    "upper_face",
    "face_boundary",
    "jaw",
)
_DTYPES = {"float32": np.float32, "uint32": np.uint32}
MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0}  # template and dataset length units


class TemplateFormatError(ValueError):
    """A template file is missing, corrupt, or lacks what the toolkit needs; the message says which."""


@dataclass
class Template:
    id: str
    units: str                      # length unit of `vertices`: "cm", "mm" or "m"
    vertices: np.ndarray            # (N, 3) float32, Y up, +Z toward the viewer
    triangles: np.ndarray           # (T, 3) int64
    adj_offsets: np.ndarray         # (N + 1,) int64, CSR row starts of the 1-ring
    adj_indices: np.ndarray         # (E,) int64, neighbours, ascending per vertex, no self loops
    regions: dict[str, np.ndarray]  # name -> sorted int64 vertex indices
    uvs: np.ndarray | None = None   # (N, 2) float32
    source: dict[str, str] = field(default_factory=dict)

    @property
    def num_vertices(self) -> int:
        return self.vertices.shape[0]

    def neighbours(self, v: int) -> np.ndarray:
        return self.adj_indices[self.adj_offsets[v] : self.adj_offsets[v + 1]]

    def edges(self) -> np.ndarray:
        """(E, 2) directed 1-ring edges (both directions), for graph ops and attention masks."""
        rows = np.repeat(np.arange(self.num_vertices), np.diff(self.adj_offsets))
        return np.stack([rows, self.adj_indices], axis=1)

    def to_millimetres(self) -> float:
        """Factor that converts this template's units to mm (metrics are reported in mm, as in the paper)."""
        return MM_PER_UNIT[self.units]


def build_adjacency(num_vertices: int, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1-ring neighbours from triangle edges as CSR (offsets, indices): symmetric, no self loops, sorted."""
    tri = np.asarray(triangles, dtype=np.int64)
    pairs = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    both = np.concatenate([pairs, pairs[:, ::-1]])
    both = np.unique(both, axis=0)  # sorted by row, then column
    offsets = np.zeros(num_vertices + 1, dtype=np.int64)
    np.add.at(offsets, both[:, 0] + 1, 1)
    return np.cumsum(offsets), both[:, 1].copy()


def load_template(path: str | Path, masks: str | Path | None = None) -> Template:
    """Load a template: our template.json, or an .obj / .ply mesh together with its masks JSON."""
    path = Path(path)
    if not path.exists():
        raise TemplateFormatError(f"template file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".json":
        return _load_native(path)
    if suffix in (".obj", ".ply"):
        if masks is None:
            raise TemplateFormatError(f"{path.name}: a mesh template needs a masks file with its regions (docs/templates.md)")
        try:
            m = json.loads(Path(masks).read_text())
        except json.JSONDecodeError as e:
            raise TemplateFormatError(f"masks file {masks} is not valid JSON: {e}") from e
        try:
            verts, tris, uvs = read_obj(path) if suffix == ".obj" else read_ply(path)
        except MeshFormatError as e:  # the template loader's one error type; the mesh reader's reason kept
            raise TemplateFormatError(str(e)) from e
        return template_from_mesh(path.stem, m.get("units", "mm"), verts, tris, m.get("regions", {}), uvs, {"file": path.name})
    raise TemplateFormatError(f"{path.name}: a template must be template.json, .obj or .ply")


def template_from_mesh(id: str, units: str, vertices, triangles, regions: dict, uvs=None, source=None) -> Template:
    vertices = np.asarray(vertices, dtype=np.float32).reshape(-1, 3)
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    n = vertices.shape[0]
    if triangles.size and (triangles.min() < 0 or triangles.max() >= n):
        raise TemplateFormatError(f"template {id}: a triangle index is out of range for {n} vertices")
    missing = [r for r in REQUIRED_REGIONS if len(regions.get(r, [])) == 0]
    if missing:
        raise TemplateFormatError(f"template {id} lacks the regions {', '.join(missing)} (docs/templates.md)")
    regs = {}
    for name, idx in regions.items():
        idx = np.unique(np.asarray(idx, dtype=np.int64))
        if idx.size and (idx.min() < 0 or idx.max() >= n):
            raise TemplateFormatError(f"template {id}: region {name} has an index out of range for {n} vertices")
        regs[name] = idx
    offsets, indices = build_adjacency(n, triangles)
    return Template(id, units, vertices, triangles, offsets, indices, regs, uvs, dict(source or {}))


def _load_native(path: Path) -> Template:
    try:
        return _read_native(path)
    except (KeyError, TypeError) as e:  # a field it must have is missing, or is not what it must be
        raise TemplateFormatError(f"{path}: the template header lacks or misstates {e} (re-export it: npm run import-template)") from e


def _read_native(path: Path) -> Template:
    try:
        header = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise TemplateFormatError(f"{path} is not valid JSON: {e}") from e
    if header.get("format") != TEMPLATE_FORMAT:
        raise TemplateFormatError(f'{path} is not a face template (expected "format": "{TEMPLATE_FORMAT}")')
    if header.get("version") != TEMPLATE_FORMAT_VERSION:
        raise TemplateFormatError(f"{path}: template format version {header.get('version')} is not supported")
    bin_path = path.parent / header["binary"]
    if not bin_path.exists():
        raise TemplateFormatError(f"template binary {bin_path} is missing")
    blob = bin_path.read_bytes()
    if hashlib.sha256(blob).hexdigest() != header["binarySha256"]:
        raise TemplateFormatError(f"template binary {bin_path} is corrupt or belongs to another template (sha256 mismatch)")

    def view(name: str, required: bool = True):
        spec = header["buffers"].get(name)
        if spec is None:
            if required:
                raise TemplateFormatError(f"template {header['id']} has no {name!r} buffer")
            return None
        count = int(np.prod(spec["shape"]))
        arr = np.frombuffer(blob, dtype=np.dtype(_DTYPES[spec["dtype"]]).newbyteorder("<"), count=count, offset=spec["byteOffset"])
        return arr.reshape(spec["shape"]).copy()

    n = header["vertexCount"]
    t = Template(
        id=header["id"],
        units=header["units"],
        vertices=view("positions"),
        triangles=view("triangles").astype(np.int64),
        adj_offsets=view("adjacencyOffsets").astype(np.int64),
        adj_indices=view("adjacencyIndices").astype(np.int64),
        regions={k: np.asarray(v, dtype=np.int64) for k, v in header["regions"].items()},
        uvs=view("uvs", required=False),
        source=header.get("source", {}),
    )
    if t.vertices.shape != (n, 3) or t.adj_offsets.shape != (n + 1,):
        raise TemplateFormatError(f"template {t.id}: buffer sizes do not match vertexCount {n}")
    check_adjacency(t)
    missing = [r for r in REQUIRED_REGIONS if t.regions.get(r, np.empty(0)).size == 0]
    if missing:
        raise TemplateFormatError(f"template {t.id} lacks the regions {', '.join(missing)} (docs/templates.md)")
    return t


def check_adjacency(t: Template) -> None:
    """The 1-rings in CSR form as the attention reads them (as the browser checks them: src/template/face-template.ts):
    offsets from 0 to the index count, never decreasing; each ring ascending, without its vertex; symmetric."""
    off, idx, n = t.adj_offsets, t.adj_indices, t.num_vertices
    if off[0] != 0 or off[-1] != len(idx) or (np.diff(off) < 0).any() or ((idx < 0) | (idx >= n)).any():
        raise TemplateFormatError(f"template {t.id}: adjacencyOffsets must rise from 0 to the index count, indices in range")
    row = np.repeat(np.arange(n), np.diff(off))
    same = row[1:] == row[:-1]
    why = ("a vertex lists itself" if (idx == row).any() else "a ring is not in ascending order" if (idx[1:][same] <= idx[:-1][same]).any()
           else "a ring lists a vertex whose ring lacks it" if not np.isin(idx * n + row, row * n + idx).all() else "")
    if why:
        raise TemplateFormatError(f"template {t.id}: {why} (adjacencyIndices: symmetric, no self loops, ascending)")


def subdivide(t: Template, new_id: str | None = None) -> Template:
    """Midpoint subdivision: every edge gets a vertex, every triangle becomes four. A new vertex joins a
    region when both ends of its edge are in it. (468 -> 1,790 vertices for the MediaPipe face.)"""
    tri = t.triangles
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, inverse = np.unique(edges, axis=0, return_inverse=True)
    n = t.num_vertices
    mid = n + inverse.reshape(3, -1).T                                          # (T, 3) midpoints of edges 01, 12, 20
    verts = np.concatenate([t.vertices, 0.5 * (t.vertices[uniq[:, 0]] + t.vertices[uniq[:, 1]])]).astype(np.float32)
    a, b, c = tri.T
    m01, m12, m20 = mid.T
    new_tri = np.concatenate([np.stack([a, m01, m20], 1), np.stack([m01, b, m12], 1), np.stack([m20, m12, c], 1), np.stack([m01, m12, m20], 1)])
    uvs = None
    if t.uvs is not None:
        uvs = np.concatenate([t.uvs, 0.5 * (t.uvs[uniq[:, 0]] + t.uvs[uniq[:, 1]])]).astype(np.float32)
    regions = {}
    for name, idx in t.regions.items():
        member = np.zeros(n, dtype=bool)
        member[idx] = True
        regions[name] = np.concatenate([idx, n + np.flatnonzero(member[uniq[:, 0]] & member[uniq[:, 1]])])
    return template_from_mesh(new_id or f"{t.id}-subdivided", t.units, verts, new_tri, regions, uvs, {**t.source, "subdivided": "midpoint"})
