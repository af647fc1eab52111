"""The browser artefacts: ONNX equals PyTorch, the manifest matches the files, the committed models/ is what the exporter writes."""
import dataclasses
import json

import numpy as np
import onnxruntime as ort
import pytest
import torch

from talkingface import export
from talkingface.artefacts import compare_exports
from talkingface.cli import read_checkpoint
from talkingface.paths import MODELS_DIR
from talkingface.safetensors import read_safetensors, sha256
from talkingface.train import train


@pytest.fixture(scope="module")
def exported(corpus, trained_run, tmp_path_factory):
    out = tmp_path_factory.mktemp("export")
    manifest = export.export(trained_run / "final.pt", out)
    model, _ = train.load_checkpoint(trained_run / "final.pt", corpus.template)
    return out, manifest, model.eval()


def session(path):
    return ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])


def test_onnx_encoders_equal_pytorch(exported):
    out, manifest, model = exported
    fx = read_safetensors(out / "fixtures" / "fixtures.safetensors")
    mel = fx["mel"][None]
    logits = session(out / "content_encoder.onnx").run(None, {"mel": mel})[0]
    np.testing.assert_allclose(logits[0], fx["content_logits"], atol=1e-5)
    latents = session(out / "hierarchical.onnx").run(None, {"windows": fx["windows"]})[0]
    np.testing.assert_allclose(latents, fx["hierarchical_latents"], atol=1e-5)
    # the vertex tokens the browser's decoder makes of them, with gava.safetensors' per-vertex tensors
    w = read_safetensors(out / "gava.safetensors")
    d = model.cfg.d_model
    a, g = torch.from_numpy(latents[:, None, :d]), torch.from_numpy(latents[:, None, d:])
    h = torch.nn.functional.gelu(a + torch.from_numpy(w["hierarchical.vertex_embedding"]))
    tokens = h @ torch.from_numpy(w["hierarchical.local_out.weight"]).T + torch.from_numpy(w["hierarchical.local_out.bias"]) + g
    np.testing.assert_allclose(tokens[: fx["tokens"].shape[0]].numpy(), fx["tokens"], atol=1e-5)
    conv = session(out / "pose_conv.onnx").run(None, {"mel": mel})[0]
    np.testing.assert_allclose(conv[0], fx["pose_conv"], atol=1e-5)
    C = model.cfg.pose_channels
    zeros = np.zeros((1, 1, C), np.float32)
    feats = session(out / "pose_lstm.onnx").run(None, {"conv": conv, "h0": zeros, "c0": zeros})[0]
    np.testing.assert_allclose(feats[0], fx["pose_features"], atol=1e-5)
    with torch.no_grad():  # and the fixture itself is what PyTorch computes
        torch.testing.assert_close(model.content(torch.from_numpy(mel))[0], torch.from_numpy(fx["content_logits"]), atol=1e-5, rtol=0)


def test_pose_lstm_streams_in_chunks(exported):
    out, _, model = exported
    lstm = session(out / "pose_lstm.onnx")
    C = model.cfg.pose_channels
    conv = np.random.default_rng(0).standard_normal((1, 50, C)).astype(np.float32)
    z = np.zeros((1, 1, C), np.float32)
    whole = lstm.run(None, {"conv": conv, "h0": z, "c0": z})[0]
    a, h, c = lstm.run(None, {"conv": conv[:, :17], "h0": z, "c0": z})
    b, _, _ = lstm.run(None, {"conv": conv[:, 17:], "h0": h, "c0": c})
    np.testing.assert_allclose(np.concatenate([a, b], 1), whole, atol=1e-5)


def test_dense_whole_model_equals_pytorch(exported):
    out, _, model = exported
    fx = read_safetensors(out / "fixtures" / "fixtures.safetensors")
    verts, offsets, pose = session(out / "gava_dense.onnx").run(
        None, {"mel": fx["mel"][None], "mel_index": fx["mel_index"][None].astype(np.int64), "template": fx["template_mm"][None]})
    np.testing.assert_allclose(verts[0], fx["vertices"], atol=1e-4)  # mm; the fixture used the neighbour form
    np.testing.assert_allclose(pose[0], fx["pose"], atol=1e-5)


def test_manifest_matches_the_files(exported):
    out, manifest, model = exported
    for name, path in manifest["files"].items():
        assert manifest["sha256"][name] == sha256(out / path), name
    assert manifest["runtime_bytes"] <= 3_000_000  # what a visitor downloads of the model (issue 14: at most 3 MB)
    w = read_safetensors(out / "gava.safetensors")
    assert {k: list(v.shape) for k, v in w.items()} == manifest["decoder_tensors"]
    assert manifest["audio"]["sample_rate"] == 16000 and manifest["audio"]["n_mels"] == 80 and manifest["audio"]["fps"] == 30
    assert manifest["tokens"]["pose_token_index"] == model.num_vertices
    assert manifest["model"]["layer_norm_eps"] == model.decoder.ln.eps == model.decoder.blocks[0].ln1.eps
    assert manifest["template"]["units"] == "cm" and manifest["template"]["mm_per_unit"] == 10.0


def test_the_template_units_set_the_model_millimetres(corpus, trained_run, exported, tmp_path):
    """The same face in millimetres (the template's units, not an assumed centimetre) gives the model the same input."""
    out_cm, manifest_cm, _ = exported
    mm_face = dataclasses.replace(corpus.template, vertices=corpus.template.vertices * 10.0, units="mm")
    manifest = export.export(trained_run / "final.pt", tmp_path / "mm", mm_face)
    assert manifest["template"]["units"] == "mm" and manifest["template"]["mm_per_unit"] == 1.0
    cm, mm = (read_safetensors(o / "fixtures" / "fixtures.safetensors") for o in (out_cm, tmp_path / "mm"))
    np.testing.assert_allclose(mm["template_mm"], cm["template_mm"], rtol=1e-6)
    np.testing.assert_allclose(mm["vertices"], cm["vertices"], atol=1e-4)


def test_an_export_refuses_a_folder_holding_another_face(trained_run, tmp_path):
    (tmp_path / "template").mkdir()
    (tmp_path / "template" / "template.json").write_text(json.dumps({"id": "someone-else"}))
    with pytest.raises(ValueError, match="someone-else"):
        export.export(trained_run / "final.pt", tmp_path)


def test_a_template_that_is_not_the_models_is_named_as_such(corpus, trained_run, tmp_path):
    """--template B for a model trained on A, into a folder holding A: B is the wrong one (not the folder's A)."""
    (tmp_path / "template").mkdir()
    (tmp_path / "template" / "template.json").write_text(json.dumps({"id": corpus.template.id}))
    other = dataclasses.replace(corpus.template, id="someone-else")
    with pytest.raises(ValueError, match=f"trained on template {corpus.template.id}, not someone-else"):
        export.export(trained_run / "final.pt", tmp_path, other)


def test_the_export_fails_where_the_browser_would_have_no_face_to_load(trained_run, tmp_path, monkeypatch, capsys):
    """A template the exporter cannot copy (a mesh: it has no template.json) leaves the export without its face: exit 1."""
    monkeypatch.setattr(export, "copy_template", lambda source, out: f"note: {out}/template/template.json is missing")
    assert export.main(["--checkpoint", str(trained_run / "final.pt"), "--out", str(tmp_path)]) == 1
    assert "the browser cannot load it without its face template" in capsys.readouterr().err


def test_an_export_that_fails_leaves_its_folder_as_it_was(exported, trained_run):
    """A checkpoint that fails once the ONNX files are made (here: it has no step count) changes nothing in `out`:
    the browser still loads the export that was there, not new ONNX files beside the old manifest."""
    out, _, _ = exported
    files = lambda: {p.relative_to(out): sha256(p) for p in sorted(out.rglob("*")) if p.is_file()}  # noqa: E731
    before = files()
    ck = read_checkpoint(trained_run / "final.pt")
    ck["model"] = {k: v + 0.5 if v.is_floating_point() else v for k, v in ck["model"].items()}  # other weights: other ONNX bytes
    del ck["step"]
    with pytest.raises(KeyError, match="step"):
        export.export(trained_run / "final.pt", out, ck=ck)
    assert files() == before
    assert not [p.name for p in out.iterdir() if p.name.startswith(".export-")], "the staging folder is removed"


def test_committed_models_are_what_the_exporter_writes(reexported):
    problems, diffs = compare_exports(MODELS_DIR, reexported)
    print("\n".join(map(str, diffs)))  # pytest -s shows how far the fixtures are from this machine's numbers
    assert not problems, "models/ is stale: rerun scripts/py -m talkingface.export\n" + "\n".join(problems)
