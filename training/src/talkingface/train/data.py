"""Training batches: random crops of clips, with the audio context the encoders need around them.

A clip is loaded once: log-Mel of the whole waveform, per-frame ground truth in mm, the phone
label of every content frame. A crop of T animation frames takes its Mel from 1 s before the
first frame (the pose LSTM warms up on it) to just past the look-ahead after the last.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..corpus.phonemes import PHONE_INDEX, SILENCE
from ..data.datasets import FaceDataset
from ..features import AudioConfig, frame_to_mel_index, log_mel
from ..model.config import ModelConfig

WARMUP_SECONDS = 1.0


@dataclass
class PreparedClip:
    key: str
    mel: np.ndarray             # (K, n_mels)
    phones: np.ndarray          # (K,) phone class per Mel frame (SIL where unknown)
    vertices: np.ndarray        # (F, N, 3) unposed I + O, mm
    template: np.ndarray        # (N, 3) mm
    pose: np.ndarray            # (F, 6) axis-angle (rad), translation (mm)
    source: str                 # "tts" or "human" (recorded speech)

    @property
    def num_frames(self) -> int:
        return self.vertices.shape[0]


def prepare(ds: FaceDataset, key: str, audio: AudioConfig = AudioConfig()) -> PreparedClip:
    clip = ds.load(key)
    if clip.sample_rate != audio.sample_rate:
        from ..corpus.speech import resample
        wav = resample(clip.audio, clip.sample_rate, audio.sample_rate)
    else:
        wav = clip.audio
    mel = log_mel(wav, audio)
    k = mel.shape[0]
    phones = np.full(k, PHONE_INDEX[SILENCE], dtype=np.int64)
    for p, a, b in clip.phones or []:
        phones[int(round(a * audio.feature_rate)) : int(round(b * audio.feature_rate))] = PHONE_INDEX[p]
    mm = ds.mm_per_unit
    pose = clip.pose if clip.pose is not None else np.zeros((clip.num_frames, 6), np.float32)
    pose = pose.copy()
    pose[:, 3:] *= mm
    return PreparedClip(key, mel, phones, clip.vertices * mm, clip.template * mm, pose.astype(np.float32),
                        clip.meta.get("source", "real"))


@dataclass
class Batch:
    mel: torch.Tensor         # (B, K, n_mels)
    mel_index: torch.Tensor   # (B, T)
    content_labels: torch.Tensor  # (B, Kc) phone class per content frame, -100 where padded
    template: torch.Tensor    # (B, N, 3)
    vertices: torch.Tensor    # (B, T, N, 3) unposed ground truth
    pose: torch.Tensor        # (B, T, 6)


def sample_batch(clips: list[PreparedClip], rng: np.random.Generator, n_clips: int, frames: int,
                 model_cfg: ModelConfig, audio: AudioConfig = AudioConfig()) -> Batch:
    warm = int(WARMUP_SECONDS * audio.feature_rate)
    # Past the last frame: the content window's future frames plus the convolutions' reach.
    ahead = model_cfg.content_stride * (model_cfg.window_future + 4) + 4
    picks = rng.choice(len(clips), n_clips, replace=len(clips) < n_clips)
    items = []
    for i in picks:
        c = clips[i]
        T = min(frames, c.num_frames)
        f0 = int(rng.integers(0, c.num_frames - T + 1))
        fr = np.arange(f0, f0 + T)
        mi = frame_to_mel_index(fr, audio)
        k0 = max(0, mi[0] - warm)
        k0 -= k0 % model_cfg.content_stride  # keep content frames aligned with the whole-clip ones
        k1 = min(c.mel.shape[0], mi[-1] + ahead)
        items.append((c, fr, mi - k0, k0, k1))
    K = max(k1 - k0 for *_, k0, k1 in items)
    T = max(len(fr) for _, fr, *_ in items)
    B, n_mels = len(items), clips[0].mel.shape[1]
    Kc = -(-K // model_cfg.content_stride)
    mel = np.zeros((B, K, n_mels), np.float32)
    labels = np.full((B, Kc), -100, np.int64)
    mel_index = np.zeros((B, T), np.int64)
    n = clips[0].template.shape[0]
    verts = np.zeros((B, T, n, 3), np.float32)
    pose = np.zeros((B, T, 6), np.float32)
    template = np.zeros((B, n, 3), np.float32)
    for b, (c, fr, mi, k0, k1) in enumerate(items):
        mel[b, : k1 - k0] = c.mel[k0:k1]
        lab = c.phones[k0:k1:model_cfg.content_stride]
        labels[b, : len(lab)] = lab
        mel_index[b, : len(mi)] = mi
        verts[b, : len(fr)] = c.vertices[fr]
        pose[b, : len(fr)] = c.pose[fr]
        template[b] = c.template
        if len(fr) < T:  # repeat the last frame so padding adds no motion (clips shorter than T are rare)
            mel_index[b, len(fr):] = mi[-1]
            verts[b, len(fr):] = c.vertices[fr[-1]]
            pose[b, len(fr):] = c.pose[fr[-1]]
    t = torch.from_numpy
    return Batch(t(mel), t(mel_index), t(labels), t(template), t(verts), t(pose))


def mel_statistics(clips: list[PreparedClip]) -> tuple[np.ndarray, np.ndarray]:
    allmel = np.concatenate([c.mel for c in clips])
    return allmel.mean(0).astype(np.float32), (allmel.std(0) + 1e-3).astype(np.float32)
