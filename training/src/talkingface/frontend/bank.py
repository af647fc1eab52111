"""The front-end's training speech as one bank, and its augmented crops drawn in one go on any device.

  scripts/py -m talkingface.frontend.bank --speech data/speech-a data/speech-b --corpus data/corpus --out runs/bank.npz

All clips' log-Mel frames are concatenated into one (frames, n_mels) array with a phone class per frame, so a batch
of crops is one gather, and the vocal-tract warp and SpecAugment's masks are tensor operations: a GPU trains from it
at full speed, the CPU as before. `pack` writes the bank (and the mesh corpus's val and test clips, which measure the
front-end) to one compressed file, the Mel quantised to 8 bits, so that a training run can go to a machine that holds
neither the speech set nor the corpus (a GPU's, where what travels is small: about 0.15 MiB per minute of speech).
"""
from __future__ import annotations

import argparse
import sys
import zipfile
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import torch

from ..cli import npz_path
from ..data.datasets import DatasetError

CROP = 300           # Mel frames per crop (3 s)
WARP = (0.9, 1.1)    # frequency-axis warp factors (vocal-tract length perturbation)
TIME_MASKS, TIME_MASK_MAX = 2, 12   # SpecAugment: masks per crop and their largest width (Mel frames)
FREQ_MASKS, FREQ_MASK_MAX = 2, 10   # and along the Mel bands
PAD_LABEL = -100     # cross-entropy's ignore_index: frames past a clip's end
TIMBRE_GAIN = 0.7    # timbre: the largest weight (natural log of energy) of each of the smooth gain's cosines
TIMBRE_COSINES = 3   # ... and how many (orders 1, 2, 3 over the Mel axis)
TIMBRE_LIFTER = (12, 30)  # cepstral coefficients kept of the 80 where the fine structure across bands is smoothed


@dataclass
class Bank:
    mel: torch.Tensor      # (F, n_mels) every clip's log-Mel frames, one after another
    labels: torch.Tensor   # (F,) phone class per Mel frame
    starts: torch.Tensor   # (N,) first frame of each clip
    lengths: torch.Tensor  # (N,) frames of each clip

    @classmethod
    def from_clips(cls, clips: list[tuple[np.ndarray, np.ndarray]], device: str = "cpu") -> "Bank":
        """clips: (mel (K, n_mels), labels (K,)) pairs, as frontend.train.load_speech returns them."""
        lengths = np.array([len(m) for m, _ in clips], np.int64)
        starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
        t = lambda a, dtype: torch.from_numpy(np.ascontiguousarray(a)).to(device=device, dtype=dtype)
        return cls(t(np.concatenate([m for m, _ in clips]), torch.float32),
                   t(np.concatenate([l for _, l in clips]), torch.int64), t(starts, torch.int64), t(lengths, torch.int64))

    def minutes(self, rate: float) -> float:
        return len(self.mel) / rate / 60

    def batch(self, rng: np.random.Generator, size: int, stride: int) -> tuple[torch.Tensor, torch.Tensor]:
        """`size` random 3 s crops, each warped along the Mel axis by its own factor in WARP; zeros (and PAD_LABEL)
        past a clip's end. -> mel (size, CROP, n_mels), labels (size, ceil(CROP / stride)) on the bank's device."""
        mel, lab = self.crops(rng, size, stride)
        return warp(mel, warp_factors(rng, size, mel.device)), lab

    def crops(self, rng: np.random.Generator, size: int, stride: int) -> tuple[torch.Tensor, torch.Tensor]:
        """batch's crops before their warp."""
        dev = self.mel.device
        clip = torch.from_numpy(rng.integers(len(self.starts), size=size)).to(dev)
        length = self.lengths[clip]                                                # (B,)
        k0 = (torch.from_numpy(rng.random(size)).to(dev) * (length - CROP + 1).clamp(min=1)).long()
        pos = torch.arange(CROP, device=dev)
        valid = pos[None] < (length - k0)[:, None]                                 # (B, CROP)
        idx = (self.starts[clip] + k0)[:, None] + pos[None]
        idx = torch.where(valid, idx, torch.zeros_like(idx))
        mel = self.mel[idx] * valid[..., None]                                     # (B, CROP, n_mels)
        return mel, torch.where(valid, self.labels[idx], torch.full_like(idx, PAD_LABEL))[:, ::stride]


def warp_factors(rng: np.random.Generator, size: int, device) -> torch.Tensor:
    return torch.from_numpy(rng.uniform(*WARP, size)).to(device, torch.float32)


def warp(mel: torch.Tensor, factor: torch.Tensor) -> torch.Tensor:
    """features.warp_mel for a batch: crop b's Mel axis stretched by factor[b], edge values held. (B, K, M) -> same."""
    B, K, M = mel.shape
    src = (torch.arange(M, device=mel.device)[None] / factor[:, None]).clamp(0, M - 1)   # (B, M)
    lo = src.floor().long()
    hi = (lo + 1).clamp(max=M - 1)
    both = mel.gather(2, torch.cat([lo, hi], 1)[:, None].expand(B, K, 2 * M))  # (B, K, 2M): the bands below, above
    return torch.lerp(both[..., :M], both[..., M:], (src - lo)[:, None])


def spec_augment(x: torch.Tensor, rng: np.random.Generator) -> torch.Tensor:
    """Masks on the normalised features (0 = the mean), so the encoder cannot lean on any one band or instant:
    TIME_MASKS spans of up to TIME_MASK_MAX frames and FREQ_MASKS of up to FREQ_MASK_MAX bands, per crop."""
    B, K, M = x.shape
    keep = []
    for count, widest, n in ((TIME_MASKS, TIME_MASK_MAX, K), (FREQ_MASKS, FREQ_MASK_MAX, M)):
        pos, kept = torch.arange(n, device=x.device)[None], torch.ones(B, n, dtype=torch.bool, device=x.device)
        for _ in range(count):
            w = rng.integers(widest + 1, size=B)
            t = (rng.random(B) * np.maximum(1, n - w)).astype(np.int64)
            w, t = (torch.from_numpy(a).to(x.device)[:, None] for a in (w, t))
            kept &= (pos < t) | (pos >= t + w)                                 # (B, n)
        keep.append(kept.to(x.dtype))
    return x * keep[0][:, :, None] * keep[1][:, None, :]


@lru_cache(maxsize=4)
def _dct(M: int, device: torch.device) -> torch.Tensor:
    """(M, M) orthonormal DCT-II matrix (coefficients x bands), built once per size and device, not every step."""
    k = torch.arange(M, device=device, dtype=torch.float32)
    m = (k + 0.5) / M
    return torch.cos(np.pi * k[:, None] * m[None]) * torch.where(k == 0, 1 / np.sqrt(M), np.sqrt(2 / M))[:, None]


def timbre(mel: torch.Tensor, rng: np.random.Generator, p: float) -> torch.Tensor:
    """A voice of another timbre, for a fraction `p` of the crops: (1) a smooth random gain along the Mel axis
    (TIMBRE_COSINES cosines of random weight and phase, applied to the energy: a spectral tilt and broad formant
    bumps that no microphone or vocal-tract warp gives) and (2) the fine structure across bands (harmonics of the
    voice's pitch, a synthesiser's artefacts) smoothed by a cepstral lifter, partly (mixed in by a random weight).
    The features are log(energy + 1) (features.log_mel), so the gain acts on exp(x) - 1. (B, K, M) -> same."""
    if p <= 0:  # (drawing nothing: runs without it keep their random stream)
        return mel
    B, K, M = mel.shape
    dev = mel.device
    chosen = torch.from_numpy(rng.random(B) < p).to(dev)
    m = (torch.arange(M, device=dev, dtype=torch.float32) + 0.5) / M                      # (M,)
    order = torch.arange(1, TIMBRE_COSINES + 1, device=dev, dtype=torch.float32)
    weight = torch.from_numpy(rng.uniform(-TIMBRE_GAIN, TIMBRE_GAIN, (B, TIMBRE_COSINES))).to(dev, torch.float32)
    phase = torch.from_numpy(rng.uniform(0, 2 * np.pi, (B, TIMBRE_COSINES))).to(dev, torch.float32)
    gain = (weight[:, :, None] * torch.cos(np.pi * order[None, :, None] * m[None, None] + phase[:, :, None])).sum(1)  # (B, M)
    x = torch.log1p(torch.expm1(mel) * gain.exp()[:, None])
    # An orthonormal DCT-II across the bands; the coefficients past each crop's lifter are dropped.
    dct = _dct(M, dev)                                                                     # (M coef, M band)
    k = torch.arange(M, device=dev, dtype=torch.float32)
    kept = torch.from_numpy(rng.integers(TIMBRE_LIFTER[0], TIMBRE_LIFTER[1] + 1, B)).to(dev)
    lifter = (k[None] < kept[:, None]).to(mel.dtype)                                       # (B, M coef)
    smooth = ((x @ dct.T) * lifter[:, None]) @ dct
    mix = torch.from_numpy(rng.random(B)).to(dev, torch.float32)[:, None, None]
    x = torch.lerp(x, smooth, mix).clamp(min=0)
    return torch.where(chosen[:, None, None], x, mel)


def quantise(mel: np.ndarray, lo: float, hi: float) -> np.ndarray:
    return np.round((np.clip(mel, lo, hi) - lo) / (hi - lo) * 255).astype(np.uint8)


def dequantise(q: np.ndarray, lo: float, hi: float) -> np.ndarray:
    return q.astype(np.float32) * np.float32((hi - lo) / 255) + np.float32(lo)


def pack(out: Path, train: list[tuple[np.ndarray, np.ndarray]], held: dict[str, list[tuple[np.ndarray, np.ndarray]]]) -> dict:
    """Write the training clips and the held-out splits' clips (mel, labels) to one compressed .npz, the Mel in
    8 bits between the training frames' 0.01st percentile and their maximum (a step of under 0.1 of a log unit)."""
    every = np.concatenate([m for m, _ in train])
    lo, hi = float(np.percentile(every[:: max(1, len(every) // 2_000_000)], 0.01)), float(every.max())
    arrays: dict[str, np.ndarray] = {"range": np.array([lo, hi], np.float64)}
    for name, clips in {"train": train, **held}.items():
        arrays[f"{name}_mel"] = quantise(np.concatenate([m for m, _ in clips]), lo, hi)
        arrays[f"{name}_labels"] = np.concatenate([l for _, l in clips]).astype(np.int8)
        arrays[f"{name}_lengths"] = np.array([len(m) for m, _ in clips], np.int64)
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(out, **arrays)
    return {name: len(arrays[f"{name}_lengths"]) for name in ("train", *held)}


def unpack(path: Path) -> dict[str, list[tuple[np.ndarray, np.ndarray]]]:
    """pack's file -> {"train": clips, "val": clips, "test": clips}, the Mel back in float32."""
    try:
        z = np.load(path)
        lo, hi = z["range"]
    except (ValueError, KeyError, OSError, EOFError, zipfile.BadZipFile) as e:  # a pickle, another .npz, one cut short, not numpy's at all
        raise DatasetError(f"{path} is not a packed speech bank (talkingface.frontend.bank's .npz): {e}") from e
    out = {}
    for name in sorted({k.rsplit("_", 1)[0] for k in z.files if k.endswith("_lengths")}):
        mel, lab = dequantise(z[f"{name}_mel"], lo, hi), z[f"{name}_labels"].astype(np.int64)
        cuts = np.cumsum(z[f"{name}_lengths"])[:-1]
        out[name] = list(zip(np.split(mel, cuts), np.split(lab, cuts)))
    return out


def main(argv=None) -> int:
    from ..features import AudioConfig
    from .train import read_speech

    ap = argparse.ArgumentParser(prog="python -m talkingface.frontend.bank", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--speech", type=Path, nargs="+", required=True, help="speech set folder(s) (talkingface.frontend.speechset)")
    ap.add_argument("--corpus", type=Path, required=True, help="mesh corpus: its train split's speech trains, val and test measure")
    ap.add_argument("--no-corpus-train", action="store_true", help="leave out the mesh corpus's train split")
    ap.add_argument("--out", type=Path, required=True, help="the packed file (.npz); frontend.train --packed reads it")
    args = ap.parse_args(argv)
    if args.out.is_dir():
        ap.error(f"--out {args.out} is a folder: give a file name")
    args.out = npz_path(args.out)  # numpy adds .npz to a name without it
    audio = AudioConfig()
    train, held = read_speech(args.speech, args.corpus, args.no_corpus_train, audio)
    counts = pack(args.out, train, held)
    print(f"packed {counts} clips, {sum(len(m) for m, _ in train) / audio.feature_rate / 60:.1f} min of training speech, "
          f"{args.out.stat().st_size / 2**20:.1f} MiB -> {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
