"""The front-end's trainer: its augmentation keeps labels aligned, it learns, and the face model takes it frozen."""
import json

import numpy as np
import pytest
import torch

from talkingface.frontend import bank, train as fe_train
from talkingface.phones import PHONE_INDEX
from talkingface.train import train


def test_train_a_little_then_use_it_frozen(corpus, tmp_path, capsys):
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
    fe_train.main(["--speech", str(speech), "--corpus", str(corpus.root), "--out", str(out), "--steps", "12",
                   "--eval-every", "5", "--threads", "1"])
    ev = json.loads((out / "frontend_eval.json").read_text())
    assert ev["step"] == 12 and ev["history"][-1]["loss"] < ev["history"][0]["loss"]
    fe = torch.load(out / "frontend.pt", weights_only=False)
    run = tmp_path / "run"
    train.main(["--corpus", str(corpus.root), "--out", str(run), "--steps", "3", "--batch-clips", "2", "--frames", "4",
                "--frontend", str(out / "frontend.pt")])
    model, _ = train.load_checkpoint(run / "final.pt", corpus.template)
    for k, v in fe["content"].items():  # frozen: the face's training left every front-end weight as it was
        torch.testing.assert_close(model.content.state_dict()[k], v, rtol=0, atol=0)
    # --init continues from it on two speech sets: its Mel normalisation (not trained) comes with it unchanged
    again = tmp_path / "fe2"
    fe_train.main(["--speech", str(speech), str(speech), "--corpus", str(corpus.root), "--out", str(again),
                   "--steps", "2", "--eval-every", "1000", "--threads", "1", "--init", str(out / "frontend.pt")])
    fe2 = torch.load(again / "frontend.pt", weights_only=False)
    assert fe2["args"]["speech"] == [str(speech), str(speech)] and fe2["args"]["init"] == str(out / "frontend.pt")
    for k in ("norm.mean", "norm.std"):
        torch.testing.assert_close(fe2["content"][k], fe["content"][k], rtol=0, atol=0)
    # --channels widens it, and a face trained on the wider front-end takes its width
    wide = tmp_path / "fe-wide"
    fe_train.main(["--speech", str(speech), "--corpus", str(corpus.root), "--out", str(wide), "--steps", "2",
                   "--eval-every", "1000", "--threads", "1", "--init", str(out / "frontend.pt"), "--channels", "160"])
    fe3 = torch.load(wide / "frontend.pt", weights_only=False)
    assert fe3["model_config"]["content_channels"] == 160 and fe3["content"]["out.weight"].shape[1] == 160
    run2 = tmp_path / "run2"
    train.main(["--corpus", str(corpus.root), "--out", str(run2), "--steps", "1", "--batch-clips", "2", "--frames", "4",
                "--frontend", str(wide / "frontend.pt")])
    assert train.load_checkpoint(run2 / "final.pt", corpus.template)[0].cfg.content_channels == 160
    # --ahead adds a look-ahead block; a face initialised from a model without one takes the front-end's, frozen,
    # and its export reads as many Mel frames further ahead
    ahead = tmp_path / "fe-ahead"
    fe_train.main(["--speech", str(speech), "--corpus", str(corpus.root), "--out", str(ahead), "--steps", "2",
                   "--eval-every", "1000", "--threads", "1", "--init", str(out / "frontend.pt"), "--ahead", "1"])
    fe4 = torch.load(ahead / "frontend.pt", weights_only=False)
    assert fe4["model_config"]["content_ahead"] == 1 and "blocks.4.conv.weight" in fe4["content"]
    with pytest.raises(SystemExit, match="not --ahead 2"):
        fe_train.main(["--speech", str(speech), "--corpus", str(corpus.root), "--out", str(tmp_path / "x"), "--steps", "1",
                       "--threads", "1", "--init", str(ahead / "frontend.pt"), "--ahead", "2"])
    run3 = tmp_path / "run3"
    train.main(["--corpus", str(corpus.root), "--out", str(run3), "--steps", "1", "--batch-clips", "2", "--frames", "4",
                "--frontend", str(ahead / "frontend.pt"), "--init", str(run / "final.pt")])
    model3, _ = train.load_checkpoint(run3 / "final.pt", corpus.template)
    assert model3.cfg.content_ahead == 1
    for k, v in fe4["content"].items():
        torch.testing.assert_close(model3.content.state_dict()[k], v, rtol=0, atol=0)
    # --window-future moves the window of a model initialised from another, which is otherwise refused
    run4 = tmp_path / "run4"
    train.main(["--corpus", str(corpus.root), "--out", str(run4), "--steps", "1", "--batch-clips", "2", "--frames", "4",
                "--frontend", str(ahead / "frontend.pt"), "--init", str(run3 / "final.pt"), "--window-future", "0"])
    assert train.load_checkpoint(run4 / "final.pt", corpus.template)[0].cfg.window_future == 0
    with pytest.raises(SystemExit, match="is a"):
        train.main(["--corpus", str(corpus.root), "--out", str(tmp_path / "x"), "--steps", "1", "--batch-clips", "2",
                    "--frames", "4", "--frontend", str(ahead / "frontend.pt"), "--init", str(run4 / "final.pt")])
    with pytest.raises(SystemExit, match="is a"):  # without the front-end, a model of another encoder is still refused
        train.main(["--corpus", str(corpus.root), "--out", str(tmp_path / "x"), "--steps", "1", "--batch-clips", "2",
                    "--frames", "4", "--init", str(run3 / "final.pt")])
    # the same speech packed into one file (frontend.bank) trains the same way, its measuring clips inside it
    packed = tmp_path / "bank.npz"
    bank.main(["--speech", str(speech), "--corpus", str(corpus.root), "--out", str(packed)])
    if not torch.cuda.is_available():
        with pytest.raises(SystemExit):
            fe_train.main(["--packed", str(packed), "--out", str(tmp_path / "x"), "--device", "cuda"])
        assert "no CUDA device" in capsys.readouterr().err
    with pytest.raises(SystemExit, match="leave out"):
        fe_train.main(["--packed", str(packed), "--corpus", str(corpus.root), "--out", str(tmp_path / "x")])
    from_pack = tmp_path / "fe-packed"
    fe_train.main(["--packed", str(packed), "--out", str(from_pack), "--steps", "4", "--eval-every", "2", "--threads", "1",
                   "--snapshots", "--consistency", "1", "--timbre", "0.5"])
    assert json.loads((from_pack / "frontend_eval.json").read_text())["step"] == 4
    assert {p.name for p in from_pack.glob("frontend-step*.pt")} == {"frontend-step2.pt", "frontend-step4.pt"}
    one_view = tmp_path / "fe-one-view"  # --timbre without --consistency: each crop heard once, perhaps in another timbre
    fe_train.main(["--packed", str(packed), "--out", str(one_view), "--steps", "2", "--eval-every", "2", "--threads", "1", "--timbre", "1"])
    assert json.loads((one_view / "frontend_eval.json").read_text())["step"] == 2
    with pytest.raises(SystemExit):
        fe_train.main(["--packed", str(packed), "--out", str(tmp_path / "x"), "--timbre", "1.5"])
    # --teacher distils from an ensemble of front-ends (here two) while it learns the labels
    student = tmp_path / "fe-student"
    fe_train.main(["--packed", str(packed), "--out", str(student), "--steps", "2", "--eval-every", "1000", "--threads", "1",
                   "--init", str(out / "frontend.pt"), "--teacher", f"{out / 'frontend.pt'}+{again / 'frontend.pt'}",
                   "--distill", "2"])
    fe5 = torch.load(student / "frontend.pt", weights_only=False)
    assert fe5["args"]["distill"] == 2 and fe5["step"] == 2
    odd = dict(fe, model_config=fe["model_config"] | {"content_stride": 2 * fe["model_config"]["content_stride"]})
    torch.save(odd, tmp_path / "odd.pt")
    with pytest.raises(SystemExit, match="another phone set or stride"):
        fe_train.main(["--packed", str(packed), "--out", str(tmp_path / "x"), "--steps", "1", "--threads", "1",
                       "--teacher", str(tmp_path / "odd.pt")])


def test_widening_keeps_the_function_and_the_new_channels_learn():
    from talkingface.model.config import ModelConfig
    from talkingface.model.encoders import ContentEncoder
    torch.manual_seed(0)
    narrow = ContentEncoder(ModelConfig(content_channels=32), 80).eval()
    wide = fe_train.widen(narrow, ModelConfig(content_channels=48)).eval()
    mel = torch.randn(2, 60, 80)
    torch.testing.assert_close(wide(mel), narrow(mel), rtol=1e-5, atol=1e-5)
    wide(mel).square().sum().backward()
    grown = wide.blocks[0].conv.weight.grad[32:]  # the weights into the new channels: zero, with a gradient
    assert wide.blocks[0].conv.weight[32:].abs().max() == 0 and grown.abs().max() > 0


def test_a_look_ahead_block_keeps_the_function_then_learns_from_the_frames_ahead():
    from talkingface.model.config import ModelConfig
    from talkingface.model.encoders import ContentEncoder
    torch.manual_seed(0)
    enc = ContentEncoder(ModelConfig(content_channels=32), 80).eval()
    further = fe_train.look_further(enc, ModelConfig(content_channels=32, content_ahead=2)).eval()
    mel = torch.randn(2, 60, 80)
    torch.testing.assert_close(further(mel), enc(mel), rtol=0, atol=0)
    further(mel).square().sum().backward()
    assert further.blocks[-1].conv.weight.grad.abs().max() > 0
    with torch.no_grad():
        further.blocks[-1].conv.weight.normal_()
        moved = mel.clone()
        moved[:, 40] += 1.0  # Mel frame 40 is content frame 20: the block reads 2 content frames ahead of the rest
        changed = (further(moved) - further(mel)).abs().amax(-1)[0] > 0
        base = (enc(moved) - enc(mel)).abs().amax(-1)[0] > 0
    assert int(torch.nonzero(changed)[0]) == int(torch.nonzero(base)[0]) - 2
    with pytest.raises(ValueError):
        fe_train.look_further(further, ModelConfig(content_channels=32, content_ahead=1))
    with pytest.raises(ValueError):
        ContentEncoder(ModelConfig(content_arch="conv4", content_ahead=1), 80)


def test_view_disagreement_is_zero_for_the_same_posteriors_only():
    a = torch.randn(3, 10, 40)
    real = torch.ones(6, 10, dtype=torch.bool)
    assert fe_train.view_disagreement(torch.cat([a, a]), real).abs() < 1e-6
    other = fe_train.view_disagreement(torch.cat([a, torch.randn(3, 10, 40)]), real)
    assert other > 0.1
    real[:3, 5:] = False  # padded frames do not count
    b = a.clone()
    b[:, 5:] = torch.randn(3, 5, 40)
    assert fe_train.view_disagreement(torch.cat([a, b]), real).abs() < 1e-6


def test_distillation_is_zero_where_the_student_hears_as_the_teacher_does():
    logits = torch.randn(2, 10, 40)
    real = torch.ones(2, 10, dtype=torch.bool)
    assert fe_train.distillation(logits, logits.log_softmax(-1), real).abs() < 1e-6
    assert fe_train.distillation(logits, torch.randn(2, 10, 40).log_softmax(-1), real) > 0.1
    teacher = logits.log_softmax(-1).clone()
    teacher[:, 5:] = torch.randn(2, 5, 40).log_softmax(-1)
    real[:, 5:] = False  # padded frames do not count
    assert fe_train.distillation(logits, teacher, real).abs() < 1e-6
    loss = fe_train.distillation(logits.requires_grad_(), torch.randn(2, 10, 40).log_softmax(-1), real)
    loss.backward()  # the student learns, towards the teacher, on the frames that count
    assert logits.grad[:, :5].abs().sum() > 0 and logits.grad[:, 5:].abs().sum() == 0


def test_a_clip_several_speech_sets_hold_is_read_once(tmp_path):
    def speech_set(name, rows):
        folder = tmp_path / name
        folder.mkdir()
        for i, r in enumerate(rows):
            np.savez(folder / f"{r['key']}.npz", mel=np.full((5, 80), i, np.float32), labels=np.zeros(5, np.int8))
        (folder / "index.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
        return folder

    shared = {"key": "s00000", "voice": "a", "text": "Bob", "seed": 1}
    first = speech_set("first", [shared, {"key": "s00001", "voice": "b", "text": "Pam", "seed": 2}])
    # the same key with another voice is another clip; the row itself (keys in any order) is the same clip
    second = speech_set("second", [dict(reversed(list(shared.items()))), {"key": "s00001", "voice": "c", "text": "Pam", "seed": 2},
                                   {"key": "s00002", "skipped": "no bilabial diphone"}])
    assert len(fe_train.load_speech(second)) == 2  # alone, as before
    seen: set[str] = set()
    assert len(fe_train.load_speech(first, seen)) == 2
    kept = fe_train.load_speech(second, seen)
    assert [m[0, 0] for m, _ in kept] == [1.0]  # only the new voice's clip
    with pytest.raises(SystemExit, match="no clips"):
        fe_train.load_speech(speech_set("empty", [{"key": "s00000", "skipped": "x"}]), seen)
