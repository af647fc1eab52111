"""The corpus build: the small preset's layout, the same corpus whatever the workers, its refusal to
overwrite what it did not make, and the count of recordings a TTS voice had to speak."""
import hashlib
import json
import logging
from dataclasses import replace

import pytest

from talkingface.corpus import clip as clip_module
from talkingface.corpus.build import build_corpus
from talkingface.corpus.plan import PRESETS, plan
from tests.speech_tools import NoAlignment, needs_speech_tools

pytestmark = needs_speech_tools


def test_small_preset_layout(corpus):
    root = corpus.root
    meta = json.loads((root / "meta.json").read_text())
    n = sum(PRESETS["small"].subjects) * PRESETS["small"].sentences_per_subject
    assert meta["clips"] == n
    for folder, ext in (("wav", "wav"), ("vertices_npy", "npy"), ("poses_npy", "npy"), ("alignments", "json")):
        assert len(list((root / folder).glob(f"*.{ext}"))) == n
    assert set(corpus.subject_templates) == {s["name"] for s in meta["subjects"]}
    assert meta["tool_versions"]["flite"] != "not installed" and meta["tool_versions"]["pocketsphinx"]


def test_same_seed_same_corpus(tmp_path):
    def digest(root):
        h = hashlib.sha256()
        for p in sorted(root.rglob("*")):
            if p.is_file() and p.name not in ("meta.json",):
                h.update(p.relative_to(root).as_posix().encode())
                h.update(p.read_bytes())
        return h.hexdigest()
    cfg = PRESETS["small"]
    build_corpus(tmp_path / "a", cfg, workers=1)
    build_corpus(tmp_path / "b", cfg, workers=2)
    a, b = tmp_path / "a", tmp_path / "b"
    differing = [str(p.relative_to(a)) for p in sorted(a.rglob("*"))
                 if p.is_file() and p.name != "meta.json" and p.read_bytes() != (b / p.relative_to(a)).read_bytes()]
    assert differing == []
    assert digest(a) == digest(b)
    assert plan(cfg)[1][0].seed != plan(type(cfg)(**{**cfg.__dict__, "seed": 1}))[1][0].seed


def test_refuses_to_overwrite_a_folder_it_did_not_make(tmp_path):
    (tmp_path / "precious.txt").write_text("keep me")
    with pytest.raises(FileExistsError):
        build_corpus(tmp_path, PRESETS["small"], workers=1, overwrite=True)
    assert (tmp_path / "precious.txt").exists()


def test_recordings_that_fail_alignment_are_warned_about_and_counted(tmp_path, monkeypatch, caplog):
    """A clip planned as recorded speech whose alignment fails is spoken by a TTS voice (clip.py): the build
    says so in its log and in meta.json, and each such clip's record names its recording and the reason."""
    monkeypatch.setattr(clip_module, "_aligner", NoAlignment)  # the forked workers inherit it
    cfg = replace(PRESETS["small"], subjects=(1, 1, 1), sentences_per_subject=1, human_fraction=1.0)
    recorded_keys = sorted(s.key for s in plan(cfg)[1] if s.recording)
    assert len(recorded_keys) == 3
    with caplog.at_level(logging.WARNING, logger="talkingface.corpus.build"):
        meta = build_corpus(tmp_path / "c", cfg, workers=1)
    assert sorted(meta["recordings_failed_alignment"]) == recorded_keys
    assert all("will not align" in v["reason"] for v in meta["recordings_failed_alignment"].values())
    records = [json.loads(line) for line in (tmp_path / "c" / "clips.jsonl").read_text().splitlines()]
    assert all(r["source"] == "tts" and r["recording_failed_alignment"] == meta["recordings_failed_alignment"][r["key"]]
               for r in records)
    warned = [r.getMessage() for r in caplog.records if r.name == "talkingface.corpus.build"]
    assert len(warned) == 1 and "3 clip(s)" in warned[0] and all(k in warned[0] for k in recorded_keys)
