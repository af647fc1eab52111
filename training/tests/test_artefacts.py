"""Comparing a committed export with a fresh one: a last-bit difference in a fixture passes, a changed weight
or fixture value fails."""
import json
import shutil

import numpy as np

from talkingface.artefacts import compare_exports
from talkingface.safetensors import read_safetensors, sha256, write_safetensors


def copy_export(src, dst):
    shutil.copytree(src, dst)
    return dst


def test_a_last_bit_difference_in_a_fixture_passes(reexported, tmp_path):
    other = copy_export(reexported, tmp_path / "m")
    fx = read_safetensors(other / "fixtures" / "fixtures.safetensors")
    for name, a in fx.items():
        if a.dtype == np.float32:  # every value one ulp away, as another BLAS kernel might compute it
            fx[name] = np.nextafter(a, np.float32(np.inf))
    write_safetensors(other / "fixtures" / "fixtures.safetensors", fx, {"frames": "x"})
    problems, diffs = compare_exports(other, reexported)
    assert [p for p in problems if "does not match its manifest hash" not in p] == []
    assert max(d.max_abs for d in diffs) > 0


def test_a_changed_weight_fails(reexported, tmp_path):
    other = copy_export(reexported, tmp_path / "m")
    w = read_safetensors(other / "gava.safetensors")
    name = sorted(w)[0]
    w[name].flat[0] += 0.01 * np.abs(w[name]).max()
    write_safetensors(other / "gava.safetensors", w)
    manifest = json.loads((other / "manifest.json").read_text())
    manifest["sha256"]["decoder_weights"] = sha256(other / "gava.safetensors")  # even with its hash updated
    (other / "manifest.json").write_text(json.dumps(manifest))
    problems, _ = compare_exports(other, reexported)
    assert any("decoder_weights" in p and "serialised weights differ" in p for p in problems), problems


def test_a_changed_fixture_value_fails(reexported, tmp_path):
    other = copy_export(reexported, tmp_path / "m")
    fx = read_safetensors(other / "fixtures" / "fixtures.safetensors")
    fx["vertices"][0, 0, 0] += 0.05  # mm: far more than rounding, far less than anything visible
    write_safetensors(other / "fixtures" / "fixtures.safetensors", fx)
    problems, _ = compare_exports(other, reexported)
    assert any("vertices" in p and "over tolerance" in p for p in problems), problems
