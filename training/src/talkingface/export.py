"""Export a trained model for the browser: what models/ holds, and the one command that writes it.

  scripts/py -m talkingface.export --checkpoint models/checkpoint.pt --out models

Writes
  content_encoder.onnx   log-Mel (1, K, n_mels) -> phone logits (1, Kc, D)
  hierarchical.onnx      posterior windows (F, W, D) -> the frame's hierarchical latents (F, 2d): [a, g], a = the local
                         MLP's first layer, g = the global MLP; the decoder makes the vertex tokens of them
                         (f_h,j = local_out(gelu(a + e_j)) + g, e and local_out in gava.safetensors)
  pose_conv.onnx         log-Mel (1, K, n_mels) -> conv features (1, K, C)      (no state: recompute with context)
  pose_lstm.onnx         conv features + (h, c) -> pose features (1, K, d) + (h, c)   (streams chunk by chunk)
  gava.safetensors       the attention layers and the heads (the browser's WGSL / TypeScript decoder reads these)
  gava_dense.onnx        the whole model with the dense (N+1)^2 mask, for parity checks only
  fixtures/              a short clip and every intermediate tensor, for the TypeScript tests
  manifest.json          every shared constant, tensor names and shapes, the template id and units, file hashes
The template is the one the checkpoint was trained on (train.checkpoint_template), or the one --template names;
its units set the model's millimetres. The checkpoint given (weights and configs, no optimiser state) is copied to
models/checkpoint.pt when --out is models/, so the export can be rerun and checked byte for byte.
"""
from __future__ import annotations

import argparse
import io
import json
import os
import shutil
import tempfile
import sys
import warnings
from pathlib import Path

import numpy as np
import torch
import torch.nn as nn

from .fixtures import fixture_audio, write_fixtures
from .model.gava import TalkingFace
from .model.head_motion import HeadMotion
from .model.lip_closure import LipClosure
from .paths import MODELS_DIR, REPO_ROOT, TEMPLATE_DIR
from .phones import CONTENT_CLASSES
from .safetensors import sha256, write_safetensors
from .cli import read_checkpoint
from .template import Template, load_template
from .out_template import check_out_template, copy_template

MANIFEST_FORMAT = "talking-face-model"
MANIFEST_VERSION = 2  # 2: hierarchical.onnx gives the latents [a, g]; the browser's decoder makes the vertex tokens
OPSET = 17


class _HierarchicalLatents(nn.Module):
    """hierarchical.onnx: the part of the hierarchical feature that is one per frame, [a, g] (F, 2d)
    (HierarchicalFeature.latents). The per-vertex part, local_out(gelu(a + e_j)) + g, is N times the work and N times
    the bytes; the browser's decoder computes it (vertex_token_tensors), so only 2d numbers a frame leave onnxruntime."""

    def __init__(self, model):
        super().__init__()
        self.h = model.hierarchical

    def forward(self, window):
        return self.h.latents(window)


def vertex_token_tensors(model, template_mm: torch.Tensor) -> dict[str, np.ndarray]:
    """The per-vertex part of the hierarchical feature, for the browser's decoder: e_j (N, d; with a template_input
    model's shape term for the template baked in, as the model computes it for that face) and local_out. A model
    without the local part gets zeros, so that its tokens are g alone, as the model's."""
    h, d, n = model.hierarchical, model.cfg.d_model, model.num_vertices
    if h.use_local:
        e = h.vertex_embeddings(model.template_delta(template_mm) if h.shape_in is not None else None)[0].detach()
        w, b = h.local_out.weight.detach(), h.local_out.bias.detach()
    else:
        e, w, b = torch.zeros(n, d), torch.zeros(d, d), torch.zeros(d)
    return {"hierarchical.vertex_embedding": e.numpy().astype(np.float32),
            "hierarchical.local_out.weight": w.numpy().astype(np.float32),
            "hierarchical.local_out.bias": b.numpy().astype(np.float32)}


class _PoseLSTM(nn.Module):
    def __init__(self, pe):
        super().__init__()
        self.pe = pe

    def forward(self, h, h0, c0):
        y, (h1, c1) = self.pe.lstm(h, (h0, c0))
        return self.pe.out(y), h1, c1


class _PoseConv(nn.Module):
    def __init__(self, pe):
        super().__init__()
        self.pe = pe

    def forward(self, mel):
        return self.pe.conv(self.pe.norm(mel).transpose(1, 2)).transpose(1, 2)


class _Dense(nn.Module):
    def __init__(self, model):
        super().__init__()
        self.model = model

    def forward(self, mel, mel_index, template):
        out = self.model(mel, mel_index, template, dense=True)
        return out["vertices"], out["offsets"], out["pose"]


def _onnx(module: nn.Module, args: tuple, path: Path, inputs: list[str], outputs: list[str], dynamic: dict) -> None:
    # The TorchScript exporter warns that it is legacy (DeprecationWarning), that Python-level shape checks are traced
    # as constants (TracerWarning), and about constant folding and LSTM batch sizes (UserWarning); whether the graphs
    # compute what PyTorch does is tested instead (tests/test_export.py), at the shapes the browser uses.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        buf = io.BytesIO()
        torch.onnx.export(module, args, buf, input_names=inputs, output_names=outputs, dynamic_axes=dynamic,
                          opset_version=OPSET, dynamo=False, do_constant_folding=True)
    path.write_bytes(buf.getvalue())


def decoder_tensors(model: TalkingFace) -> dict[str, np.ndarray]:
    """The attention decoder and heads, named as the TypeScript decoder expects (manifest lists them)."""
    if model.cfg.decoder != "GAVA" or model.cfg.variant != "paper":
        raise ValueError(f"the browser decoder implements the paper's GAVA; this checkpoint is {model.cfg.name} ({model.cfg.variant})")
    t = {}
    for name, p in model.decoder.state_dict().items():
        t[f"decoder.{name}"] = p.detach().numpy().astype(np.float32)
    for head in ("displacement_head", "pose_head"):
        for name, p in getattr(model, head).state_dict().items():
            t[f"{head}.{name}"] = p.detach().numpy().astype(np.float32)
    return t


def receptive_field(model: TalkingFace) -> dict:
    """How many Mel frames past its own position each encoder output reads (the streaming look-ahead), and how
    many before it (the context a chunk must carry): measured, not assumed, by perturbing one Mel frame (at both
    stride parities) and seeing which outputs move."""
    cfg = model.cfg
    K = 300
    reach = {"content_mel_frames": 0, "pose_mel_frames": 0, "content_mel_frames_back": 0, "pose_mel_frames_back": 0}
    with torch.no_grad():
        mel = torch.randn(1, K, model.audio.n_mels)
        base_c = model.content(mel)
        base_p = model.pose_encoder.conv(model.pose_encoder.norm(mel).transpose(1, 2))
        for probe in (150, 151):
            moved = mel.clone()
            moved[0, probe] += 1.0
            c = torch.nonzero((model.content(moved) - base_c).abs().amax(-1)[0] > 0).flatten()
            p = torch.nonzero((model.pose_encoder.conv(model.pose_encoder.norm(moved).transpose(1, 2)) - base_p).abs().amax(1)[0] > 0).flatten()
            # Content frame j covers Mel frames [j * stride, (j + 1) * stride).
            reach["content_mel_frames"] = max(reach["content_mel_frames"], probe - int(c[0]) * cfg.content_stride)
            reach["content_mel_frames_back"] = max(reach["content_mel_frames_back"], (int(c[-1]) + 1) * cfg.content_stride - 1 - probe)
            reach["pose_mel_frames"] = max(reach["pose_mel_frames"], probe - int(p[0]))
            reach["pose_mel_frames_back"] = max(reach["pose_mel_frames_back"], int(p[-1]) - probe)
    return reach


def layer_norm_eps(model: TalkingFace) -> float:
    """The eps of the decoder's LayerNorms, read from the modules: the browser's decoder normalises with it."""
    eps = {m.eps for m in model.decoder.modules() if isinstance(m, nn.LayerNorm)}
    if len(eps) != 1:
        raise ValueError(f"the decoder's LayerNorms use eps {sorted(eps)}; the manifest carries one")
    return eps.pop()


def export(checkpoint: Path, out: Path, template: Template | None = None, ck: dict | None = None) -> dict:
    """Write the browser's files for `checkpoint` into `out`; `template` defaults to the one the checkpoint names;
    `ck`: the checkpoint already read (read_checkpoint), so that it is read once. Everything is written into a folder
    inside `out` first and moved into place once all of it is made: an export that fails (a checkpoint of a decoder
    the browser does not run, a missing key, Ctrl-C) leaves `out` as it was, not its ONNX files replaced beside the
    old manifest (which the browser would then refuse as corrupt)."""
    out.mkdir(parents=True, exist_ok=True)
    for left in out.glob(".export-*"):  # an export killed outright (no `finally`) left its staging folder
        shutil.rmtree(left, ignore_errors=True)
    stage = Path(tempfile.mkdtemp(prefix=".export-", dir=out))
    try:
        manifest = _export_into(stage, checkpoint, out, template, ck)
        for made in sorted(p for p in stage.rglob("*") if p.is_file()):
            there = out / made.relative_to(stage)
            there.parent.mkdir(parents=True, exist_ok=True)
            if made.name != "manifest.json":
                os.replace(made, there)
        os.replace(stage / "manifest.json", out / "manifest.json")  # last: it names what is now there
        return manifest
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _export_into(stage: Path, checkpoint: Path, out: Path, template: Template | None, ck: dict | None) -> dict:
    """export()'s work, every file written into `stage` (moved to `out` by export)."""
    from .train.train import checkpoint_template, model_of
    ck = read_checkpoint(checkpoint) if ck is None else ck
    if template is None:
        template = checkpoint_template(ck)
    model, ck = model_of(ck, template, checkpoint)  # (first: a --template that is not the model's is named as such)
    check_out_template(out, template)
    model.eval()
    cfg, a = model.cfg, model.audio
    files = {}

    K = 120
    mel = torch.randn(1, K, a.n_mels)
    _onnx(model.content, (mel,), stage / "content_encoder.onnx", ["mel"], ["logits"], {"mel": {1: "K"}, "logits": {1: "Kc"}})
    files["content_encoder"] = "content_encoder.onnx"
    win = torch.rand(3, cfg.window, cfg.content_classes)
    _onnx(_HierarchicalLatents(model), (win,), stage / "hierarchical.onnx", ["windows"], ["latents"], {"windows": {0: "F"}, "latents": {0: "F"}})
    files["hierarchical"] = "hierarchical.onnx"
    _onnx(_PoseConv(model.pose_encoder), (mel,), stage / "pose_conv.onnx", ["mel"], ["conv"], {"mel": {1: "K"}, "conv": {1: "K"}})
    files["pose_conv"] = "pose_conv.onnx"
    C = cfg.pose_channels
    _onnx(_PoseLSTM(model.pose_encoder), (torch.randn(1, K, C), torch.zeros(1, 1, C), torch.zeros(1, 1, C)), stage / "pose_lstm.onnx",
          ["conv", "h0", "c0"], ["pose_features", "hn", "cn"], {"conv": {1: "K"}, "pose_features": {1: "K"}})
    files["pose_lstm"] = "pose_lstm.onnx"
    T = 4
    mm_per_unit = template.to_millimetres()
    tpl = torch.from_numpy(template.vertices * mm_per_unit)[None]
    _onnx(_Dense(model), (mel, torch.arange(10, 10 + 3 * T, 3)[None], tpl), stage / "gava_dense.onnx",
          ["mel", "mel_index", "template"], ["vertices", "offsets", "pose"],
          {"mel": {1: "K"}, "mel_index": {1: "T"}, "vertices": {1: "T"}, "offsets": {1: "T"}, "pose": {1: "T"}})
    files["dense_model"] = "gava_dense.onnx"
    weights = decoder_tensors(model) | vertex_token_tensors(model, tpl.float())
    head = HeadMotion.from_dict(ck["head_motion"]) if "head_motion" in ck else None
    if head is not None:  # the head's own motion: read by src/pose/head-motion.ts from the same file
        weights |= {f"head_motion.{k}": np.asarray(v, np.float32) for k, v in head.to_dict().items()}
    write_safetensors(stage / "gava.safetensors", weights)
    files["decoder_weights"] = "gava.safetensors"

    template_mm = (template.vertices * mm_per_unit).astype(np.float32)
    closure = ck.get("lip_closure")
    closer = LipClosure(template, template_mm, closure["reference_gap_mm"], closure.get("mouth_gain", 1.0)) if closure else None
    fixtures = write_fixtures(model, template_mm, fixture_audio(a.sample_rate), stage / "fixtures", head, closer)
    if out.resolve() == MODELS_DIR.resolve() and checkpoint.resolve() != (out / "checkpoint.pt").resolve():
        slim = {k: v for k, v in ck.items() if k != "optimizer"}
        torch.save(slim, stage / "checkpoint.pt")

    all_files = {**files, "fixtures": fixtures["file"]}
    runtime = ["content_encoder", "hierarchical", "pose_conv", "pose_lstm", "decoder_weights"]
    manifest = {
        "format": MANIFEST_FORMAT, "version": MANIFEST_VERSION,
        "model": {"name": cfg.name, "config": cfg.to_dict(), "trained_steps": ck["step"],
                  "trained_minutes": round(ck["trained_seconds"] / 60, 1), "parameters": int(sum(p.numel() for p in model.parameters())),
                  "layer_norm_eps": layer_norm_eps(model)},
        "audio": a.to_dict() | {"feature_rate": a.feature_rate, "mel": "meyda melBands: symmetric Hann, power spectrum of the first frame_size/2 bins, HTK Mel 0..Nyquist, ln(1 + energy); frames centred at k * hop"},
        "timing": {"frame_time": "frame i shows t = i / fps", "mel_index": "round(i / fps * feature_rate), half to even",
                   "content_index": "floor(mel_index / content_stride)",
                   "window": f"content frames [c - {cfg.window - 1 - cfg.window_future}, c + {cfg.window_future}], zeros outside the clip"},
        "template": {"id": template.id, "units": template.units, "mm_per_unit": mm_per_unit, "vertices": template.num_vertices,
                     "path": "template/template.json",
                     "model_units": "mm (positions are multiplied by the template's mm per unit before the model)"},
        "tokens": {"count": "N + 1", "pose_token_index": template.num_vertices,
                   "vertex_tokens": "f_h,j = local_out(gelu(a + e_j)) + g per frame, [a, g] = hierarchical.onnx's latents, e_j and "
                                    "local_out = hierarchical.* in gava.safetensors (exact GELU)", "d_model": cfg.d_model, "heads": cfg.heads, "layers": cfg.layers,
                   "mask": "vertex j attends to itself and its 1-ring (template adjacency); the pose token attends to all; no vertex attends to the pose token"},
        "head_motion": ({"tensors": "head_motion.* in gava.safetensors", "default_seed": 0,
                         "process": "residual_t = A f_t + c + r_t, r_t = a1 r_(t-1) + a2 r_(t-2) + g softplus(W f_t + b) z_t per axis (degrees, rotation vector); f_t the pose token; A, c: speech_w, speech_b; z_t = normal(seed, t, axis); R' = R_r R, t' = R_r (t - pivot) + pivot"}
                        if head is not None else None),
        "lip_closure": ({"reference_gap_mm": float(closure["reference_gap_mm"]), "mouth_gain": float(closure.get("mouth_gain", 1.0)),
                         "calibrated_on": closure.get("split"),
                         "rule": "the model's offsets first scaled by 1 + (mouth_gain - 1) clamp(max(jaw field, lip fields), 0, 1); then "
                                 "at each x across the mouth, c = clamp(-(du - dl) / g_ref(x), 0, 1) of those offsets; the lips "
                                 "close by c (g(x) - g_ref(x)) more, with the rig's lip fields; g the face's gap, g_ref = g * reference / lip gap; "
                                 "where the face's lips touch (g <= 0.05 mm) their closing, min(du - dl, 0), is taken out "
                                 "(training/src/talkingface/model/lip_closure.py)"}
                        if closure else None),
        "heads": {"displacement": "Linear(d, 3), mm", "pose": f"Linear(d, 6): rotation = {cfg.max_rotation} tanh(x[0:3]) (axis-angle, rad), translation = {cfg.max_translation_mm} tanh(x[3:6]) mm; y = R (I + O) + t"},
        "files": all_files,
        "runtime_files": runtime,
        "onnx": {name: {"inputs": ins, "outputs": outs} for name, ins, outs in [
            ("content_encoder", {"mel": ["1", "K", a.n_mels]}, {"logits": ["1", "ceil(K / content_stride)", cfg.content_classes]}),
            ("hierarchical", {"windows": ["F", cfg.window, cfg.content_classes]}, {"latents": ["F", 2 * cfg.d_model]}),
            ("pose_conv", {"mel": ["1", "K", a.n_mels]}, {"conv": ["1", "K", C]}),
            ("pose_lstm", {"conv": ["1", "K", C], "h0": [1, 1, C], "c0": [1, 1, C]}, {"pose_features": ["1", "K", cfg.d_model], "hn": [1, 1, C], "cn": [1, 1, C]}),
            ("dense_model", {"mel": ["1", "K", a.n_mels], "mel_index": ["1", "T"], "template": ["1", template.num_vertices, 3]},
             {"vertices": ["1", "T", template.num_vertices, 3], "offsets": ["1", "T", template.num_vertices, 3], "pose": ["1", "T", 6]}),
        ]},
        "decoder_tensors": {k: list(v.shape) for k, v in weights.items()},
        # The content encoder's classes in logit order: what the engine names the phone it heard at each frame.
        "content_phones": list(CONTENT_CLASSES[: cfg.content_classes]),
        "fixtures": fixtures,
        "receptive_field": receptive_field(model),
        "look_ahead_ms": round(1000 * ((cfg.window_future * cfg.content_stride + receptive_field(model)["content_mel_frames"]) / a.feature_rate
                                       + a.frame_size / 2 / a.sample_rate)),
    }
    manifest["sha256"] = {name: sha256(stage / path) for name, path in all_files.items()}
    manifest["runtime_bytes"] = sum((stage / files[n]).stat().st_size for n in runtime)
    (stage / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")
    return manifest


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.export", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checkpoint", type=Path, default=MODELS_DIR / "checkpoint.pt")
    ap.add_argument("--out", type=Path, default=MODELS_DIR)
    ap.add_argument("--template", type=Path, help="the template the model was trained on, when the one the checkpoint "
                    "names is not on this machine (template.json, or a mesh with --masks)")
    ap.add_argument("--masks", type=Path, help="region masks for a mesh template")
    args = ap.parse_args(argv)
    if not args.checkpoint.exists():
        print(f"error: checkpoint {args.checkpoint} does not exist (train one: python -m talkingface.train.train)", file=sys.stderr)
        return 2
    ck = read_checkpoint(args.checkpoint)
    m = export(args.checkpoint, args.out, load_template(args.template, args.masks) if args.template else None, ck)
    # The template the model was exported with (checkpoint_template's choice): the recorded one where it is on this
    # machine, else the shipped one (which export checked has the recorded id).
    recorded = Path(ck.get("template_path", ""))
    named = args.template or next((p for p in (recorded, REPO_ROOT / recorded) if str(recorded) and p.is_file()), TEMPLATE_DIR / "template.json")
    if said := copy_template(named, args.out):
        print(said, file=sys.stderr)
    if not (args.out / "template" / "template.json").exists():
        print(f"error: the model is exported to {args.out}, but the browser cannot load it without its face template there", file=sys.stderr)
        return 1
    print(f"exported {m['model']['name']} ({m['model']['parameters']:,} parameters): runtime files {m['runtime_bytes'] / 1e6:.2f} MB -> {args.out}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
