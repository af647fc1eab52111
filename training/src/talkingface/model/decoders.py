"""Decoders from tokens to motion (Fig. 2, right): GAVA, plain self-attention (SA), or an MLP (ablation)."""
from __future__ import annotations

import torch
import torch.nn as nn

from .attention import Block
from .config import ModelConfig


class AttentionDecoder(nn.Module):
    """A stack of transformer layers over [vertex tokens, pose token].

    GAVA masks every layer with the augmented adjacency; SA attends everywhere. The released-code
    variant computes Q/K/V with a graph convolution and adds one unmasked layer after the masked ones."""

    def __init__(self, cfg: ModelConfig):
        super().__init__()
        released = cfg.variant == "released"
        self.masked = cfg.decoder == "GAVA"
        self.blocks = nn.ModuleList(Block(cfg.d_model, cfg.heads, cfg.ffn, graph_conv=released and self.masked)
                                    for _ in range(cfg.layers))
        self.full = Block(cfg.d_model, cfg.heads, cfg.ffn) if released and self.masked else None
        self.ln = nn.LayerNorm(cfg.d_model)

    def forward(self, x, table, pad, dense_mask=None, dense=False, return_attention=False):
        """x: (B, N+1, d) -> (B, N+1, d), list of per-layer attention (or None)."""
        mode = ("dense" if dense else "neighbour") if self.masked else "full"
        maps = []
        for block in self.blocks:
            x, attn = block(x, mode, table, pad, dense_mask, return_attention)
            maps.append(attn)
        if self.full is not None:
            x, attn = self.full(x, "full", return_attention=return_attention)
            maps.append(attn)
        return self.ln(x), (maps if return_attention else None)


class MLPDecoder(nn.Module):
    """The ablation's MLP: every vertex output mixes all vertices' features through a learned N x N map
    (it "computes the relationships among any vertices blindly", Sec. III-D). Own vertex embedding, so a
    global feature copied to every vertex still yields per-vertex motion (as VOCA's decoder does)."""

    def __init__(self, cfg: ModelConfig, num_vertices: int):
        super().__init__()
        d = cfg.d_model
        self.inp = nn.Linear(d, d)
        self.vertex_embedding = nn.Parameter(torch.randn(num_vertices, d) * 0.5)
        self.mix = nn.Parameter(torch.eye(num_vertices) + torch.randn(num_vertices, num_vertices) / num_vertices)
        self.hidden = nn.Sequential(nn.GELU(), nn.Linear(d, d), nn.GELU())
        self.pose = nn.Sequential(nn.Linear(2 * d, d), nn.GELU(), nn.Linear(d, d))
        self.ln = nn.LayerNorm(d)

    def forward(self, x, *_, return_attention=False, **__):
        n = x.shape[1] - 1
        h = torch.nn.functional.gelu(self.inp(x[:, :n]) + self.vertex_embedding[None])   # (B, N, d)
        h = self.hidden(torch.einsum("jk,bkd->bjd", self.mix, h))
        p = self.pose(torch.cat([x[:, n], h.mean(1)], -1))[:, None]                     # (B, 1, d)
        return self.ln(torch.cat([h, p], 1)), None
