"""A front-end between two: weight by weight on the line from the one a fine-tune started from to the fine-tune."""
import pytest
import torch

from talkingface.cli import CheckpointError

from talkingface.frontend import measure, soup
from talkingface.train.train import load_frontend


def _shifted(fe: dict, by: float) -> dict:
    return {**fe, "content": {k: v + by if v.is_floating_point() else v for k, v in fe["content"].items()}}


def test_the_soup_is_the_line_between_the_two_and_ends_at_each(trained_run):
    base = load_frontend(str(trained_run / "final.pt"))
    tuned = _shifted(base, 1.0)
    for alpha in (0.0, 0.3, 1.0):
        mixed = soup.interpolate(base, tuned, alpha)
        for k, v in base["content"].items():
            assert torch.allclose(mixed[k], v + alpha, atol=1e-6), (k, alpha)
    with pytest.raises(ValueError, match="from 0 to 1"):
        soup.interpolate(base, tuned, 1.2)


def test_front_ends_of_other_shapes_or_layers_are_refused_with_the_reason(trained_run):
    base = load_frontend(str(trained_run / "final.pt"))
    k = next(k for k, v in base["content"].items() if v.ndim == 2 or v.ndim == 3)
    wider = {**base, "content": {**base["content"], k: torch.zeros(base["content"][k].shape[0] + 1, *base["content"][k].shape[1:])}}
    with pytest.raises(ValueError, match="differ in " + k.replace(".", r"\.")):
        soup.interpolate(base, wider, 0.5)
    fewer = {**base, "content": {n: v for n, v in base["content"].items() if n != k}}
    with pytest.raises(ValueError, match="differ in their layers"):
        soup.interpolate(base, fewer, 0.5)


def test_the_command_writes_a_front_end_that_measure_and_the_face_read(trained_run, tmp_path):
    base = trained_run / "final.pt"
    tuned = tmp_path / "tuned.pt"
    torch.save(_shifted(load_frontend(str(base)), 0.5), tuned)
    out = tmp_path / "soup.pt"
    assert soup.main([str(base), str(tuned), "--alpha", "0.5", "--out", str(out)]) == 0
    enc, _ = measure.load_encoder(str(out))
    want = load_frontend(str(base))["content"]
    got = enc.state_dict()
    assert all(torch.allclose(got[k], want[k] + 0.25, atol=1e-6) for k in want if want[k].is_floating_point())
    assert torch.load(out, weights_only=False)["soup"] == {"base": str(base), "tuned": str(tuned), "alpha": 0.5}


def test_with_face_the_result_replaces_that_faces_content_encoder_and_nothing_else(trained_run, tmp_path):
    face = trained_run / "final.pt"
    tuned = tmp_path / "tuned.pt"
    torch.save(_shifted(load_frontend(str(face)), 0.5), tuned)
    out = tmp_path / "face.pt"
    assert soup.main([str(face), str(tuned), "--alpha", "1", "--face", str(face), "--out", str(out)]) == 0
    before, after = torch.load(face, weights_only=False), torch.load(out, weights_only=False)
    for k, v in before["model"].items():
        if k.startswith("content.") and v.is_floating_point():
            assert torch.allclose(after["model"][k], v + 0.5, atol=1e-6), k
        else:
            assert torch.equal(after["model"][k], v), k
    assert after["model_config"] == before["model_config"] and after["frontend_soup"]["alpha"] == 1.0
    with pytest.raises(CheckpointError, match="is a speech front-end"):  # not a face (one line on the command line: talkingface.cli)
        soup.main([str(face), str(tuned), "--face", str(tuned), "--out", str(tmp_path / "no.pt")])


def test_a_fine_tune_that_gained_a_look_ahead_block_soups_with_the_front_end_without_it(trained_run, corpus, tmp_path):
    from talkingface.frontend.train import look_further
    from talkingface.model.config import ModelConfig
    face = trained_run / "final.pt"
    base = load_frontend(str(face))
    cfg = ModelConfig.from_dict(base["model_config"])
    enc = measure.load_encoder(str(face))[0]
    ahead_cfg = ModelConfig(**cfg.to_dict() | {"content_ahead": 1})
    further = look_further(enc, ahead_cfg).state_dict()
    tuned = tmp_path / "tuned.pt"
    torch.save({"content": {k: v + 1.0 if v.is_floating_point() else v for k, v in further.items()},
                "model_config": ahead_cfg.to_dict(), "step": 1}, tuned)
    out = tmp_path / "soup.pt"
    assert soup.main([str(face), str(tuned), "--alpha", "0.25", "--out", str(out)]) == 0
    got = torch.load(out, weights_only=False)
    assert got["model_config"]["content_ahead"] == 1
    extra = [k for k in further if k.startswith("blocks.4.")]
    assert extra and all(torch.allclose(got["content"][k], torch.full_like(further[k], 0.25)) for k in extra)  # 0.75 x 0 + 0.25 x 1
    into = tmp_path / "face.pt"
    assert soup.main([str(face), str(tuned), "--alpha", "0.25", "--face", str(face), "--out", str(into)]) == 0
    written = torch.load(into, weights_only=False)
    assert written["model_config"]["content_ahead"] == 1
    from talkingface.train.train import load_checkpoint
    model, _ = load_checkpoint(into, corpus.template)  # the face loads, its content encoder the soup's
    for k in extra:
        torch.testing.assert_close(model.content.state_dict()[k], got["content"][k], rtol=0, atol=0)
