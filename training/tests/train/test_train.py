"""Training and resuming on the small corpus, and distributed training (a few steps each)."""
import os
import subprocess
import sys
from pathlib import Path

import torch

import talkingface
from talkingface.train import train

SRC = str(Path(talkingface.__file__).resolve().parents[1])


def test_train_and_resume(corpus, tmp_path):
    out = tmp_path / "run"
    common = ["--corpus", str(corpus.root), "--out", str(out), "--batch-clips", "2", "--frames", "4", "--checkpoint-every", "2"]
    assert train.main(common + ["--steps", "3"]) == 0
    ck = torch.load(out / "checkpoint.pt", weights_only=False)
    assert ck["step"] == 3 and ck["model_config"]["decoder"] == "GAVA" and ck["template_id"] == corpus.template.id
    assert train.main(common + ["--steps", "5", "--resume"]) == 0
    ck = torch.load(out / "final.pt", weights_only=False)
    assert ck["step"] == 5
    model, _ = train.load_checkpoint(out / "final.pt", corpus.template)
    assert model.num_vertices == corpus.template.num_vertices


def test_a_checkpoint_names_its_template(trained_run, corpus):
    """Without a template given, a checkpoint loads the one training recorded (the corpus's copy here)."""
    ck = torch.load(trained_run / "final.pt", weights_only=False)
    assert train.checkpoint_template(ck).id == corpus.template.id
    model, _ = train.load_checkpoint(trained_run / "final.pt")
    assert model.num_vertices == corpus.template.num_vertices


def test_two_process_ddp_with_gloo(corpus, tmp_path):
    out = tmp_path / "ddp"
    env = {**os.environ, "PYTHONPATH": SRC, "OMP_NUM_THREADS": "1"}
    cmd = [sys.executable, "-m", "torch.distributed.run", "--nproc-per-node", "2", "--master-port", "29517",
           "-m", "talkingface.train.train", "--corpus", str(corpus.root), "--out", str(out), "--steps", "2",
           "--batch-clips", "2", "--frames", "4", "--threads", "1"]
    res = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    ck = torch.load(out / "final.pt", weights_only=False)
    assert ck["world_size"] == 2 and ck["step"] == 2


def test_a_face_checkpoint_serves_as_the_frozen_front_end(trained_run, corpus, tmp_path):
    """--frontend takes a face checkpoint's content encoder (as the shipped model's fine-tunes do), frozen."""
    fe = train.load_frontend(str(trained_run / "final.pt"))
    ck = torch.load(trained_run / "final.pt", weights_only=False)
    assert fe["model_config"] == ck["model_config"] and fe["step"] == ck["step"]
    assert fe["content"] and all(torch.equal(v, ck["model"][f"content.{k}"]) for k, v in fe["content"].items())
    out = tmp_path / "tuned"
    assert train.main(["--corpus", str(corpus.root), "--out", str(out), "--steps", "2", "--batch-clips", "2", "--frames", "4",
                       "--frontend", str(trained_run / "final.pt"), "--init", str(trained_run / "final.pt")]) == 0
    tuned = torch.load(out / "final.pt", weights_only=False)["model"]
    for k, v in ck["model"].items():
        if k.startswith("content."):
            assert torch.equal(tuned[k], v), k  # frozen: the front-end is exactly the one given


def test_frontend_rejects_other_files(tmp_path):
    bad = tmp_path / "other.pt"
    torch.save({"weights": {}}, bad)
    try:
        train.load_frontend(str(bad))
    except SystemExit as e:
        assert "neither a front-end" in str(e)
    else:
        raise AssertionError("load_frontend accepted a file that is neither")
