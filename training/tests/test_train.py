"""Training, resuming, evaluating and distributed training on the small corpus (a few steps each)."""
import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch

from talkingface.train import evaluate, train

SRC = str(Path(__file__).resolve().parents[1] / "src")


def test_train_resume_and_evaluate(corpus, tmp_path):
    out = tmp_path / "run"
    common = ["--corpus", str(corpus.root), "--out", str(out), "--batch-clips", "2", "--frames", "4", "--checkpoint-every", "2"]
    assert train.main(common + ["--steps", "3"]) == 0
    ck = torch.load(out / "checkpoint.pt", weights_only=False)
    assert ck["step"] == 3 and ck["model_config"]["decoder"] == "GAVA" and ck["template_id"] == corpus.template.id
    assert train.main(common + ["--steps", "5", "--resume"]) == 0
    ck = torch.load(out / "final.pt", weights_only=False)
    assert ck["step"] == 5
    model, _ = train.load_checkpoint(out / "final.pt", corpus.template)
    res = evaluate.evaluate(model, corpus, "test")
    for key in ("E_vl", "E_ve", "FDD", "AFDD", "pose_error_deg", "pose_jitter_deg"):
        assert key in res["all"]
    assert res["all"]["clips"] == len(corpus.keys("test"))


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


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_ablation_driver_writes_the_table(corpus, tmp_path, jobs):
    import json
    from talkingface.train import ablation
    out = tmp_path / "results"
    ablation.main(["--corpus", str(corpus.root), "--steps", "1", "--rows", "G+MLP", "LG+GAVA", "--runs", str(tmp_path / "runs"),
                   "--out", str(out), "--batch-clips", "2", "--frames", "4", "--jobs", jobs])
    table = json.loads((out / "ablation.json").read_text())
    for row in ("G+MLP", "LG+GAVA"):
        assert set(("E_vl", "E_ve", "FDD", "AFDD")) <= set(table[row])
        assert all(isinstance(table[row][k], float) for k in ("E_vl", "E_ve", "FDD", "AFDD"))
    assert "cannot be judged yet" in (out / "ablation.md").read_text()


def test_silence_crops_target_each_subjects_closed_rest_face(corpus):
    import numpy as np
    from talkingface.corpus.checks import contour_gap
    from talkingface.model.config import ModelConfig
    from talkingface.train.data import attach_rest_faces, prepare, sample_batch
    clips = [prepare(corpus, k) for k in corpus.keys("train")]
    r = corpus.template.regions
    gaps = attach_rest_faces(clips, corpus.template)
    # One rest face per subject; it is one of that subject's own frames, and the most closed one among
    # its silence frames (so no more open than any silence-labelled frame with open eyes).
    assert len(gaps) == len({c.template.tobytes() for c in clips})
    for c in clips:
        assert any(np.array_equal(c.rest, v) for d in clips if d.template.tobytes() == c.template.tobytes() for v in d.vertices)
    all_gaps = np.concatenate([contour_gap(c.vertices, r["lips_inner_upper"], r["lips_inner_lower"]) for c in clips])
    assert max(gaps.values()) < np.median(all_gaps)
    cfg = ModelConfig()
    rng = np.random.default_rng(0)
    b = sample_batch(clips, rng, 8, 4, cfg, silence=1.0)
    assert torch.all(b.pose == 0)
    assert torch.all(b.vertices == b.vertices[:, :1])           # a still face ...
    quiet = b.mel.abs().max().item()
    assert quiet < 0.05                                          # ... for silence or faint noise
    from talkingface.corpus.phonemes import PHONE_INDEX, SILENCE
    assert set(b.content_labels.unique().tolist()) <= {-100, PHONE_INDEX[SILENCE]}  # labelled silence
    # And a normal batch is untouched by the option at 0.
    b0 = sample_batch(clips, np.random.default_rng(0), 8, 4, cfg, silence=0.0)
    assert b0.mel.abs().max().item() > 1.0
    with pytest.raises(ValueError, match="attach_rest_faces"):
        for c in clips:
            c.rest = None
        sample_batch(clips, rng, 8, 4, cfg, silence=1.0)
