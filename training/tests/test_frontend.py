"""The speech front-end: its speech set keeps the mesh corpus's test material out, its augmentation keeps
labels aligned, its trainer learns, and the face model takes it frozen."""
import json

import numpy as np
import pytest
import torch

from talkingface.corpus import kokoro
from talkingface.corpus.build import is_test_voice
from talkingface.corpus.phonemes import PHONE_INDEX
from talkingface.corpus.speech import Voice
from talkingface.frontend import speechset
from talkingface.frontend import train as fe_train
from talkingface.model.config import LEGACY, ModelConfig
from talkingface.model.encoders import ContentEncoder


def test_the_plan_never_uses_test_voices_or_sentences(monkeypatch):
    monkeypatch.setattr(kokoro, "voice_names", lambda: ["af_a", "bm_b"])
    specs = speechset.plan(20, seed=3)
    banned = speechset.face_test_sentences()
    assert len(specs) == 400 and not any(s.text in banned for s in specs)
    classic = [s for s in specs if s.engine in ("festival", "flite", "espeak")]
    assert classic and not any(is_test_voice(Voice(s.engine, s.voice)) for s in classic)
    assert {s.engine for s in specs} >= {"kokoro", "human"} and any("+" in s.voice for s in specs if s.engine == "kokoro")


def test_a_plan_without_kokoro_says_how_to_set_it_up(monkeypatch):
    monkeypatch.setattr(kokoro, "voice_names", lambda: [])
    with pytest.raises(kokoro.KokoroMissing, match="setup --kokoro"):
        speechset.plan(5, seed=0)


def test_frame_labels_follow_the_phones():
    lab = speechset.frame_labels([("SIL", 0.0, 0.1), ("M", 0.1, 0.25), ("AA", 0.25, 0.4)], 45, 100.0)
    assert lab[5] == PHONE_INDEX["SIL"] and lab[10] == lab[24] == PHONE_INDEX["M"] and lab[25] == PHONE_INDEX["AA"]
    assert lab[44] == PHONE_INDEX["SIL"]  # past the last phone: silence


def test_warp_moves_energy_up_the_mel_axis():
    mel = np.zeros((3, 80), np.float32)
    mel[:, 20] = 1.0
    assert np.argmax(fe_train.warp(mel, 1.1)[0]) == 22 and np.argmax(fe_train.warp(mel, 0.9)[0]) == 18
    np.testing.assert_array_equal(fe_train.warp(mel, 1.0), mel)


def test_the_dilated_encoder_looks_back_not_ahead():
    enc = ContentEncoder(ModelConfig(), 80).eval()
    mel = torch.randn(1, 300, 80)
    with torch.no_grad():
        base = enc(mel)
        moved = mel.clone()
        moved[0, 150] += 1.0
        changed = torch.nonzero((enc(moved) - base).abs().amax(-1)[0] > 0).flatten()
    assert 150 - int(changed[0]) * 2 <= 7          # 70 ms look-ahead, as the first encoder
    assert int(changed[-1]) * 2 - 150 >= 50         # and half a second of context behind


def test_old_checkpoints_keep_their_encoder():
    assert ModelConfig.from_dict({k: v for k, v in ModelConfig().to_dict().items() if k != "content_arch"}).content_arch == LEGACY["content_arch"]


def test_train_a_little_then_use_it_frozen(corpus, tmp_path):
    from talkingface.train import train
    speech = tmp_path / "speech"
    speech.mkdir()
    rows = []
    rng = np.random.default_rng(0)
    for i in range(6):  # a toy speech set: noise with two "phones" that differ in level
        lab = (np.arange(400) // 50 % 2).astype(np.int8) * PHONE_INDEX["M"]
        mel = (rng.standard_normal((400, 80)) + 3.0 * (lab[:, None] > 0)).astype(np.float16)
        np.savez(speech / f"s{i}.npz", mel=mel, labels=lab)
        rows.append({"key": f"s{i}", "seconds": 4.0})
    (speech / "index.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    out = tmp_path / "fe"
    fe_train.main(["--speech", str(speech), "--corpus", str(corpus.root), "--out", str(out), "--minutes", "0.05",
                   "--eval-every", "5", "--threads", "1"])
    ev = json.loads((out / "frontend_eval.json").read_text())
    assert ev["step"] >= 5 and ev["history"][-1]["loss"] < ev["history"][0]["loss"]
    fe = torch.load(out / "frontend.pt", weights_only=False)
    run = tmp_path / "run"
    train.main(["--corpus", str(corpus.root), "--out", str(run), "--steps", "3", "--batch-clips", "2", "--frames", "4",
                "--frontend", str(out / "frontend.pt")])
    model, _ = train.load_checkpoint(run / "final.pt", corpus.template)
    for k, v in fe["content"].items():  # frozen: the face's training left every front-end weight as it was
        torch.testing.assert_close(model.content.state_dict()[k], v, rtol=0, atol=0)
