"""The face template I (Eq. 2): neutral vertices, triangles, 1-ring adjacency, named regions.

Reads the repository's template format (template.json + template.bin, written by
scripts/extract-template.ts and scripts/import-template.ts) and, with a masks
file, a user's own OBJ or PLY mesh (a FLAME head from VOCASET, a Multiface
mesh). Nothing here assumes a vertex count.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

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
        m = json.loads(Path(masks).read_text())
        verts, tris, uvs = read_obj(path) if suffix == ".obj" else read_ply(path)
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
    missing = [r for r in REQUIRED_REGIONS if t.regions.get(r, np.empty(0)).size == 0]
    if missing:
        raise TemplateFormatError(f"template {t.id} lacks the regions {', '.join(missing)} (docs/templates.md)")
    return t


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    verts, tex, tris = [], [], []
    uv_of_vertex: dict[int, int] = {}
    for line_no, line in enumerate(Path(path).read_text().splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            verts.append([float(x) for x in parts[1:4]])
        elif parts[0] == "vt":
            tex.append([float(x) for x in parts[1:3]])
        elif parts[0] == "f":
            corners = []
            for c in parts[1:]:
                fields = c.split("/")
                v = _obj_index(int(fields[0]), len(verts), path, line_no)
                if len(fields) > 1 and fields[1]:
                    uv_of_vertex.setdefault(v, _obj_index(int(fields[1]), len(tex), path, line_no))
                corners.append(v)
            tris.extend([corners[0], corners[k], corners[k + 1]] for k in range(1, len(corners) - 1))
    if not verts or not tris:
        raise TemplateFormatError(f"{path}: no vertices or no faces")
    uvs = None
    if len(uv_of_vertex) == len(verts):
        uvs = np.array([tex[uv_of_vertex[v]] for v in range(len(verts))], dtype=np.float32)
    return np.array(verts, dtype=np.float32), np.array(tris, dtype=np.int64), uvs


def _obj_index(i: int, count: int, path: Path, line_no: int) -> int:
    idx = count + i if i < 0 else i - 1
    if not 0 <= idx < count:
        raise TemplateFormatError(f"{path} line {line_no}: index {i} refers to no vertex")
    return idx


_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def read_ply(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    data = Path(path).read_bytes()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise TemplateFormatError(f"{path}: not a PLY file")
    body_start = data.index(b"\n", end) + 1
    fmt, elements = None, []
    for line in data[:end].decode("ascii").splitlines()[1:]:
        p = line.split()
        if not p:
            continue
        if p[0] == "format":
            fmt = p[1]
        elif p[0] == "element":
            elements.append((p[1], int(p[2]), []))
        elif p[0] == "property":
            elements[-1][2].append((p[4], p[3], p[2]) if p[1] == "list" else (p[2], p[1], None))
    if fmt not in ("ascii", "binary_little_endian"):
        raise TemplateFormatError(f"{path}: PLY format {fmt!r} is not supported (use ascii or binary_little_endian)")
    rows = _ply_ascii(data[body_start:], elements) if fmt == "ascii" else _ply_binary(data, body_start, elements)
    if "vertex" not in rows or "face" not in rows:
        raise TemplateFormatError(f"{path}: PLY needs vertex and face elements")
    vrows = rows["vertex"]
    verts = np.array([[r["x"], r["y"], r["z"]] for r in vrows], dtype=np.float32)
    uvs = None
    if vrows and ("s" in vrows[0] or "u" in vrows[0]):
        uvs = np.array([[r.get("s", r.get("u")), r.get("t", r.get("v"))] for r in vrows], dtype=np.float32)
    tris = []
    for r in rows["face"]:
        idx = r.get("vertex_indices", r.get("vertex_index"))
        tris.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    return verts, np.array(tris, dtype=np.int64), uvs


def _ply_ascii(body: bytes, elements) -> dict[str, list[dict]]:
    tokens = body.split()
    pos, out = 0, {}
    for name, count, props in elements:
        rows = []
        for _ in range(count):
            row = {}
            for pname, ptype, count_type in props:
                if count_type:
                    n = int(tokens[pos]); pos += 1
                    row[pname] = [int(x) for x in tokens[pos : pos + n]]; pos += n
                else:
                    row[pname] = float(tokens[pos]); pos += 1
            rows.append(row)
        out[name] = rows
    return out


def _ply_binary(data: bytes, pos: int, elements) -> dict[str, list[dict]]:
    out = {}
    for name, count, props in elements:
        rows = []
        for _ in range(count):
            row = {}
            for pname, ptype, count_type in props:
                if count_type:
                    n = int(np.frombuffer(data, "<" + _PLY_TYPES[count_type], 1, pos)[0])
                    pos += np.dtype(_PLY_TYPES[count_type]).itemsize
                    row[pname] = np.frombuffer(data, "<" + _PLY_TYPES[ptype], n, pos).tolist()
                    pos += n * np.dtype(_PLY_TYPES[ptype]).itemsize
                else:
                    row[pname] = float(np.frombuffer(data, "<" + _PLY_TYPES[ptype], 1, pos)[0])
                    pos += np.dtype(_PLY_TYPES[ptype]).itemsize
            rows.append(row)
        out[name] = rows
    return out


def subdivide(t: Template, new_id: str | None = None) -> Template:
    """Midpoint subdivision: every edge gets a vertex, every triangle becomes four. A new vertex joins a
    region when both ends of its edge are in it. (468 -> 1,788 vertices for the MediaPipe face.)"""
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
