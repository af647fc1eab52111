"""More of a newcomer's mistakes with the command lines (after a review of them): outputs that cannot be written are
refused before the work, names numpy would change are reported as written, a SIGTERM keeps a run like Ctrl-C, a
checkpoint of another face is said in one line, and a calibration with nothing to calibrate on writes nothing."""
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest
import torch

import talkingface
from talkingface import export
from talkingface.cli import CheckpointError, npz_path
from talkingface.frontend import soup
from talkingface.model import head_motion, lip_closure
from talkingface.train import evaluate, packed, train

SRC = str(Path(talkingface.__file__).resolve().parents[1])


def test_outputs_that_cannot_be_written_are_refused_before_the_work(corpus, trained_run, tmp_path, capsys):
    ck = str(trained_run / "final.pt")
    common = ["--corpus", str(corpus.root), "--checkpoint", ck]
    folder = tmp_path / "afolder"
    folder.mkdir()
    cases = [
        (lip_closure.main, [*common, "--out", str(tmp_path / "nowhere" / "cal.pt")], "the folder"),
        (lip_closure.main, [*common, "--mouth-gain", "3"], "between 0.5 and 2"),
        (head_motion.main, [*common, "--out", str(tmp_path / "nowhere" / "hm.pt")], "the folder"),
        (head_motion.main, [*common, "--cache", str(folder)], "is a folder"),
        (soup.main, [ck, ck, "--out", str(tmp_path / "nowhere" / "fe.pt")], "the folder"),
        (evaluate.main, [*common, "--out", str(folder)], "is a folder"),
        (evaluate.main, [*common, "--out", str(tmp_path / "res.md")], "the JSON's name"),
        (packed.main, ["--corpus", str(corpus.root), "--out", str(folder)], "is a folder"),
        (train.main, ["--corpus", str(corpus.root), "--out", str(tmp_path / "r"), "--steps", "1", "--device", "gpu"], "not a torch device"),
    ]
    for main, argv, said in cases:
        t0 = time.time()
        with pytest.raises(SystemExit) as e:
            main(argv)
        assert e.value.code == 2 and said in capsys.readouterr().err, (main.__module__, argv)
        assert time.time() - t0 < 5, f"{main.__module__} worked before refusing"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afolder"]  # nothing written


def test_a_name_without_npz_is_reported_and_found_as_numpy_writes_it(corpus, tmp_path, capsys):
    assert npz_path("a/b.pack") == Path("a/b.pack.npz") and npz_path("a/b.npz") == Path("a/b.npz")
    assert packed.main(["--corpus", str(corpus.root), "--out", str(tmp_path / "clips.pack")]) == 0
    assert f"{tmp_path / 'clips.pack.npz'}:" in capsys.readouterr().out
    assert packed.load(tmp_path / "clips.pack.npz")[0]


def test_a_checkpoint_of_another_face_is_one_line(corpus, trained_run, tmp_path):
    other = torch.load(trained_run / "final.pt", weights_only=False)
    other["template_id"] = "other-face-468"
    torch.save(other, tmp_path / "other.pt")
    with pytest.raises(CheckpointError, match="trained on template other-face-468"):
        train.load_checkpoint(tmp_path / "other.pt", corpus.template)
    with pytest.raises(SystemExit, match="--init: .* was trained on template other-face-468"):
        train.main(["--corpus", str(corpus.root), "--out", str(tmp_path / "r"), "--steps", "1", "--init", str(tmp_path / "other.pt")])


def test_head_motion_takes_the_template_named(corpus, trained_run, tmp_path):
    """A checkpoint whose recorded template is gone is read with --template, as the other tools read it."""
    moved = tmp_path / "corpus"
    shutil.copytree(corpus.root, moved)
    ck = torch.load(trained_run / "final.pt", weights_only=False)
    ck["template_path"], ck["template_id"] = str(tmp_path / "gone" / "template.json"), "moved-face"
    torch.save(ck, tmp_path / "ck.pt")
    tpl = moved / "template" / "template.json"
    tpl.write_text(tpl.read_text().replace(f'"{corpus.template.id}"', '"moved-face"'))
    assert head_motion.main(["--corpus", str(moved), "--checkpoint", str(tmp_path / "ck.pt"), "--template", str(tpl),
                             "--out", str(tmp_path / "hm.pt"), "--cache", str(tmp_path / "cache")]) == 0
    assert (tmp_path / "cache.npz").exists()  # and a second run reuses it (found by the name numpy gave it)
    assert head_motion.main(["--corpus", str(moved), "--checkpoint", str(tmp_path / "ck.pt"), "--template", str(tpl),
                             "--out", str(tmp_path / "hm2.pt"), "--cache", str(tmp_path / "cache")]) == 0


def test_a_calibration_with_no_heard_bilabial_writes_nothing(corpus, trained_run, tmp_path, monkeypatch):
    monkeypatch.setattr(lip_closure, "heard_bilabials", lambda *a, **k: [])
    with pytest.raises(SystemExit, match="heard no /p b m/ segment"):
        lip_closure.main(["--corpus", str(corpus.root), "--checkpoint", str(trained_run / "final.pt"), "--out", str(tmp_path / "cal.pt")])
    assert not (tmp_path / "cal.pt").exists()


def test_sigterm_saves_the_checkpoint_as_ctrl_c_does(corpus, tmp_path):
    out = tmp_path / "run"
    cmd = [str(Path(SRC).parents[1] / "scripts" / "py"), "-m", "talkingface.train.train", "--corpus", str(corpus.root), "--out", str(out),
           "--minutes", "5", "--batch-clips", "2", "--frames", "4", "--checkpoint-every", "100000", "--threads", "1"]
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)  # through scripts/py: the signal reaches Python
    for line in proc.stderr:
        if line.startswith("step"):
            break
    proc.send_signal(signal.SIGTERM)
    rest = proc.stderr.read()
    assert proc.wait(timeout=60) == 130, rest
    assert "interrupted at step" in rest
    assert torch.load(out / "checkpoint.pt", weights_only=False)["step"] >= 20


def test_an_export_copies_the_template_it_used(trained_run, tmp_path, capsys):
    """The recorded template gone (a run packed elsewhere), the shipped one of the same id is the model's: export copies it."""
    ck = torch.load(trained_run / "final.pt", weights_only=False)
    ck["template_path"] = str(tmp_path / "elsewhere" / "template.json")
    torch.save(ck, tmp_path / "ck.pt")
    assert export.main(["--checkpoint", str(tmp_path / "ck.pt"), "--out", str(tmp_path / "out")]) == 0
    assert "copied the face template" in capsys.readouterr().err
    assert (tmp_path / "out" / "template" / "template.json").is_file()
