"""A dataset's training clips (its train split) packed into one file, for training the face where the dataset is not
(a GPU machine that takes a few tens of MiB): what `data.prepare` makes of each clip, the faces compressed.

  scripts/py -m talkingface.train.packed --corpus data/corpus --out runs/facegpu/train.npz      # about 30 MiB
  python -m talkingface.train.train --packed runs/facegpu/train.npz --device cuda --out ... (the usual options)

The log-Mel is kept in float16 (0.01 of its range at most off); the faces, which a synthetic rig moves in far fewer
directions than it has vertices, as their displacement from the subject's neutral face projected on its first
principal directions (128 by default: on our corpus's train split 0.002 mm off at the worst vertex and frame,
printed when packing), each direction's coefficients as 16-bit integers. The template travels in the file, and the
checkpoint a packed run saves names the dataset's template path, as a run on the dataset itself would.
"""
from __future__ import annotations

import argparse
import pickle
import sys
import zipfile
from pathlib import Path

import numpy as np

from ..cli import npz_path
from ..data.datasets import DatasetError, open_dataset
from ..features import AudioConfig
from ..template import Template
from .data import PreparedClip, prepare

FORMAT = "talking-face-packed-clips"
VERSION = 1


def _basis(disp: np.ndarray, components: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(frames, N*3) displacements -> (mean (N*3,), basis (components, N*3)) of their principal directions
    (from at most 20,000 frames: the directions settle long before)."""
    mean = disp.mean(0)
    sample = disp[rng.choice(len(disp), min(len(disp), 20_000), replace=False)] - mean
    _, _, vt = np.linalg.svd(sample.astype(np.float64), full_matrices=False)
    return mean.astype(np.float32), vt[:components].astype(np.float32)


def pack(clips: list[PreparedClip], template: Template, template_path: str, fps: float, out: Path,
         components: int = 128, seed: int = 0) -> dict:
    """Write the clips to `out` (.npz) -> the compression's error, in mm: {'mean': ..., 'max': ...}."""
    if not clips:
        raise ValueError("no clips to pack")
    n = template.num_vertices
    disp = np.concatenate([(c.vertices - c.template).reshape(c.num_frames, -1) for c in clips])
    components = min(components, disp.shape[1], disp.shape[0])
    mean, basis = _basis(disp, components, np.random.default_rng(seed))
    coef = (disp - mean) @ basis.T                                               # (frames, C)
    scale = np.maximum(np.abs(coef).max(0), 1e-9) / 32767
    q = np.round(coef / scale).astype(np.int16)
    back = (q * scale) @ basis + mean
    err = np.sqrt(((back - disp).reshape(len(disp), n, 3) ** 2).sum(-1))
    templates, template_index = np.unique(np.stack([c.template for c in clips]), axis=0, return_inverse=True)
    frames = np.cumsum([0] + [c.num_frames for c in clips])
    mels = np.cumsum([0] + [len(c.mel) for c in clips])
    np.savez_compressed(
        out, format=np.array(FORMAT), version=np.array(VERSION), fps=np.array(float(fps)),
        template_path=np.array(template_path), template=np.frombuffer(pickle.dumps(template), np.uint8),
        keys=np.array([c.key for c in clips]), sources=np.array([c.source for c in clips]),
        voices=np.array([c.voice for c in clips]), frames=frames, mels=mels,
        mel=np.concatenate([c.mel for c in clips]).astype(np.float16),
        phones=np.concatenate([c.phones for c in clips]).astype(np.int16),
        pose=np.concatenate([c.pose for c in clips]).astype(np.float32),
        templates=templates.astype(np.float32), template_index=template_index.reshape(-1),
        mean=mean, basis=basis, scale=scale.astype(np.float32), coef=q)
    return {"mean": float(err.mean()), "max": float(err.max()), "components": components}


def load(path: str | Path) -> tuple[list[PreparedClip], Template, str, float]:
    """-> (clips, template, the dataset's template path, fps) from a file `pack` wrote (DatasetError: it is not one)."""
    path = Path(path)
    if not path.is_file():
        raise DatasetError(f"--packed: {path} {'is a folder, not a file' if path.is_dir() else 'does not exist'}")
    not_packed = f"--packed: {path} is not a file of packed clips (talkingface.train.packed writes them)"
    try:
        z = np.load(path, allow_pickle=False)
        if not isinstance(z, np.lib.npyio.NpzFile):  # a bare array (.npy)
            raise DatasetError(not_packed)
        with z:
            if "format" not in z or str(z["format"]) != FORMAT:
                raise DatasetError(not_packed)
            if int(z["version"]) != VERSION:
                raise DatasetError(f"--packed: {path} is version {int(z['version'])}; this toolkit reads {VERSION}: pack it again")
            f = {k: z[k] for k in z.files}
    except (ValueError, KeyError, OSError, EOFError, zipfile.BadZipFile) as e:  # a pickle, not numpy's at all, one cut short
        raise DatasetError(f"{not_packed}: {e}") from e
    template = pickle.loads(f["template"].tobytes())
    n = template.num_vertices
    faces = (f["coef"].astype(np.float32) * f["scale"]) @ f["basis"] + f["mean"]  # (frames, N*3)
    clips = []
    for i, key in enumerate(f["keys"]):
        a, b = f["frames"][i], f["frames"][i + 1]
        m0, m1 = f["mels"][i], f["mels"][i + 1]
        tpl = f["templates"][f["template_index"][i]]
        clips.append(PreparedClip(str(key), f["mel"][m0:m1].astype(np.float32), f["phones"][m0:m1].astype(np.int64),
                                  faces[a:b].reshape(-1, n, 3) + tpl, tpl, f["pose"][a:b], str(f["sources"][i]),
                                  voice=str(f["voices"][i])))
    return clips, template, str(f["template_path"]), float(f["fps"])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.train.packed", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", required=True, help="dataset folder (our corpus, processed VOCASET or Multiface)")
    ap.add_argument("--template", help="template for a real dataset (as train.train's --template)")
    ap.add_argument("--masks", help="region masks for a mesh template")
    ap.add_argument("--components", type=int, default=128, help="principal directions the faces are kept in")
    ap.add_argument("--out", required=True, help="the .npz file to write")
    args = ap.parse_args(argv)
    if args.components < 1:
        ap.error("--components must be at least 1")
    if Path(args.out).is_dir():
        ap.error(f"--out {args.out} is a folder: give a file name")
    out = npz_path(args.out)  # numpy adds .npz to a name without it
    ds = open_dataset(args.corpus, args.template, args.masks)
    audio = AudioConfig(fps=int(ds.fps))
    keys = ds.keys("train")
    clips = []
    for i, k in enumerate(keys):
        clips.append(prepare(ds, k, audio))
        if (i + 1) % 50 == 0 or i + 1 == len(keys):
            print(f"prepared {i + 1} / {len(keys)} clips", file=sys.stderr, flush=True)
    template_path = args.template or str(Path(args.corpus) / "template" / "template.json")
    out.parent.mkdir(parents=True, exist_ok=True)
    err = pack(clips, ds.template, template_path, ds.fps, out, args.components)
    print(f"{out}: {len(clips)} clips, {sum(c.num_frames for c in clips)} frames, {out.stat().st_size / 2**20:.1f} MiB; "
          f"faces in {err['components']} directions, {err['mean']:.5f} mm off on average, {err['max']:.4f} mm at worst")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli

    run_cli(main)
