"""The command lines on a user's mistakes (talkingface.cli and each entry point's checks): one line naming the problem,
no silently wrong output, no lost work, nothing of the user's deleted."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

import talkingface
from talkingface import export, samples
from talkingface.cli import CheckpointError, read_checkpoint
from talkingface.frontend import train as fe_train
from talkingface.model import head_motion
from talkingface.train import ablation, evaluate, train

SRC = str(Path(talkingface.__file__).resolve().parents[1])


def run_module(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *args], env={"PYTHONPATH": SRC, "PATH": "/usr/bin:/bin"},
                          capture_output=True, text=True, timeout=120)


def test_a_file_that_is_not_a_face_checkpoint_is_said_in_one_line(trained_run, tmp_path):
    text, cut, frontend = tmp_path / "text.pt", tmp_path / "cut.pt", tmp_path / "frontend.pt"
    text.write_text("not a checkpoint\n")
    cut.write_bytes((trained_run / "final.pt").read_bytes()[:4000])
    torch.save({"content": {}, "model_config": {}}, frontend)
    for path, said in [(text, "is not a PyTorch checkpoint"), (cut, "is not a PyTorch checkpoint, or it is cut short"),
                       (frontend, "is a speech front-end"), (tmp_path / "nowhere.pt", "does not exist"), (tmp_path, "is a folder")]:
        with pytest.raises(CheckpointError, match=said):
            read_checkpoint(path)
    assert read_checkpoint(frontend, kind="any")["content"] == {}
    res = run_module("talkingface.export", "--checkpoint", str(frontend), "--out", str(tmp_path / "x"))
    assert res.returncode == 2 and res.stderr.strip().splitlines() == [f"error: {frontend} is a speech front-end (frontend.train's; "
                                                                      "it goes to --frontend or --init of frontend.train): give a face "
                                                                      "model's checkpoint (train.train's OUT/final.pt, or models/checkpoint.pt)"]


@pytest.mark.parametrize("budget", [["--steps", "0"], ["--steps", "-1"], ["--minutes", "0"], ["--minutes", "-1"],
                                    ["--steps", "2", "--checkpoint-every", "0"], ["--steps", "2", "--batch-clips", "0"]])
def test_train_refuses_an_empty_or_negative_budget(corpus, tmp_path, budget):
    with pytest.raises(SystemExit) as e:
        train.main(["--corpus", str(corpus.root), "--out", str(tmp_path / "run"), *budget])
    assert e.value.code == 2
    assert not (tmp_path / "run" / "final.pt").exists()


def test_train_keeps_a_run_it_is_not_told_to_resume(corpus, trained_run):
    before = (trained_run / "final.pt").read_bytes()
    with pytest.raises(SystemExit):
        train.main(["--corpus", str(corpus.root), "--out", str(trained_run), "--steps", "1", "--batch-clips", "2", "--frames", "4"])
    assert (trained_run / "final.pt").read_bytes() == before


def test_ctrl_c_saves_the_checkpoint_and_resume_continues(corpus, tmp_path, monkeypatch):
    out = tmp_path / "run"
    common = ["--corpus", str(corpus.root), "--out", str(out), "--batch-clips", "2", "--frames", "4", "--checkpoint-every", "100"]
    calls = {"n": 0}
    real = train.sample_batch

    def interrupted(*a, **k):
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(train, "sample_batch", interrupted)
    assert train.main([*common, "--steps", "10"]) == 130
    assert torch.load(out / "checkpoint.pt", weights_only=False)["step"] == 3  # three steps done, none lost
    monkeypatch.setattr(train, "sample_batch", real)
    assert train.main([*common, "--steps", "5", "--resume"]) == 0
    assert torch.load(out / "final.pt", weights_only=False)["step"] == 5


def test_the_front_end_trainer_refuses_an_empty_budget(tmp_path):
    for budget in (["--steps", "0"], ["--minutes", "-1"], ["--batch", "0"]):
        with pytest.raises(SystemExit) as e:
            fe_train.main(["--speech", str(tmp_path), "--out", str(tmp_path / "fe"), *budget])
        assert e.value.code == 2


def test_the_ablation_trains_again_for_another_corpus(corpus, tmp_path):
    runs, out = tmp_path / "runs", tmp_path / "results"
    argv = ["--corpus", str(corpus.root), "--steps", "1", "--rows", "G+MLP", "--runs", str(runs), "--out", str(out),
            "--batch-clips", "2", "--frames", "4"]
    ablation.main(argv)
    final = runs / "G-MLP-s0" / "final.pt"
    ck = torch.load(final, weights_only=False)
    ck["args"]["corpus"] = "another/corpus"  # as if it had been trained there
    torch.save(ck, final)
    ablation.main(argv)
    assert torch.load(final, weights_only=False)["args"]["corpus"] == str(corpus.root)
    assert json.loads((runs / "G-MLP-s0" / "ablation_eval.json").read_text())["corpus"] == str(corpus.root)


def test_a_head_motion_cache_of_another_checkpoint_is_refused(corpus, trained_run, tmp_path):
    cache = tmp_path / "hm.npz"
    np.savez(cache, clips=0, speakers=np.array([]), sources=np.array([]), against_mean=False, made_from="elsewhere")
    with pytest.raises(SystemExit, match="made from another corpus or checkpoint"):
        head_motion.main(["--corpus", str(corpus.root), "--checkpoint", str(trained_run / "final.pt"), "--out", str(tmp_path / "hm.pt"),
                          "--cache", str(cache)])


def test_samples_replace_their_own_files_only(corpus, tmp_path):
    out = tmp_path / "samples"
    out.mkdir()
    (out / "my-recording.wav").write_bytes(b"RIFF mine")
    samples.main(["--corpus", str(corpus.root), "--out", str(out), "--count", "1"])
    first = json.loads((out / "index.json").read_text())["clips"][0]["audio"]
    samples.main(["--corpus", str(corpus.root), "--out", str(out), "--count", "1"])
    assert (out / "my-recording.wav").read_bytes() == b"RIFF mine"
    assert (out / first).exists()
    with pytest.raises(SystemExit):
        samples.main(["--corpus", str(corpus.root), "--out", str(out), "--count", "0"])


def test_evaluate_checks_its_output_before_the_work(corpus, trained_run, tmp_path):
    blocker = tmp_path / "afile"
    blocker.write_text("")
    with pytest.raises(SystemExit) as e:
        evaluate.main(["--corpus", str(corpus.root), "--checkpoint", str(trained_run / "final.pt"), "--out", str(blocker / "x.json")])
    assert e.value.code == 2


def test_an_export_elsewhere_carries_the_face_template(trained_run, tmp_path):
    out = tmp_path / "exported"
    assert export.main(["--checkpoint", str(trained_run / "final.pt"), "--out", str(out)]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    there = out / manifest["template"]["path"]
    assert json.loads(there.read_text())["id"] == manifest["template"]["id"]
    assert there.with_suffix(".bin").exists()


def test_an_export_into_another_models_folder_is_refused_in_one_line(trained_run, tmp_path):
    out = tmp_path / "exported"
    (out / "template").mkdir(parents=True)
    (out / "template" / "template.json").write_text(json.dumps({"id": "someone-else"}))
    result = run_module("talkingface.export", "--checkpoint", str(trained_run / "final.pt"), "--out", str(out))
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "is template 'someone-else', but the model was trained on" in result.stderr


def test_corpus_build_refuses_nonsense_counts(tmp_path):
    for bad in (["--sentences", "0"], ["--sentences", "-1"], ["--subjects", "1", "0", "0"], ["--workers", "0"]):
        res = run_module("talkingface.corpus", "build", "--preset", "small", "--out", str(tmp_path / "c"), *bad)
        assert res.returncode == 2, bad
        assert res.stderr.strip().startswith("error: ") and len(res.stderr.strip().splitlines()) == 1, res.stderr
        assert not (tmp_path / "c").exists()


def test_a_clip_missing_its_alignment_or_pose_is_an_error_not_silence(corpus, tmp_path):
    from talkingface.data.datasets import DatasetError, open_dataset
    for folder in ("alignments", "poses_npy", "vertices_npy"):
        copy = tmp_path / folder
        shutil.copytree(corpus.root, copy)
        key = open_dataset(copy).keys("test")[0]
        next((copy / folder).glob(f"{key}.*")).unlink()
        with pytest.raises(DatasetError, match=f"clip {key}: missing {folder}/{key}"):
            open_dataset(copy).load(key)


@pytest.mark.parametrize("module", ["talkingface.train.evaluate", "talkingface.model.lip_closure", "talkingface.model.head_motion",
                                    "talkingface.train.closure_causes", "talkingface.train.paired", "talkingface.frontend.measure"])
def test_the_measuring_commands_take_a_real_datasets_template(module):
    res = run_module(module, "--help")
    assert res.returncode == 0 and "--template" in res.stdout and "--masks" in res.stdout


def test_dataset_of_opens_the_corpus_with_the_template_named(corpus):
    import argparse
    from talkingface.cli import dataset_of
    ds = dataset_of(argparse.Namespace(corpus=str(corpus.root), template=str(corpus.root / "template" / "template.json"), masks=None))
    assert ds.template.id == corpus.template.id and ds.keys("test") == corpus.keys("test")


def test_a_file_that_is_not_a_speech_bank_is_said_so(tmp_path):
    from talkingface.data.datasets import DatasetError
    from talkingface.frontend.bank import unpack
    other = tmp_path / "other.npz"
    np.savez(other, something=np.zeros(3))
    with pytest.raises(DatasetError, match="is not a packed speech bank"):
        unpack(other)


def test_evaluate_says_what_its_figures_are_measured_against_without_alignments_or_poses(corpus, trained_run, tmp_path):
    copy = tmp_path / "no-alignments"
    shutil.copytree(corpus.root, copy)
    shutil.rmtree(copy / "alignments")
    out = tmp_path / "eval.json"
    assert evaluate.main(["--corpus", str(copy), "--checkpoint", str(trained_run / "final.pt"), "--out", str(out), "--head-draws", "1"]) == 0
    assert json.loads(out.read_text())["missing"] == ["phone alignments"]
    assert "**Note**: the dataset has no phone alignments" in out.with_suffix(".md").read_text()


def test_train_without_alignments_needs_a_front_end(corpus, trained_run, tmp_path, capsys):
    """Real data has no phone alignments: the content encoder would learn silence, so training asks for --frontend."""
    copy = tmp_path / "no-alignments"
    shutil.copytree(corpus.root, copy)
    shutil.rmtree(copy / "alignments")
    with pytest.raises(SystemExit) as e:
        train.main(["--corpus", str(copy), "--out", str(tmp_path / "run"), "--steps", "1"])
    assert e.value.code == 2
    assert "has no phone alignments" in capsys.readouterr().err and not (tmp_path / "run" / "final.pt").exists()
    assert train.main(["--corpus", str(copy), "--out", str(tmp_path / "run"), "--steps", "1",
                       "--frontend", str(trained_run / "final.pt")]) == 0
