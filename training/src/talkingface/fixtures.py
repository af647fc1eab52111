"""The exporter's fixtures: a short clip and every intermediate tensor the model computes of it, from the same
code paths the browser mirrors, so the TypeScript tests (and the parity pages) check each stage against PyTorch.

Written to models/fixtures/fixtures.safetensors by export.py; artefacts.py compares them by value.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from .features import frame_to_mel_index, log_mel
from .geometry.pose_torch import apply_pose
from .model.gava import TalkingFace
from .safetensors import write_safetensors

FIXTURE_SECONDS = 0.6     # a short clip keeps the fixtures small
FIXTURE_TOKEN_FRAMES = 2  # frames whose tokens and per-layer outputs are kept


@torch.no_grad()
def write_fixtures(model: TalkingFace, template_mm: np.ndarray, audio: np.ndarray, out: Path, head_motion=None,
                   lip_closure=None) -> dict:
    """Every intermediate tensor of one short clip, from the same code paths the browser mirrors; with the head's
    own motion (model/head_motion.py) when given: its residuals for seed 0, and the poses and vertices with it;
    with the lip closure (model/lip_closure.py) when given: the offsets it gives the template's face, and those
    of a face with its lips parted 1.5 mm further (the lower lip's tissue lowered), so the test sees both ways, and of
    one with its lips shut at rest (the lower lip's tissue raised by the face's gap: they meet in the middle and
    cross towards the corners, where the face's own gap is smaller)."""
    a = model.audio
    mel = log_mel(audio, a)                                                    # (K, n_mels)
    n_frames = int(round(len(audio) / a.sample_rate * a.fps))
    mel_t = torch.from_numpy(mel)[None]
    logits = model.content(mel_t)                                              # (1, Kc, D)
    mel_index = torch.from_numpy(frame_to_mel_index(np.arange(n_frames), a)).clamp(max=mel.shape[0] - 1)
    windows = model.content_windows(logits, mel_index[None])[0]                # (F, W, D)
    tokens = model.hierarchical(windows)                                       # (F, N, d)
    latents = model.hierarchical.latents(windows)                                         # (F, 2d): what hierarchical.onnx gives
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
    vertices = apply_pose(torch.from_numpy(template_mm)[None] + offsets, pose)
    tensors = {
        "audio": audio.astype(np.float32), "mel": mel, "content_logits": logits[0].numpy(), "mel_index": mel_index.numpy(),
        "windows": windows.numpy(), "hierarchical_latents": latents.numpy(), "tokens": tokens[:FIXTURE_TOKEN_FRAMES].numpy(), "pose_conv": conv[0].numpy(),
        "pose_features": pose_feat[0].numpy(), "pose_token": pose_token.numpy(), "template_mm": template_mm.astype(np.float32),
        "offsets": offsets.numpy(), "pose": pose.numpy(), "vertices": vertices.numpy(),
    }
    if head_motion is not None:
        from .model.head_motion import compose
        residual = head_motion.sample(pose_token.numpy(), seed=0)
        sampled = compose(pose.numpy(), residual, head_motion.pivot_mm)
        # The whole engine's output: the sampled pose on the offsets as the engine gives them (the mouth's amplitude
        # and the lip closure applied where the model has them).
        engine_offsets = torch.from_numpy(lip_closure.apply(offsets.numpy())) if lip_closure is not None else offsets
        tensors |= {"head_residual": residual.astype(np.float32), "pose_sampled": sampled,
                    "vertices_sampled": apply_pose(torch.from_numpy(template_mm)[None] + engine_offsets, torch.from_numpy(sampled)).numpy()}
    if lip_closure is not None:
        from .model.lip_closure import LipClosure
        # The clip's frames open the lips; silence closes them (c = 1) and 0.6 of it partly (c < 1): all three cases.
        silence = model.animate(torch.from_numpy(log_mel(np.zeros(a.sample_rate // 2, np.float32), a)),
                                torch.from_numpy(template_mm), 4)["offsets"].numpy()
        lips_in = np.concatenate([offsets.numpy()[:4], silence, 0.6 * silence]).astype(np.float32)
        wider, shut = template_mm.copy(), template_mm.copy()
        wider[:, 1] -= 1.5 * lip_closure.lower_weight.astype(np.float32)
        shut[:, 1] += lip_closure.face_gap * lip_closure.lower_weight.astype(np.float32)  # lips meeting at rest
        closure = lambda face: LipClosure(lip_closure.template, face, lip_closure.reference_gap, lip_closure.mouth_gain)
        tensors |= {"lips_in": lips_in, "lips_out": lip_closure.apply(lips_in), "template_wider_mm": wider,
                    "lips_out_wider": closure(wider).apply(lips_in), "template_shut_mm": shut, "lips_out_shut": closure(shut).apply(lips_in)}
    for i, l in enumerate(layers):
        tensors[f"layer{i}"] = l
    tensors.update(attention)
    out.mkdir(parents=True, exist_ok=True)
    write_safetensors(out / "fixtures.safetensors", tensors, {"frames": str(n_frames), "token_frames": str(FIXTURE_TOKEN_FRAMES)})
    return {"file": "fixtures/fixtures.safetensors", "frames": n_frames, "token_frames": FIXTURE_TOKEN_FRAMES,
            "seconds": FIXTURE_SECONDS, "tensors": {k: list(v.shape) for k, v in tensors.items()}}


def fixture_audio(sample_rate: int) -> np.ndarray:
    """The fixture clip: FIXTURE_SECONDS of a deterministic synthetic vowel-like signal (a gliding pitch with
    29 harmonics, a 3 Hz syllable envelope and faint seeded noise)."""
    n = int(FIXTURE_SECONDS * sample_rate)
    t = np.arange(n) / sample_rate
    f0 = 120 + 30 * np.sin(2 * np.pi * 2 * t)
    phase = 2 * np.pi * np.cumsum(f0) / sample_rate
    voice = sum(np.sin(k * phase) / k for k in range(1, 30)) * (0.5 + 0.5 * np.sin(2 * np.pi * 3 * t))
    noise = np.random.default_rng(0).standard_normal(n) * 0.01
    return (0.2 * voice / np.abs(voice).max() + noise).astype(np.float32)
