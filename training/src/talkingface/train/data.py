"""Training batches: random crops of clips, with the audio context the encoders need around them.

A clip is loaded once: log-Mel of the whole waveform, per-frame ground truth in mm, the phone
label of every content frame. A crop of T animation frames takes its Mel from 1 s before the
first frame (the pose LSTM warms up on it) to just past the look-ahead after the last.

Silence crops (`silence` > 0): a dataset's clips hold only short pauses, where the face is still
moving into or out of speech (in our corpus the inner lips are 2.0 mm apart on average in frames
labelled silence), so a model trained on them alone never learns what a long silence looks like
and leaves the mouth ajar when a microphone hears nothing. A silence crop is a stretch (warm-up and
crop, over a second) of digital silence or faint noise (-90 to -50 dBFS) whose target is the subject's rest face: the
frame of its clips, among those labelled silence with the eyes open, where the inner lips are
closest, with the head in its neutral pose. Half the silence crops sit at the very start of the signal:
the corpus's clips open the mouth during their leading silence (the speech follows within a few
hundred ms), and a model trained on those alone opens the mouth at the start of any recording, 3 mm
in the first 0.3 s of pure silence. Nothing here assumes our corpus: unlabelled data
counts every frame as silence, and the rest face is then the subject's most closed-mouth frame.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..data.datasets import FaceDataset
from ..features import AudioConfig, frame_to_mel_index, log_mel
from ..geometry.contours import contour_gap
from ..model.config import ModelConfig
from ..phones import PHONE_INDEX, SILENCE, frame_labels
from ..template import Template
from ..wav import resample

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
    rest: np.ndarray | None = None  # (N, 3) the subject's rest face, mm (set by attach_rest_faces)
    segments: list | None = None    # [(phone, start s, end s)] as aligned, for the articulation measures
    voice: str = ""                 # who speaks: "festival:ked", "espeak:en-gb-scotland+m5", "human:allison" ("" if unknown)

    @property
    def num_frames(self) -> int:
        return self.vertices.shape[0]


def prepare(ds: FaceDataset, key: str, audio: AudioConfig = AudioConfig()) -> PreparedClip:
    clip = ds.load(key)
    mel = log_mel(resample(clip.audio, clip.sample_rate, audio.sample_rate), audio)
    k = mel.shape[0]
    phones = frame_labels(clip.phones or [], k, audio.feature_rate)
    mm = ds.mm_per_unit
    pose = clip.pose if clip.pose is not None else np.zeros((clip.num_frames, 6), np.float32)
    pose = pose.copy()
    pose[:, 3:] *= mm
    return PreparedClip(key, mel, phones, clip.vertices * mm, clip.template * mm, pose.astype(np.float32),
                        clip.meta.get("source", "real"), segments=list(clip.phones or []), voice=str(clip.meta.get("voice", "")))


@dataclass
class Batch:
    mel: torch.Tensor         # (B, K, n_mels)
    mel_index: torch.Tensor   # (B, T)
    content_labels: torch.Tensor  # (B, Kc) phone class per content frame, -100 where padded
    template: torch.Tensor    # (B, N, 3)
    vertices: torch.Tensor    # (B, T, N, 3) unposed ground truth
    pose: torch.Tensor        # (B, T, 6)

    def to(self, device: str | torch.device) -> "Batch":
        return Batch(*(getattr(self, f).to(device) for f in self.__dataclass_fields__))


def attach_rest_faces(clips: list[PreparedClip], template: Template, audio: AudioConfig = AudioConfig()) -> dict[str, float]:
    """Give every clip its subject's rest face (subjects told apart by their neutral template).
    -> per subject, the rest face's inner-lip gap in mm (for the training log)."""
    r = template.regions
    eyes = [(r[f"eye_{s}_upper"], r[f"eye_{s}_lower"]) for s in ("left", "right")]

    def candidates(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """frames -> (frames, inner-lip gap, the smaller eye opening)"""
        return v, contour_gap(v, r["lips_inner_upper"], r["lips_inner_lower"]), np.minimum(*[contour_gap(v, u, l) for u, l in eyes])

    silence = PHONE_INDEX[SILENCE]
    groups: dict[bytes, list[PreparedClip]] = {}
    for c in clips:
        groups.setdefault(c.template.tobytes(), []).append(c)
    gaps = {}
    for n, group in enumerate(groups.values()):
        cand = []
        for c in group:
            mi = np.clip(frame_to_mel_index(np.arange(c.num_frames), audio), 0, len(c.phones) - 1)
            quiet = np.flatnonzero(c.phones[mi] == silence)
            if len(quiet):
                cand.append(candidates(c.vertices[quiet]))
        if not cand:  # no frame labelled silence: every frame is a candidate
            cand = [candidates(c.vertices) for c in group]
        v, lip, eye = (np.concatenate(parts) for parts in zip(*cand))
        open_eyes = eye >= 0.9 * eye.max()
        best = np.flatnonzero(open_eyes)[np.argmin(lip[open_eyes])]
        for c in group:
            c.rest = v[best].copy()
        gaps[f"subject {n}"] = float(lip[best])
    return gaps


def silence_mel(seconds: float, rng: np.random.Generator, audio: AudioConfig) -> np.ndarray:
    """Log-Mel of `seconds` of digital silence (a third of the time) or faint white noise, -90 to -50 dBFS."""
    n = int(seconds * audio.sample_rate)
    if rng.random() < 1 / 3:
        wav = np.zeros(n, np.float32)
    else:
        wav = (rng.standard_normal(n) * 10 ** (rng.uniform(-90, -50) / 20)).astype(np.float32)
    return log_mel(wav, audio)


def sample_batch(clips: list[PreparedClip], rng: np.random.Generator, n_clips: int, frames: int,
                 model_cfg: ModelConfig, audio: AudioConfig = AudioConfig(), silence: float = 0.0) -> Batch:
    """`silence`: the chance that a crop is a silence crop (module docstring); needs attach_rest_faces."""
    warm = int(WARMUP_SECONDS * audio.feature_rate)
    # Past the last frame: the content window's future frames plus the convolutions' reach.
    ahead = model_cfg.content_stride * (model_cfg.window_future + 4) + 4
    picks = rng.choice(len(clips), n_clips, replace=len(clips) < n_clips)
    items = []
    for i in picks:
        c = clips[i]
        if silence > 0 and rng.random() < silence:
            if c.rest is None:
                raise ValueError("silence crops need the rest faces: call attach_rest_faces first")
            # Half of them at the very start of a signal (the encoders' edge padding in view), half a
            # second or more in: a recording that starts silent must not open the mouth either.
            f0 = 0 if rng.random() < 0.5 else int(np.ceil(WARMUP_SECONDS * audio.fps))
            fr = np.arange(f0, f0 + frames)
            mi = frame_to_mel_index(fr, audio)
            k0 = max(0, mi[0] - warm)
            k0 -= k0 % model_cfg.content_stride
            mel = silence_mel((mi[-1] + ahead + 2) * audio.hop / audio.sample_rate, rng, audio)
            k1 = min(len(mel), mi[-1] + ahead)
            rest = np.broadcast_to(c.rest, (frames, *c.rest.shape))
            quiet = PreparedClip(c.key + ":silence", mel, np.full(len(mel), PHONE_INDEX[SILENCE], np.int64),
                                 rest, c.template, np.zeros((frames, 6), np.float32), "silence", c.rest)
            items.append((quiet, np.arange(frames), mi - k0, k0, k1))
            continue
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
