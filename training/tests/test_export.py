"""The browser artefacts: ONNX equals PyTorch, the manifest matches the files, the committed models/ is what the exporter writes."""
import json
import shutil

import numpy as np
import onnxruntime as ort
import pytest
import torch

from talkingface import export
from talkingface.artefacts import compare_exports
from talkingface.safetensors import read_safetensors, write_safetensors
from talkingface.paths import MODELS_DIR
from talkingface.train import train


@pytest.fixture(scope="module")
def exported(corpus, tmp_path_factory):
    run = tmp_path_factory.mktemp("run")
    train.main(["--corpus", str(corpus.root), "--out", str(run), "--steps", "2", "--batch-clips", "2", "--frames", "4"])
    out = tmp_path_factory.mktemp("export")
    manifest = export.export(run / "final.pt", out)
    model, _ = train.load_checkpoint(run / "final.pt", corpus.template)
    return out, manifest, model.eval()


def session(path):
    return ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])


def test_onnx_encoders_equal_pytorch(exported):
    out, manifest, model = exported
    fx = export.read_safetensors(out / "fixtures" / "fixtures.safetensors")
    mel = fx["mel"][None]
    logits = session(out / "content_encoder.onnx").run(None, {"mel": mel})[0]
    np.testing.assert_allclose(logits[0], fx["content_logits"], atol=1e-5)
    tokens = session(out / "hierarchical.onnx").run(None, {"windows": fx["windows"]})[0]
    np.testing.assert_allclose(tokens[: fx["tokens"].shape[0]], fx["tokens"], atol=1e-5)
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
    fx = export.read_safetensors(out / "fixtures" / "fixtures.safetensors")
    verts, offsets, pose = session(out / "gava_dense.onnx").run(
        None, {"mel": fx["mel"][None], "mel_index": fx["mel_index"][None].astype(np.int64), "template": fx["template_mm"][None]})
    np.testing.assert_allclose(verts[0], fx["vertices"], atol=1e-4)  # mm; the fixture used the neighbour form
    np.testing.assert_allclose(pose[0], fx["pose"], atol=1e-5)


def test_manifest_matches_the_files(exported):
    out, manifest, model = exported
    for name, path in manifest["files"].items():
        assert manifest["sha256"][name] == export.sha256(out / path), name
    assert manifest["runtime_bytes"] <= 3_000_000  # what a visitor downloads of the model (issue 14: at most 3 MB)
    w = export.read_safetensors(out / "gava.safetensors")
    assert {k: list(v.shape) for k, v in w.items()} == manifest["decoder_tensors"]
    assert manifest["audio"]["sample_rate"] == 16000 and manifest["audio"]["n_mels"] == 80 and manifest["audio"]["fps"] == 30
    assert manifest["tokens"]["pose_token_index"] == model.num_vertices


@pytest.fixture(scope="module")
def reexported(tmp_path_factory):
    """The shipped checkpoint exported afresh by this machine's exporter."""
    out = tmp_path_factory.mktemp("reexport")
    export.export(MODELS_DIR / "checkpoint.pt", out)
    return out


def test_committed_models_are_what_the_exporter_writes(reexported):
    problems, diffs = compare_exports(MODELS_DIR, reexported)
    print("\n".join(map(str, diffs)))  # pytest -s shows how far the fixtures are from this machine's numbers
    assert not problems, "models/ is stale: rerun scripts/py -m talkingface.export\n" + "\n".join(problems)


def copy_export(src, dst):
    shutil.copytree(src, dst)
    return dst


def test_a_last_bit_difference_in_a_fixture_passes(reexported, tmp_path):
    other = copy_export(reexported, tmp_path / "m")
    fx = read_safetensors(other / "fixtures" / "fixtures.safetensors")
    for name, a in fx.items():
        if a.dtype == np.float32:  # every value one ulp away, as another BLAS kernel might compute it
            fx[name] = np.nextafter(a, np.float32(np.inf))
    write_safetensors(other / "fixtures" / "fixtures.safetensors", fx, {"frames": "x"})
    problems, diffs = compare_exports(other, reexported)
    assert [p for p in problems if "does not match its manifest hash" not in p] == []
    assert max(d.max_abs for d in diffs) > 0


def test_a_changed_weight_fails(reexported, tmp_path):
    other = copy_export(reexported, tmp_path / "m")
    w = read_safetensors(other / "gava.safetensors")
    name = sorted(w)[0]
    w[name].flat[0] += 0.01 * np.abs(w[name]).max()
    write_safetensors(other / "gava.safetensors", w)
    manifest = json.loads((other / "manifest.json").read_text())
    manifest["sha256"]["decoder_weights"] = export.sha256(other / "gava.safetensors")  # even with its hash updated
    (other / "manifest.json").write_text(json.dumps(manifest))
    problems, _ = compare_exports(other, reexported)
    assert any("decoder_weights" in p and "serialised weights differ" in p for p in problems), problems


def test_a_changed_fixture_value_fails(reexported, tmp_path):
    other = copy_export(reexported, tmp_path / "m")
    fx = read_safetensors(other / "fixtures" / "fixtures.safetensors")
    fx["vertices"][0, 0, 0] += 0.05  # mm: far more than rounding, far less than anything visible
    write_safetensors(other / "fixtures" / "fixtures.safetensors", fx)
    problems, _ = compare_exports(other, reexported)
    assert any("vertices" in p and "over tolerance" in p for p in problems), problems
