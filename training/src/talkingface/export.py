"""Export a trained model for the browser: what models/ holds, and the one command that writes it.

  scripts/py -m talkingface.export --checkpoint models/checkpoint.pt --out models

Writes
  content_encoder.onnx   log-Mel (1, K, n_mels) -> phone logits (1, Kc, D)
  hierarchical.onnx      posterior windows (F, W, D) -> vertex tokens (F, N, d)
  pose_conv.onnx         log-Mel (1, K, n_mels) -> conv features (1, K, C)      (no state: recompute with context)
  pose_lstm.onnx         conv features + (h, c) -> pose features (1, K, d) + (h, c)   (streams chunk by chunk)
  gava.safetensors       the attention layers and the heads (the browser's WGSL / TypeScript decoder reads these)
  gava_dense.onnx        the whole model with the dense (N+1)^2 mask, for parity checks only
  fixtures/              a short clip and every intermediate tensor, for the TypeScript tests
  manifest.json          every shared constant, tensor names and shapes, the template id, file hashes
The checkpoint given (weights and configs, no optimiser state) is copied to models/checkpoint.pt when
--out is models/, so the export can be rerun and checked byte for byte.
"""
from __future__ import annotations

import argparse
import io
import json
import sys
import warnings
from pathlib import Path

import numpy as np
import torch
import torch.nn as nn

from .data.datasets import read_wav
from .corpus.phonemes import PHONES
from .features import AudioConfig, frame_to_mel_index, log_mel
from .model.gava import TalkingFace
from .paths import MODELS_DIR, TEMPLATE_DIR
from .safetensors import read_safetensors, sha256, write_safetensors
from .template import load_template

MANIFEST_FORMAT = "talking-face-model"
OPSET = 17


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


FIXTURE_SECONDS = 0.6     # a short clip keeps the fixtures small
FIXTURE_TOKEN_FRAMES = 2  # frames whose tokens and per-layer outputs are kept


@torch.no_grad()
def write_fixtures(model: TalkingFace, template_mm: np.ndarray, audio: np.ndarray, out: Path) -> dict:
    """Every intermediate tensor of one short clip, from the same code paths the browser mirrors."""
    a = model.audio
    mel = log_mel(audio, a)                                                    # (K, n_mels)
    n_frames = int(round(len(audio) / a.sample_rate * a.fps))
    mel_t = torch.from_numpy(mel)[None]
    logits = model.content(mel_t)                                              # (1, Kc, D)
    mel_index = torch.from_numpy(frame_to_mel_index(np.arange(n_frames), a)).clamp(max=mel.shape[0] - 1)
    windows = model.content_windows(logits, mel_index[None])[0]                # (F, W, D)
    tokens = model.hierarchical(windows)                                       # (F, N, d)
    conv = model.pose_encoder.conv(model.pose_encoder.norm(mel_t).transpose(1, 2)).transpose(1, 2)
    pose_feat, _ = model.pose_encoder(mel_t)                                   # (1, K, d)
    pose_token = pose_feat[0, mel_index]                                       # (F, d)
    x = torch.cat([tokens, pose_token[:, None]], 1)
    layers, attention = [], {}
    h = x[:FIXTURE_TOKEN_FRAMES]
    for i, block in enumerate(model.decoder.blocks):
        h, (w_pose, w_vert) = block(h, "neighbour", model.nbr_table, model.nbr_pad, return_attention=True)
        layers.append(h.numpy())
        # Frame 0, mean over heads: the pose token's weights (N+1), and each vertex's over its key table (N, K).
        attention[f"attention_pose{i}"] = w_pose[0].mean(0).numpy()
        attention[f"attention_vertex{i}"] = w_vert[0].mean(1).masked_fill(model.nbr_pad, 0.0).numpy()
    offsets, pose, _ = model.decode(tokens, pose_token)
    tpl = torch.from_numpy(template_mm)
    from .model.geometry import apply_pose
    vertices = apply_pose(tpl[None] + offsets, pose)
    tensors = {
        "audio": audio.astype(np.float32), "mel": mel, "content_logits": logits[0].numpy(), "mel_index": mel_index.numpy(),
        "windows": windows.numpy(), "tokens": tokens[:FIXTURE_TOKEN_FRAMES].numpy(), "pose_conv": conv[0].numpy(),
        "pose_features": pose_feat[0].numpy(), "pose_token": pose_token.numpy(), "template_mm": template_mm.astype(np.float32),
        "offsets": offsets.numpy(), "pose": pose.numpy(), "vertices": vertices.numpy(),
    }
    for i, l in enumerate(layers):
        tensors[f"layer{i}"] = l
    tensors.update(attention)
    out.mkdir(parents=True, exist_ok=True)
    write_safetensors(out / "fixtures.safetensors", tensors, {"frames": str(n_frames), "token_frames": str(FIXTURE_TOKEN_FRAMES)})
    return {"file": "fixtures/fixtures.safetensors", "frames": n_frames, "token_frames": FIXTURE_TOKEN_FRAMES,
            "seconds": FIXTURE_SECONDS, "tensors": {k: list(v.shape) for k, v in tensors.items()}}


def fixture_audio(sample_rate: int) -> np.ndarray:
    """The fixture clip: the first FIXTURE_SECONDS of a recorded prompt shipped in the repo's test data,
    or, without it, a deterministic synthetic vowel-like signal."""
    n = int(FIXTURE_SECONDS * sample_rate)
    t = np.arange(n) / sample_rate
    f0 = 120 + 30 * np.sin(2 * np.pi * 2 * t)
    phase = 2 * np.pi * np.cumsum(f0) / sample_rate
    voice = sum(np.sin(k * phase) / k for k in range(1, 30)) * (0.5 + 0.5 * np.sin(2 * np.pi * 3 * t))
    noise = np.random.default_rng(0).standard_normal(n) * 0.01
    return (0.2 * voice / np.abs(voice).max() + noise).astype(np.float32)


def export(checkpoint: Path, out: Path) -> dict:
    from .train.train import load_checkpoint
    template = load_template(TEMPLATE_DIR / "template.json")
    model, ck = load_checkpoint(checkpoint, template)
    model.eval()
    cfg, a = model.cfg, model.audio
    out.mkdir(parents=True, exist_ok=True)
    files = {}

    K = 120
    mel = torch.randn(1, K, a.n_mels)
    _onnx(model.content, (mel,), out / "content_encoder.onnx", ["mel"], ["logits"], {"mel": {1: "K"}, "logits": {1: "Kc"}})
    files["content_encoder"] = "content_encoder.onnx"
    win = torch.rand(3, cfg.window, cfg.content_classes)
    _onnx(model.hierarchical, (win,), out / "hierarchical.onnx", ["windows"], ["tokens"], {"windows": {0: "F"}, "tokens": {0: "F"}})
    files["hierarchical"] = "hierarchical.onnx"
    _onnx(_PoseConv(model.pose_encoder), (mel,), out / "pose_conv.onnx", ["mel"], ["conv"], {"mel": {1: "K"}, "conv": {1: "K"}})
    files["pose_conv"] = "pose_conv.onnx"
    C = cfg.pose_channels
    _onnx(_PoseLSTM(model.pose_encoder), (torch.randn(1, K, C), torch.zeros(1, 1, C), torch.zeros(1, 1, C)), out / "pose_lstm.onnx",
          ["conv", "h0", "c0"], ["pose_features", "hn", "cn"], {"conv": {1: "K"}, "pose_features": {1: "K"}})
    files["pose_lstm"] = "pose_lstm.onnx"
    T = 4
    tpl = torch.from_numpy(template.vertices * 10.0)[None]
    _onnx(_Dense(model), (mel, torch.arange(10, 10 + 3 * T, 3)[None], tpl), out / "gava_dense.onnx",
          ["mel", "mel_index", "template"], ["vertices", "offsets", "pose"],
          {"mel": {1: "K"}, "mel_index": {1: "T"}, "vertices": {1: "T"}, "offsets": {1: "T"}, "pose": {1: "T"}})
    files["dense_model"] = "gava_dense.onnx"
    weights = decoder_tensors(model)
    write_safetensors(out / "gava.safetensors", weights)
    files["decoder_weights"] = "gava.safetensors"

    template_mm = (template.vertices * template.to_millimetres()).astype(np.float32)
    fixtures = write_fixtures(model, template_mm, fixture_audio(a.sample_rate), out / "fixtures")
    if out.resolve() == MODELS_DIR.resolve() and checkpoint.resolve() != (out / "checkpoint.pt").resolve():
        slim = {k: v for k, v in torch.load(checkpoint, map_location="cpu", weights_only=False).items() if k != "optimizer"}
        torch.save(slim, out / "checkpoint.pt")

    all_files = {**files, "fixtures": fixtures["file"]}
    runtime = ["content_encoder", "hierarchical", "pose_conv", "pose_lstm", "decoder_weights"]
    manifest = {
        "format": MANIFEST_FORMAT, "version": 1,
        "model": {"name": cfg.name, "config": cfg.to_dict(), "trained_steps": ck["step"],
                  "trained_minutes": round(ck["trained_seconds"] / 60, 1), "parameters": int(sum(p.numel() for p in model.parameters()))},
        "audio": a.to_dict() | {"feature_rate": a.feature_rate, "mel": "meyda melBands: symmetric Hann, power spectrum of the first frame_size/2 bins, HTK Mel 0..Nyquist, ln(1 + energy); frames centred at k * hop"},
        "timing": {"frame_time": "frame i shows t = i / fps", "mel_index": "round(i / fps * feature_rate), half to even",
                   "content_index": "floor(mel_index / content_stride)",
                   "window": f"content frames [c - {cfg.window - 1 - cfg.window_future}, c + {cfg.window_future}], zeros outside the clip"},
        "template": {"id": template.id, "units": template.units, "vertices": template.num_vertices, "path": "template/template.json",
                     "model_units": "mm (positions are multiplied by the template's mm per unit before the model)"},
        "tokens": {"count": "N + 1", "pose_token_index": template.num_vertices, "d_model": cfg.d_model, "heads": cfg.heads, "layers": cfg.layers,
                   "mask": "vertex j attends to itself and its 1-ring (template adjacency); the pose token attends to all; no vertex attends to the pose token"},
        "heads": {"displacement": "Linear(d, 3), mm", "pose": f"Linear(d, 6): rotation = {cfg.max_rotation} tanh(x[0:3]) (axis-angle, rad), translation = {cfg.max_translation_mm} tanh(x[3:6]) mm; y = R (I + O) + t"},
        "files": all_files,
        "runtime_files": runtime,
        "onnx": {name: {"inputs": ins, "outputs": outs} for name, ins, outs in [
            ("content_encoder", {"mel": ["1", "K", a.n_mels]}, {"logits": ["1", "ceil(K / content_stride)", cfg.content_classes]}),
            ("hierarchical", {"windows": ["F", cfg.window, cfg.content_classes]}, {"tokens": ["F", template.num_vertices, cfg.d_model]}),
            ("pose_conv", {"mel": ["1", "K", a.n_mels]}, {"conv": ["1", "K", C]}),
            ("pose_lstm", {"conv": ["1", "K", C], "h0": [1, 1, C], "c0": [1, 1, C]}, {"pose_features": ["1", "K", cfg.d_model], "hn": [1, 1, C], "cn": [1, 1, C]}),
            ("dense_model", {"mel": ["1", "K", a.n_mels], "mel_index": ["1", "T"], "template": ["1", template.num_vertices, 3]},
             {"vertices": ["1", "T", template.num_vertices, 3], "offsets": ["1", "T", template.num_vertices, 3], "pose": ["1", "T", 6]}),
        ]},
        "decoder_tensors": {k: list(v.shape) for k, v in weights.items()},
        # The content encoder's classes in logit order: what the engine names the phone it heard at each frame.
        "content_phones": [*PHONES, "<blank>"][: cfg.content_classes],
        "fixtures": fixtures,
        "receptive_field": receptive_field(model),
        "look_ahead_ms": round(1000 * ((cfg.window_future * cfg.content_stride + receptive_field(model)["content_mel_frames"]) / a.feature_rate
                                       + a.frame_size / 2 / a.sample_rate)),
    }
    manifest["sha256"] = {name: sha256(out / path) for name, path in all_files.items()}
    manifest["runtime_bytes"] = sum((out / files[n]).stat().st_size for n in runtime)
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")
    return manifest


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.export", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checkpoint", type=Path, default=MODELS_DIR / "checkpoint.pt")
    ap.add_argument("--out", type=Path, default=MODELS_DIR)
    args = ap.parse_args(argv)
    if not args.checkpoint.exists():
        print(f"error: checkpoint {args.checkpoint} does not exist (train one: python -m talkingface.train.train)", file=sys.stderr)
        return 2
    m = export(args.checkpoint, args.out)
    print(f"exported {m['model']['name']} ({m['model']['parameters']:,} parameters): runtime files {m['runtime_bytes'] / 1e6:.2f} MB -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
