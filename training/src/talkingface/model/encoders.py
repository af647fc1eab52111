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


class ShiftedConv(nn.Module):
    """A dilated kernel-3 convolution that reads `ahead` of its 3 taps from the future and the rest from the past,
    so the encoder can look far back (free for latency) while its look-ahead stays fixed."""

    def __init__(self, C: int, dilation: int, ahead: int):
        super().__init__()
        self.pad = (dilation * (2 - ahead), dilation * ahead)
        self.conv = nn.Conv1d(C, C, 3, dilation=dilation)

    def forward(self, x: torch.Tensor) -> torch.Tensor:                       # (B, C, T)
        return self.conv(nn.functional.pad(x, self.pad))


class ContentEncoder(nn.Module):
    """log-Mel (100/s) -> phone logits (50/s): the role DeepSpeech's character logits play in the paper.

    "dilated" (default): two convolutions to 50/s, then residual dilated convolutions (dilations 1, 1, 4, 8);
    the first two read one frame ahead, the rest only the past. Look-ahead 20 + 10 + 20 + 20 = 70 ms (as conv4),
    look-back about 550 ms: phones are recognised from their context, which the four-layer "conv4" (70 ms each way) lacked.
    Trained on its own on many voices (talkingface.frontend), then frozen in the face model."""

    DILATIONS = ((1, 1), (1, 1), (4, 0), (8, 0))  # (dilation, taps ahead) per residual block

    def __init__(self, cfg: ModelConfig, n_mels: int):
        super().__init__()
        C = cfg.content_channels
        self.arch = cfg.content_arch
        self.norm = MelNorm(n_mels)
        if cfg.content_arch == "conv4":
            self.net = nn.Sequential(
                nn.Conv1d(n_mels, C, 5, padding=2), nn.GELU(),
                nn.Conv1d(C, C, 3, stride=cfg.content_stride, padding=1), nn.GELU(),
                nn.Conv1d(C, C, 3, padding=1), nn.GELU(),
                nn.Conv1d(C, C, 3, padding=1), nn.GELU(),
                nn.Conv1d(C, cfg.content_classes, 1),
            )
        elif cfg.content_arch == "dilated":
            self.stem = nn.Sequential(
                nn.Conv1d(n_mels, C, 5, padding=2), nn.GELU(),
                nn.Conv1d(C, C, 3, stride=cfg.content_stride, padding=1), nn.GELU(),
            )
            extra = ((cfg.content_ahead, 1),) if cfg.content_ahead else ()
            self.blocks = nn.ModuleList(ShiftedConv(C, d, a) for d, a in self.DILATIONS + extra)
            self.out = nn.Conv1d(C, cfg.content_classes, 1)
        else:
            raise ValueError(f"unknown content_arch {cfg.content_arch!r} (dilated, conv4)")
        if cfg.content_ahead and cfg.content_arch != "dilated":
            raise ValueError(f"content_ahead needs the dilated content encoder, not {cfg.content_arch!r}")

    def forward(self, mel: torch.Tensor) -> torch.Tensor:
        """(B, K, n_mels) -> (B, ceil(K / stride), classes) logits."""
        x = self.norm(mel).transpose(1, 2)                                     # (B, n_mels, K)
        if self.arch == "conv4":
            return self.net(x).transpose(1, 2)
        h = self.stem(x)                                                       # (B, C, Kc)
        for block in self.blocks:
            h = h + nn.functional.gelu(block(h))
        return self.out(h).transpose(1, 2)                                     # (B, Kc, classes)


class HierarchicalFeature(nn.Module):
    """A window of phone posteriors -> one token per vertex: f_h,j = f_g + f_l,j (Sec. III-C, summed).

    f_g: an MLP of the whole window. f_l,j: a vertex-conditioned MLP, W2 gelu(W1 a + e_j), so every
    vertex reads its own latent movement from the same audio at the cost of one d-vector per vertex.

    With cfg.template_input, e_j becomes e_j + S (x_j - r_j): x the subject's neutral face, r the reference face
    the model was trained around (mm). The displacement that closes the lips is the neutral face's own lip gap,
    which differs from face to face (4.6 to 7.3 mm in the corpus); a model that hears only audio closes an
    average gap: measured, the shipped model pressed the lips of the val split's narrow-gapped subjects together
    (median smallest gap -0.42 / -0.11 mm on heard /p b m/) and left the test split's wide-gapped ones 0.38 / 0.56 mm
    apart (train.closure_causes; issue 14). Fine-tunes with it have not helped yet (docs/results/README.md). S starts at
    zero. For the reference face itself the term is the constant S's bias, so the browser's graph is unchanged."""

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
        self.shape_in = None
        if cfg.template_input and self.use_local:  # (a global-only feature has no per-vertex term to add it to)
            self.shape_in = nn.Linear(3, d)
            nn.init.zeros_(self.shape_in.weight)
            nn.init.zeros_(self.shape_in.bias)
        self.num_vertices = num_vertices
        self.d_model = d

    def forward(self, window: torch.Tensor, delta: torch.Tensor | None = None) -> torch.Tensor:
        """(B, W, D) posteriors -> (B, N, d) tokens. delta: (B or 1, N, 3) the neutral face minus the reference
        face in mm (template_input models; None: the reference face itself)."""
        flat = window.flatten(1)                                               # (B, W*D)
        tokens = 0
        if self.use_local:
            a = self.local_in(flat)[:, None, :]                                # (B, 1, d)
            tokens = self.local_out(torch.nn.functional.gelu(a + self.vertex_embeddings(delta)))  # (B, N, d)
        if self.use_global:
            g = self.global_mlp(flat)[:, None, :]                              # (B, 1, d)
            tokens = tokens + g if self.use_local else g.expand(-1, self.num_vertices, -1)
        return tokens

    def vertex_embeddings(self, delta: torch.Tensor | None = None) -> torch.Tensor:
        """e_j for a face, (1 or B, N, d): the vertex embedding, plus the shape term where the model has one."""
        e = self.vertex_embedding[None]
        if self.shape_in is not None:
            e = e + (self.shape_in.bias if delta is None else self.shape_in(delta))
        return e

    def latents(self, window: torch.Tensor) -> torch.Tensor:
        """The part of forward that is one per frame, (B, 2d): [a, g], a = local_in(window), g = the global MLP, zeros
        for a part the model lacks; forward's tokens are local_out(gelu(a + e_j)) + g (the browser's decoder makes
        them so: export.vertex_token_tensors)."""
        flat = window.flatten(1)
        zeros = flat.new_zeros(flat.shape[0], self.d_model)
        a = self.local_in(flat) if self.use_local else zeros
        g = self.global_mlp(flat) if self.use_global else zeros
        return torch.cat([a, g], 1)


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
