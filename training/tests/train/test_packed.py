"""Training clips packed into one file (train/packed.py) for a GPU machine without the dataset: the same clips
back, the faces within the compression's stated error, and a packed run training as a run on the dataset does."""
import json
import os
import subprocess
import sys
import tarfile

import numpy as np
import pytest
import torch

from talkingface.data.datasets import DatasetError
from talkingface.features import AudioConfig
from talkingface.paths import REPO_ROOT as REPO
from talkingface.train import packed, train
from talkingface.train.data import prepare


@pytest.fixture(scope="module")
def packed_file(corpus, tmp_path_factory):
    out = tmp_path_factory.mktemp("packed") / "train.npz"
    assert packed.main(["--corpus", str(corpus.root), "--out", str(out)]) == 0
    return out


def test_the_clips_come_back(corpus, packed_file):
    audio = AudioConfig(fps=int(corpus.fps))
    clips, template, template_path, fps = packed.load(packed_file)
    keys = corpus.keys("train")
    assert [c.key for c in clips] == keys and template.id == corpus.template.id and fps == corpus.fps
    assert template_path == str(corpus.root / "template" / "template.json")
    for c in clips[:5]:
        ref = prepare(corpus, c.key, audio)
        np.testing.assert_array_equal(c.phones, ref.phones)
        np.testing.assert_array_equal(c.template, ref.template)
        np.testing.assert_allclose(c.pose, ref.pose, rtol=0, atol=1e-6)
        np.testing.assert_allclose(c.mel, ref.mel, rtol=2e-3, atol=2e-3)        # float16
        assert np.abs(c.vertices - ref.vertices).max() < 0.01                    # mm
        assert (c.source, c.voice) == (ref.source, ref.voice)


def test_the_stated_error_is_the_error(corpus, tmp_path):
    """Few directions: the error pack reports is what load gives back."""
    audio = AudioConfig(fps=int(corpus.fps))
    clips = [prepare(corpus, k, audio) for k in corpus.keys("train")[:6]]
    err = packed.pack(clips, corpus.template, "t.json", corpus.fps, tmp_path / "p.npz", components=3)
    back, *_ = packed.load(tmp_path / "p.npz")
    worst = max(np.sqrt(((b.vertices - c.vertices) ** 2).sum(-1)).max() for b, c in zip(back, clips))
    assert err["components"] == 3 and err["max"] > 0.01
    assert worst == pytest.approx(err["max"], rel=1e-3)


def test_a_packed_run_trains_as_a_run_on_the_dataset(corpus, packed_file, tmp_path):
    common = ["--steps", "2", "--batch-clips", "2", "--frames", "4", "--seed", "3"]
    assert train.main(["--corpus", str(corpus.root), "--out", str(tmp_path / "a")] + common) == 0
    assert train.main(["--packed", str(packed_file), "--out", str(tmp_path / "b"), "--device", "cpu"] + common) == 0
    a, b = (torch.load(tmp_path / r / "final.pt", weights_only=False) for r in "ab")
    assert a["template_path"] == b["template_path"] and a["template_id"] == b["template_id"]
    # The same losses on the same crops (the Mel in float16 moves them in the fourth digit), and the same weights
    # within a fraction of the two Adam steps' size (1e-3 each), where wrong data would move them apart by up to 2e-3.
    la, lb = (json.loads((tmp_path / r / "train_log.json").read_text())["last_100"] for r in "ab")
    assert lb == pytest.approx(la, rel=2e-3)
    for k, v in a["model"].items():
        torch.testing.assert_close(b["model"][k], v, rtol=0, atol=5e-4)
    model, _ = train.load_checkpoint(tmp_path / "b" / "final.pt")                # found by its recorded template path
    assert model.num_vertices == corpus.template.num_vertices


def test_bad_packed_files_are_named(packed_file, tmp_path, capsys):
    with pytest.raises(DatasetError, match="does not exist"):
        packed.load(tmp_path / "none.npz")
    with pytest.raises(DatasetError, match="is a folder"):
        packed.load(tmp_path)
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    np.save(tmp_path / "bare.npy", np.zeros(3))
    (tmp_path / "meta.json").write_text("{}")
    (tmp_path / "cut.npz").write_bytes(packed_file.read_bytes()[:300_000])
    for name in ("other.npz", "bare.npy", "meta.json", "cut.npz"):  # another .npz, a bare array, not numpy's, cut short
        with pytest.raises(DatasetError, match="not a file of packed clips"):
            packed.load(tmp_path / name)
    with pytest.raises(SystemExit):
        train.main(["--packed", str(tmp_path / "other.npz"), "--corpus", "x", "--out", str(tmp_path / "r"), "--steps", "1"])
    assert "not allowed with argument" in capsys.readouterr().err


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has CUDA")
def test_cuda_is_refused_where_there_is_none(packed_file, tmp_path, capsys):
    with pytest.raises(SystemExit):
        train.main(["--packed", str(packed_file), "--out", str(tmp_path / "r"), "--steps", "1", "--device", "cuda"])
    assert "sees no CUDA device" in capsys.readouterr().err


def test_the_gpu_script_trains_its_recipes(packed_file, tmp_path):
    """scripts/face-gpu.sh on the CPU: each recipe's model (without the optimiser) and log come back in a tar."""
    recipes = tmp_path / "recipes.txt"
    # the last line without its newline; run from another folder, with a relative OUT
    recipes.write_text("# a comment\nwrong --no-such-option\n\nquick --batch-clips 2 --frames 4   # trailing comment")
    env = {**os.environ, "DEVICE": "cpu", "PYTHON": sys.executable, "OMP_NUM_THREADS": "1"}
    run = subprocess.run([str(REPO / "scripts" / "face-gpu.sh"), str(packed_file), "out", "0.02", str(recipes)],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 1 and "no model from: wrong" in run.stderr, run.stderr
    with tarfile.open(tmp_path / "out" / "wrong.tar") as tar:
        assert tar.getnames() == ["wrong.log"]
    with tarfile.open(tmp_path / "out" / "quick.tar") as tar:
        names = tar.getnames()
        tar.extractall(tmp_path / "x", filter="data")
    assert "quick/model.pt" in names and "quick.log" in names and "quick/final.pt" not in names
    ck = torch.load(tmp_path / "x" / "quick" / "model.pt", weights_only=False)
    assert ck["step"] >= 1 and "optimizer" not in ck and ck["args"]["device"] == "cpu"
    bad = subprocess.run([str(REPO / "scripts" / "face-gpu.sh"), str(packed_file), str(tmp_path / "o2"), "1"], cwd=REPO,
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "usage" in bad.stderr
