"""The content encoder: the dilated one reads half a second back and no further ahead than the first one."""
import numpy as np
import torch

from talkingface.model.config import ModelConfig
from talkingface.model.encoders import ContentEncoder


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


def test_the_shape_input_reads_how_the_face_differs_from_the_reference(make, template):
    """It starts at zero (a model gains it without changing), then each face's own shape changes its tokens;
    the reference face itself reads the same as no face given (what the browser's export bakes in)."""
    model = make(template_input=True)
    assert model.shape_input and "reference" in model.state_dict()
    mm = template.to_millimetres()
    ref = torch.from_numpy(template.vertices * mm).float()[None]
    other = ref * 1.05                                                         # a face 5% larger
    win = torch.rand(2, model.cfg.window, model.cfg.content_classes)
    h = model.hierarchical
    torch.testing.assert_close(h(win, model.template_delta(other)), h(win, None), rtol=0, atol=0)
    torch.nn.init.normal_(h.shape_in.weight)
    torch.nn.init.normal_(h.shape_in.bias)
    torch.testing.assert_close(h(win, model.template_delta(ref)), h(win, None), rtol=0, atol=0)
    assert (h(win, model.template_delta(other)) - h(win, None)).abs().max() > 1e-3
    mel = torch.randn(150, 80)
    a, b = model.animate(mel, ref[0], 40), model.animate(mel, other[0], 40)
    assert (a["offsets"] - b["offsets"]).abs().max() > 1e-3                   # the face changes what the model does
    assert not make().shape_input and not make(template_input=True, features="G").shape_input


def test_the_exported_split_of_the_hierarchical_feature_makes_the_same_tokens(make, template, tmp_path):
    """hierarchical.onnx gives [a, g] per frame and the browser's decoder makes the vertex tokens of them with
    gava.safetensors' e_j and local_out (export.vertex_token_tensors): the same tokens as the model's, for every
    kind of feature, and with the shape input baked in for the face exported with (here not the reference face, so
    that the shape term counts); the ONNX graph of the latents takes any number of frames."""
    import onnxruntime as ort
    from talkingface.export import _HierarchicalLatents, _onnx, vertex_token_tensors
    ref = torch.from_numpy(template.vertices * template.to_millimetres()).float()[None]
    face = ref * 1.05
    for options in ({}, {"features": "L"}, {"features": "G"}, {"template_input": True}):
        model = make(**options)
        if model.shape_input:
            torch.nn.init.normal_(model.hierarchical.shape_in.weight)
            torch.nn.init.normal_(model.hierarchical.shape_in.bias)
        d = model.cfg.d_model
        win = torch.rand(5, model.cfg.window, model.cfg.content_classes)
        with torch.no_grad():
            latents = _HierarchicalLatents(model)(win)
            want = model.hierarchical(win, model.template_delta(face) if model.shape_input else None)
            if model.shape_input:  # the face's shape moves the tokens: a test of the term, not of its bias alone
                assert (want - model.hierarchical(win, None)).abs().max() > 1e-3
        w = {k: torch.from_numpy(v) for k, v in vertex_token_tensors(model, face).items()}
        h = torch.nn.functional.gelu(latents[:, None, :d] + w["hierarchical.vertex_embedding"])
        tokens = h @ w["hierarchical.local_out.weight"].T + w["hierarchical.local_out.bias"] + latents[:, None, d:]
        assert latents.shape == (5, 2 * d), options
        torch.testing.assert_close(tokens, want, rtol=0, atol=1e-5, msg=str(options))
        path = tmp_path / "hierarchical.onnx"
        _onnx(_HierarchicalLatents(model), (win[:3],), path, ["windows"], ["latents"], {"windows": {0: "F"}, "latents": {0: "F"}})
        got = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"]).run(None, {"windows": win.numpy()})[0]
        np.testing.assert_allclose(got, latents.numpy(), atol=1e-5, err_msg=str(options))
