"""Is a models/ folder what the exporter writes? Serialised weights by hash, computed outputs by value.

The exported files are of two kinds:
- serialised weights (the ONNX graphs, gava.safetensors): the same checkpoint gives the same bytes, so they are
  compared by SHA-256 and any difference, even one weight by one bit, fails;
- computed outputs (the fixtures: log-Mel, logits, tokens, vertices of a short clip): floating-point results
  that differ in their last bits between library versions and CPUs (another BLAS kernel sums in another order),
  so they are compared by value, tensor by tensor, within FIXTURE_TOLERANCE of the tensor's own magnitude.

The manifest keeps every file's hash either way: the browser verifies what it loads against it.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .safetensors import read_safetensors, sha256

COMPUTED_FILES = ("fixtures",)  # manifest["files"] entries holding computed outputs, compared by value
# Largest allowed |committed - fresh| as a fraction of the tensor's largest magnitude. A last-bit float32 difference
# (2^-24 relative) carried through the model's few layers stays below 1e-6; a changed weight moves outputs by
# far more than 1e-4 (the test that changes one weight by 1% of its size sees about 1e-2).
FIXTURE_TOLERANCE = 1e-4


@dataclass
class TensorDiff:
    name: str
    max_abs: float    # largest |committed - fresh|
    scale: float      # largest |fresh|: the tolerance is relative to it
    ok: bool

    def __str__(self) -> str:
        rel = self.max_abs / self.scale if self.scale else float(self.max_abs > 0)
        return f"{self.name}: max |diff| {self.max_abs:.3g} ({rel:.2g} of its scale {self.scale:.3g}){'' if self.ok else '  <- over tolerance'}"


def compare_tensors(committed: dict[str, np.ndarray], fresh: dict[str, np.ndarray],
                    tolerance: float = FIXTURE_TOLERANCE) -> tuple[list[str], list[TensorDiff]]:
    """Problems (missing tensors, shapes, dtypes) and each common tensor's largest difference."""
    problems = []
    if set(committed) != set(fresh):
        problems.append(f"tensors differ: only committed {sorted(set(committed) - set(fresh))}, "
                        f"only fresh {sorted(set(fresh) - set(committed))}")
    diffs = []
    for name in sorted(set(committed) & set(fresh)):
        a, b = committed[name], fresh[name]
        if a.shape != b.shape or a.dtype != b.dtype:
            problems.append(f"{name}: committed {a.dtype}{list(a.shape)}, fresh {b.dtype}{list(b.shape)}")
            continue
        if not np.issubdtype(b.dtype, np.floating):  # indices: exact
            diffs.append(TensorDiff(name, float(np.abs(a.astype(np.int64) - b.astype(np.int64)).max(initial=0)), 0.0,
                                    bool(np.array_equal(a, b))))
            continue
        scale = float(np.abs(b).max(initial=0.0))
        max_abs = float(np.abs(a.astype(np.float64) - b).max(initial=0.0))
        finite = bool(np.isfinite(a).all() and np.isfinite(b).all())
        diffs.append(TensorDiff(name, max_abs, scale, finite and max_abs <= tolerance * max(scale, 1e-12)))
    return problems, diffs


def compare_exports(committed_dir: Path, fresh_dir: Path) -> tuple[list[str], list[TensorDiff]]:
    """What differs between a committed export and a fresh one of the same checkpoint: a list of problems
    (empty when they agree) and every computed tensor's largest difference, for the report."""
    old = json.loads((committed_dir / "manifest.json").read_text())
    new = json.loads((fresh_dir / "manifest.json").read_text())
    problems = []
    for name, path in old["files"].items():  # the committed files are the ones the manifest names
        if sha256(committed_dir / path) != old["sha256"][name]:
            problems.append(f"models/{path} does not match its manifest hash (changed by hand?)")
    for name in sorted(set(old["sha256"]) | set(new["sha256"])):
        if name not in COMPUTED_FILES and old["sha256"].get(name) != new["sha256"].get(name):
            problems.append(f"{name} ({new['files'].get(name, old['files'].get(name))}): serialised weights differ "
                            "from what the exporter writes")
    strip = lambda m: {**m, "sha256": {k: v for k, v in m["sha256"].items() if k not in COMPUTED_FILES}}
    if strip(old) != strip(new):
        keys = [k for k in set(old) | set(new) if strip(old).get(k) != strip(new).get(k)]
        problems.append(f"manifest.json differs in {sorted(keys)}")
    diffs: list[TensorDiff] = []
    for name in COMPUTED_FILES:
        p, d = compare_tensors(read_safetensors(committed_dir / old["files"][name]), read_safetensors(fresh_dir / new["files"][name]))
        problems += [f"{name}: {x}" for x in p] + [f"{name}: {x}" for x in d if not x.ok]
        diffs += d
    return problems, diffs
