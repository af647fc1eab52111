"""The demo's sample clips: the committed ones match their index, and the writer round-trips the ground truth."""
import hashlib
import json
from pathlib import Path

import numpy as np

from talkingface import samples
from talkingface.data.datasets import open_dataset
from talkingface.paths import MODELS_DIR


def read_gt(path: Path, n: int, frames: int):
    b = path.read_bytes()
    tpl = np.frombuffer(b, "<f4", n * 3).reshape(n, 3)
    off = np.frombuffer(b, "<i2", frames * n * 3, offset=n * 12).reshape(frames, n, 3)
    pose = np.frombuffer(b, "<f4", frames * 6, offset=n * 12 + frames * n * 6).reshape(frames, 6)
    assert len(b) == n * 12 + frames * n * 6 + frames * 24
    return tpl, off, pose


def test_committed_samples_match_their_index():
    index = json.loads((MODELS_DIR / "samples" / "index.json").read_text())
    assert index["clips"], "no sample clips"
    for c in index["clips"]:
        for field in ("audio", "ground_truth"):
            assert hashlib.sha256((MODELS_DIR / "samples" / c[field]).read_bytes()).hexdigest() == c[f"{field}_sha256"], c[field]
        read_gt(MODELS_DIR / "samples" / c["ground_truth"], c["vertices"], c["frames"])


def test_samples_round_trip_the_ground_truth(corpus, tmp_path):
    ds = open_dataset(corpus.root)
    key = ds.keys("test")[0]
    c = samples.write_sample(ds, key, tmp_path)
    clip = ds.load(key)
    tpl, off, pose = read_gt(tmp_path / c["ground_truth"], c["vertices"], c["frames"])
    np.testing.assert_array_equal(tpl, clip.template)
    np.testing.assert_allclose(tpl[None] + off / 1000.0 / ds.mm_per_unit, clip.vertices, atol=0.6e-3 / ds.mm_per_unit)
    np.testing.assert_array_equal(pose, clip.pose)
