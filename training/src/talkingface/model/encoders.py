"""Audio encoders: content (our DeepSpeech stand-in), hierarchical vertex features, pose (Fig. 2, left)."""
from __future__ import annotations

import torch
import torch.nn as nn

from .config import ModelConfig


class MelNorm(nn.Module):
    """Per-band standardisation of log-Mel with statistics of the training set (buffers, so they are exported)."""

    def __init__(self, n_mels: int):
        super().__init__()
        self.register_buffer("mean", torch.zeros(n_mels))
        self.register_buffer("std", torch.ones(n_mels))

    def forward(self, mel: torch.Tensor) -> torch.Tensor:                    # (B, K, F)
        return (mel - self.mean) / self.std


class ContentEncoder(nn.Module):
    """log-Mel (100/s) -> phone logits (50/s): the role DeepSpeech's character logits play in the paper.

    Look-ahead: 20 + 10 + 20 + 20 = 70 ms of audio past each output frame."""

    def __init__(self, cfg: ModelConfig, n_mels: int):
        super().__init__()
        C = cfg.content_channels
        self.norm = MelNorm(n_mels)
        self.net = nn.Sequential(
            nn.Conv1d(n_mels, C, 5, padding=2), nn.GELU(),
            nn.Conv1d(C, C, 3, stride=cfg.content_stride, padding=1), nn.GELU(),
            nn.Conv1d(C, C, 3, padding=1), nn.GELU(),
            nn.Conv1d(C, C, 3, padding=1), nn.GELU(),
            nn.Conv1d(C, cfg.content_classes, 1),
        )

    def forward(self, mel: torch.Tensor) -> torch.Tensor:
        """(B, K, n_mels) -> (B, ceil(K / stride), classes) logits."""
        return self.net(self.norm(mel).transpose(1, 2)).transpose(1, 2)


class HierarchicalFeature(nn.Module):
    """A window of phone posteriors -> one token per vertex: f_h,j = f_g + f_l,j (Sec. III-C, summed).

    f_g: an MLP of the whole window. f_l,j: a vertex-conditioned MLP, W2 gelu(W1 a + e_j), so every
    vertex reads its own latent movement from the same audio at the cost of one d-vector per vertex."""

    def __init__(self, cfg: ModelConfig, num_vertices: int):
        super().__init__()
        self.kind = cfg.features
        inp = cfg.window * cfg.content_classes
        d = cfg.d_model
        self.use_global = "G" in cfg.features
        self.use_local = "L" in cfg.features
        if self.use_global:
            self.global_mlp = nn.Sequential(nn.Linear(inp, cfg.global_hidden), nn.GELU(), nn.Linear(cfg.global_hidden, d))
        if self.use_local:
            self.local_in = nn.Linear(inp, d)
            self.vertex_embedding = nn.Parameter(torch.randn(num_vertices, d) * 0.5)
            self.local_out = nn.Linear(d, d)
        self.num_vertices = num_vertices

    def forward(self, window: torch.Tensor) -> torch.Tensor:
        """(B, W, D) posteriors -> (B, N, d) tokens."""
        flat = window.flatten(1)                                               # (B, W*D)
        tokens = 0
        if self.use_local:
            a = self.local_in(flat)[:, None, :]                                # (B, 1, d)
            tokens = self.local_out(torch.nn.functional.gelu(a + self.vertex_embedding[None]))  # (B, N, d)
        if self.use_global:
            g = self.global_mlp(flat)[:, None, :]                              # (B, 1, d)
            tokens = tokens + g if self.use_local else g.expand(-1, self.num_vertices, -1)
        return tokens


class PoseEncoder(nn.Module):
    """log-Mel -> the pose token f_p: temporal convolutions, then an LSTM run along the whole clip.

    Unidirectional, so it streams: the browser carries (h, c) from chunk to chunk. Look-ahead 30 ms."""

    def __init__(self, cfg: ModelConfig, n_mels: int):
        super().__init__()
        C = cfg.pose_channels
        self.norm = MelNorm(n_mels)
        self.conv = nn.Sequential(
            nn.Conv1d(n_mels, C, 3, padding=1), nn.GELU(),
            nn.Conv1d(C, C, 3, padding=2, dilation=2), nn.GELU(),
        )
        self.lstm = nn.LSTM(C, C, batch_first=True)
        self.out = nn.Linear(C, cfg.d_model)

    def forward(self, mel: torch.Tensor, state=None):
        """(B, K, n_mels) -> (B, K, d) pose features per Mel frame, and the LSTM state (h, c)."""
        h = self.conv(self.norm(mel).transpose(1, 2)).transpose(1, 2)          # (B, K, C)
        h, state = self.lstm(h, state)
        return self.out(h), state
