"""The whole model, stage by stage as in the paper's Fig. 2:

  log-Mel -> content encoder -> window of W phone posteriors per frame -> hierarchical tokens f_h,j
  log-Mel -> pose encoder    -> pose token f_p
  [f_h,1 .. f_h,N, f_p] -> GAVA (neighbour-masked attention) -> displacement O and pose T_p
  y = T_p (I + O)                                                                      (Eq. 2)

Lengths are in millimetres inside the model (metrics are reported in mm, as in the paper);
the training code converts dataset units once. forward() is exactly what is exported.
"""
from __future__ import annotations

import numpy as np
import torch
import torch.nn as nn

from ..features import AudioConfig, frame_to_mel_index
from ..geometry.pose_torch import apply_pose
from ..template import Template
from .attention import gava_dense_mask, neighbour_table
from .config import ModelConfig
from .decoders import AttentionDecoder, MLPDecoder
from .encoders import ContentEncoder, HierarchicalFeature, PoseEncoder


class TalkingFace(nn.Module):
    def __init__(self, cfg: ModelConfig, template: Template, audio: AudioConfig = AudioConfig()):
        super().__init__()
        self.cfg, self.audio = cfg, audio
        n = template.num_vertices
        self.num_vertices = n
        table, pad = neighbour_table(template.adj_offsets, template.adj_indices, n)
        self.register_buffer("nbr_table", table, persistent=False)             # (N, K) self + 1-ring
        self.register_buffer("nbr_pad", pad, persistent=False)                 # (N, K) True = padding
        self.register_buffer("dense_mask", gava_dense_mask(table, pad), persistent=False)  # (N+1, N+1)

        self.shape_input = cfg.template_input and "L" in cfg.features
        if self.shape_input:  # the face the model's shape input is relative to (mm), saved with the weights
            self.register_buffer("reference", torch.from_numpy(template.vertices * template.to_millimetres()).float())
        self.content = ContentEncoder(cfg, audio.n_mels)
        self.hierarchical = HierarchicalFeature(cfg, n)
        self.pose_encoder = PoseEncoder(cfg, audio.n_mels)
        self.decoder = MLPDecoder(cfg, n) if cfg.decoder == "MLP" else AttentionDecoder(cfg)
        self.displacement_head = nn.Linear(cfg.d_model, 3)                     # vertex token -> o_j (mm)
        self.pose_head = nn.Linear(cfg.d_model, 6)                             # pose token -> axis-angle, translation
        nn.init.zeros_(self.pose_head.weight)
        nn.init.zeros_(self.pose_head.bias)

    # -- stages ------------------------------------------------------------------------------------

    def template_delta(self, template: torch.Tensor) -> torch.Tensor | None:
        """(B, N, 3) neutral faces in mm -> their difference from the reference face (None: no shape input)."""
        return template - self.reference if self.shape_input else None

    def content_windows(self, logits: torch.Tensor, mel_index: torch.Tensor) -> torch.Tensor:
        """(B, Kc, D) logits, (B, T) Mel-frame index of each animation frame -> (B, T, W, D) posteriors.
        Frames outside the clip read zeros."""
        cfg = self.cfg
        post = logits.softmax(-1)
        B, Kc, D = post.shape
        centre = torch.div(mel_index, cfg.content_stride, rounding_mode="floor")  # (B, T)
        offsets = torch.arange(cfg.window, device=post.device) - (cfg.window - 1 - cfg.window_future)
        idx = centre[..., None] + offsets                                      # (B, T, W)
        valid = (idx >= 0) & (idx < Kc)
        gathered = torch.gather(post, 1, idx.clamp(0, Kc - 1).flatten(1)[..., None].expand(-1, -1, D))
        return gathered.view(B, *idx.shape[1:], D) * valid[..., None]

    def decode(self, tokens: torch.Tensor, pose_token: torch.Tensor, dense: bool = False, return_attention: bool = False):
        """(F, N, d) vertex tokens, (F, d) pose token -> displacement (F, N, 3) mm, pose (F, 6), attention maps."""
        x = torch.cat([tokens, pose_token[:, None]], 1)                        # (F, N+1, d)
        x, maps = self.decoder(x, self.nbr_table, self.nbr_pad, self.dense_mask, dense=dense, return_attention=return_attention)
        n = self.num_vertices
        offsets = self.displacement_head(x[:, :n])                             # (F, N, 3)
        raw = self.pose_head(x[:, n])                                          # (F, 6)
        pose = torch.cat([self.cfg.max_rotation * torch.tanh(raw[:, :3]),
                          self.cfg.max_translation_mm * torch.tanh(raw[:, 3:])], -1)
        return offsets, pose, maps

    # -- the whole graph ---------------------------------------------------------------------------

    def forward(self, mel: torch.Tensor, mel_index: torch.Tensor, template: torch.Tensor,
                dense: bool = False, return_attention: bool = False, content_mel: torch.Tensor | None = None) -> dict:
        """mel (B, K, n_mels); mel_index (B, T) long, the Mel frame of each animation frame;
        template (B, N, 3) neutral faces in mm. Returns O, pose, posed y, content logits (and attention).
        content_mel: what the content encoder hears instead of `mel` (training: a voice it has not heard)."""
        B, T = mel_index.shape
        logits = self.content(mel if content_mel is None else content_mel)     # (B, Kc, D)
        windows = self.content_windows(logits, mel_index)                      # (B, T, W, D)
        delta = self.template_delta(template)                                  # (B, N, 3) or None
        tokens = self.hierarchical(windows.flatten(0, 1), None if delta is None else delta.repeat_interleave(T, 0))  # (B*T, N, d)
        pose_feat, _ = self.pose_encoder(mel)                                  # (B, K, d)
        pose_token = torch.gather(pose_feat, 1, mel_index[..., None].expand(-1, -1, pose_feat.shape[-1]))  # (B, T, d)
        offsets, pose, maps = self.decode(tokens, pose_token.flatten(0, 1), dense, return_attention)
        offsets = offsets.view(B, T, self.num_vertices, 3)
        pose = pose.view(B, T, 6)
        unposed = template[:, None] + offsets                                  # I + O
        out = {"offsets": offsets, "pose": pose, "unposed": unposed, "vertices": apply_pose(unposed, pose),
               "content_logits": logits}
        if return_attention:
            out["attention"] = maps
        return out


    @torch.no_grad()
    def animate(self, mel: torch.Tensor, template: torch.Tensor, n_frames: int, chunk: int = 64,
                return_attention: bool = False, logits: torch.Tensor | None = None) -> dict:
        """Whole-clip inference, frames decoded in chunks so memory stays bounded:
        (K, n_mels) log-Mel, (N, 3) template in mm -> offsets (F, N, 3), pose (F, 6), posed vertices.
        logits: (Kc, D) content logits to decode instead of the content encoder's (evaluate --oracle-phones)."""
        logits = self.content(mel[None]) if logits is None else logits[None]   # (1, Kc, D)
        pose_feat, _ = self.pose_encoder(mel[None])                            # (1, K, d)
        idx = torch.from_numpy(frame_to_mel_index(np.arange(n_frames), self.audio)).clamp(max=mel.shape[0] - 1)
        offsets, poses, maps = [], [], []
        for a in range(0, n_frames, chunk):
            mi = idx[a : a + chunk]
            tokens = self.hierarchical(self.content_windows(logits, mi[None])[0], self.template_delta(template[None]))  # (c, N, d)
            o, p, m = self.decode(tokens, pose_feat[0, mi], return_attention=return_attention)
            offsets.append(o)
            poses.append(p)
            maps.append(m)
        offsets, pose = torch.cat(offsets), torch.cat(poses)
        unposed = template[None] + offsets
        out = {"offsets": offsets, "pose": pose, "unposed": unposed, "vertices": apply_pose(unposed, pose), "logits": logits[0]}
        if return_attention:
            out["attention"] = maps
        return out


def count_parameters(model: nn.Module) -> int:
    return sum(p.numel() for p in model.parameters())
