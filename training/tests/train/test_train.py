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


def test_content_warp_stretches_each_crop_within_its_range():
    """A single bright band at 20 moves to 20 * f or 20 / f with f in [LO, HI], differently per crop."""
    import numpy as np
    mel = torch.zeros(64, 10, 80)
    mel[..., 20] = 1.0
    out = train.content_warp(mel, np.random.default_rng(0), 1.12, 1.22)
    assert out.shape == mel.shape and torch.equal(mel[..., 20], torch.ones(64, 10))  # the input is left alone
    centres = (out[:, 0] * torch.arange(80)).sum(-1) / out[:, 0].sum(-1)
    factors = centres / 20
    up, down = factors[factors > 1], factors[factors < 1]
    assert len(up) > 10 and len(down) > 10
    assert ((up > 1.10) & (up < 1.24)).all() and ((1 / down > 1.10) & (1 / down < 1.24)).all()
    assert len(set(np.round(factors.numpy(), 3))) > 32


def test_content_warp_changes_only_what_the_content_encoder_hears(trained_run, corpus, tmp_path):
    model, _ = train.load_checkpoint(trained_run / "final.pt", corpus.template)
    mel = torch.randn(1, 120, 80)
    idx = torch.arange(10)[None] * 3 + 40
    tpl = torch.zeros(1, corpus.template.num_vertices, 3)
    with torch.no_grad():
        plain = model(mel, idx, tpl)
        same = model(mel, idx, tpl, content_mel=mel)
        heard = model(mel, idx, tpl, content_mel=train.content_warp(mel, __import__("numpy").random.default_rng(1), 1.2, 1.2))
    assert torch.equal(plain["offsets"], same["offsets"])
    assert not torch.allclose(plain["content_logits"], heard["content_logits"])
    out = tmp_path / "warped"
    common = ["--corpus", str(corpus.root), "--out", str(out), "--steps", "2", "--batch-clips", "2", "--frames", "4",
              "--content-warp", "1.1", "1.2"]
    assert train.main(common + ["--frontend", str(trained_run / "final.pt"), "--init", str(trained_run / "final.pt")]) == 0
    try:
        train.main(common)
    except SystemExit as e:
        assert e.code == 2  # argparse: needs a frozen --frontend
    else:
        raise AssertionError("--content-warp without a frozen front-end was accepted")


def test_init_from_a_model_without_the_shape_input_adds_it_at_zero(corpus, tmp_path):
    old, new = tmp_path / "old", tmp_path / "new"
    common = ["--corpus", str(corpus.root), "--batch-clips", "2", "--frames", "4", "--steps", "1"]
    assert train.main(common + ["--out", str(old)]) == 0
    assert train.main(common + ["--out", str(new), "--init", str(old / "final.pt"), "--lr", "1e-12", "--template-input"]) == 0
    a, b = (torch.load(p / "final.pt", weights_only=False) for p in (old, new))
    assert not a["model_config"]["template_input"] and b["model_config"]["template_input"]
    assert "hierarchical.shape_in.weight" not in a["model"] and "reference" in b["model"]
    assert b["model"]["hierarchical.shape_in.weight"].abs().max() < 1e-6


def test_training_with_the_lip_closure_in_the_loss_records_its_reference(corpus, tmp_path):
    """--lip-closure trains with each face's closure retargeted (model/lip_closure.py) and keeps the reference gap,
    which evaluate, closure_causes and export read; the calibration command replaces it later."""
    out = tmp_path / "lips"
    assert train.main(["--corpus", str(corpus.root), "--out", str(out), "--steps", "2", "--batch-clips", "2", "--frames", "4",
                       "--lip-closure", "5.5"]) == 0
    ck = torch.load(out / "final.pt", weights_only=False)
    assert ck["lip_closure"]["reference_gap_mm"] == 5.5


def test_the_front_end_wins_over_the_initial_weights(trained_run, corpus, tmp_path):
    """With --frontend and --init from different models, the content encoder is the front-end's (it was the init's)."""
    other = tmp_path / "other"
    assert train.main(["--corpus", str(corpus.root), "--out", str(other), "--steps", "1", "--batch-clips", "2", "--frames", "4",
                       "--seed", "7"]) == 0
    fe = torch.load(other / "final.pt", weights_only=False)["model"]
    init = torch.load(trained_run / "final.pt", weights_only=False)["model"]
    assert any(not torch.equal(fe[k], init[k]) for k in fe if k.startswith("content."))
    out = tmp_path / "tuned"
    assert train.main(["--corpus", str(corpus.root), "--out", str(out), "--steps", "2", "--batch-clips", "2", "--frames", "4",
                       "--frontend", str(other / "final.pt"), "--init", str(trained_run / "final.pt")]) == 0
    tuned = torch.load(out / "final.pt", weights_only=False)["model"]
    assert all(torch.equal(tuned[k], fe[k]) for k in fe if k.startswith("content."))
