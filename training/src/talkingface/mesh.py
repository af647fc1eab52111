"""Reading a user's own face mesh: Wavefront OBJ, and PLY in ASCII or binary little-endian.

-> (vertices (N, 3) float32, triangles (T, 3) int64, per-vertex uvs (N, 2) float32 or None); polygons are
fanned into triangles. template.py turns a mesh and its region masks into a Template.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

Mesh = tuple[np.ndarray, np.ndarray, "np.ndarray | None"]


class MeshFormatError(ValueError):
    """A mesh file is not OBJ or PLY as this reader knows them; the message says what is wrong and where."""


def read_obj(path: Path) -> Mesh:
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
        raise MeshFormatError(f"{path}: no vertices or no faces")
    uvs = None
    if len(uv_of_vertex) == len(verts):
        uvs = np.array([tex[uv_of_vertex[v]] for v in range(len(verts))], dtype=np.float32)
    return np.array(verts, dtype=np.float32), np.array(tris, dtype=np.int64), uvs


def _obj_index(i: int, count: int, path: Path, line_no: int) -> int:
    idx = count + i if i < 0 else i - 1
    if not 0 <= idx < count:
        raise MeshFormatError(f"{path} line {line_no}: index {i} refers to no vertex")
    return idx


_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def read_ply(path: Path) -> Mesh:
    data = Path(path).read_bytes()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise MeshFormatError(f"{path}: not a PLY file")
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
        elif p[0] == "property":  # (name, type, count type of a list or None)
            elements[-1][2].append((p[4], p[3], p[2]) if p[1] == "list" else (p[2], p[1], None))
    if fmt not in ("ascii", "binary_little_endian"):
        raise MeshFormatError(f"{path}: PLY format {fmt!r} is not supported (use ascii or binary_little_endian)")
    body = _AsciiBody(data[body_start:]) if fmt == "ascii" else _BinaryBody(data, body_start)
    try:
        rows = _ply_rows(body, elements)
    except (ValueError, IndexError, KeyError) as e:  # a number that is none, a body cut short, a type PLY has not
        raise MeshFormatError(f"{path}: {e}") from e
    if "vertex" not in rows or "face" not in rows:
        raise MeshFormatError(f"{path}: PLY needs vertex and face elements")
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


def _ply_rows(body: "_AsciiBody | _BinaryBody", elements) -> dict[str, list[dict]]:
    """Every element's rows, property by property, whichever encoding `body` reads."""
    out = {}
    for name, count, props in elements:
        rows = []
        for _ in range(count):
            row = {}
            for pname, ptype, count_type in props:
                if count_type:
                    row[pname] = body.items(ptype, body.count(count_type))
                else:
                    row[pname] = body.scalar(ptype)
            rows.append(row)
        out[name] = rows
    return out


class _AsciiBody:
    """An ASCII PLY body: whitespace-separated tokens, read in order."""

    def __init__(self, body: bytes):
        self.tokens, self.pos = body.split(), 0

    def _take(self, n: int) -> list[bytes]:
        out = self.tokens[self.pos : self.pos + n]
        if len(out) < n:
            raise MeshFormatError("the PLY body ends before the counts its header states (cut short?)")
        self.pos += n
        return out

    def count(self, ptype: str) -> int:
        return int(self._take(1)[0])

    def scalar(self, ptype: str) -> float:
        return float(self._take(1)[0])

    def items(self, ptype: str, n: int) -> list:
        kind = int if _PLY_TYPES[ptype][0] in "iu" else float  # (a list of floats: per-face texture coordinates)
        return [kind(x) for x in self._take(n)]


class _BinaryBody:
    """A binary little-endian PLY body: values of the declared types, packed, read in order."""

    def __init__(self, data: bytes, pos: int):
        self.data, self.pos = data, pos

    def _take(self, ptype: str, n: int) -> np.ndarray:
        dtype = np.dtype("<" + _PLY_TYPES[ptype])
        out = np.frombuffer(self.data, dtype, n, self.pos)
        self.pos += n * dtype.itemsize
        return out

    def count(self, ptype: str) -> int:
        return int(self._take(ptype, 1)[0])

    def scalar(self, ptype: str) -> float:
        return float(self._take(ptype, 1)[0])

    def items(self, ptype: str, n: int) -> list:
        return self._take(ptype, n).tolist()
