"""The command lines' common ending: the usual mistakes said in one line, not a traceback.

A missing or unreadable file, a file that is not the checkpoint asked for, a dataset or template that cannot be read:
each is a line naming the file and what to do (exit status 2). Ctrl-C ends with status 130 (the trainers save their
checkpoint first). TALKING_FACE_TRACEBACK=1 shows the traceback as well, for a bug report.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import pickle
import signal
import sys
import traceback
from collections.abc import Callable
from pathlib import Path

import torch

from .data.datasets import DatasetError
from .template import TemplateFormatError
from .wav import WavError


class CheckpointError(ValueError):
    """A file given as a checkpoint that is not one, or not of the kind asked for."""


def read_checkpoint(path: str | Path, kind: str = "face") -> dict:
    """torch.load of a checkpoint, or CheckpointError saying what the file is instead. `kind` 'face': a face model's
    (train.train's OUT/final.pt or checkpoint.pt, models/checkpoint.pt); 'any': whatever dict it holds."""
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(f"{path} {'is a folder, not a file' if path.is_dir() else 'does not exist'}")
    try:
        ck = torch.load(path, map_location="cpu", weights_only=False)
    except (pickle.UnpicklingError, RuntimeError, EOFError, ValueError) as e:
        raise CheckpointError(f"{path} is not a PyTorch checkpoint, or it is cut short ({str(e).splitlines()[0]})") from e
    if not isinstance(ck, dict):
        raise CheckpointError(f"{path} holds a {type(ck).__name__}, not a checkpoint")
    if kind == "face" and not {"model", "model_config", "template_id"} <= ck.keys():
        what = "a speech front-end (frontend.train's; it goes to --frontend or --init of frontend.train)" if "content" in ck else "not a face checkpoint"
        raise CheckpointError(f"{path} is {what}: give a face model's checkpoint (train.train's OUT/final.pt, or models/checkpoint.pt)")
    return ck


def run_cli(main: Callable[[], int | None]) -> None:
    """sys.exit(main()), with the usual mistakes in one line."""
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        sys.exit(130)
    except (CheckpointError, DatasetError, TemplateFormatError, WavError, FileNotFoundError, FileExistsError, NotADirectoryError,
            IsADirectoryError, PermissionError) as e:
        if os.environ.get("TALKING_FACE_TRACEBACK"):
            traceback.print_exc()
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)


def term_as_interrupt() -> None:
    """SIGTERM (`timeout`, `kill`, a job scheduler) raised as KeyboardInterrupt, so a trainer saves its checkpoint first,
    as on Ctrl-C (a job started with & ignores SIGINT, so SIGTERM is what stops it)."""
    def interrupt(signum, frame):
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, interrupt)


def require_positive(ap: argparse.ArgumentParser, args: argparse.Namespace, *names: str) -> None:
    """ap.error for any of the options `names` (attribute names) given as zero or less: a budget or size of nothing."""
    for name in names:
        value = getattr(args, name)
        if value is not None and value <= 0:
            ap.error(f"--{name.replace('_', '-')} must be above 0, not {value}")


def check_out_file(ap: argparse.ArgumentParser, path: str | Path | None, flag: str = "--out") -> None:
    """ap.error before any work where `path` cannot be written: it is a folder, or its folder does not exist."""
    if path is None:
        return
    p = Path(path)
    if p.is_dir():
        ap.error(f"{flag} {p} is a folder: give a file name")
    if not p.parent.is_dir():
        ap.error(f"{flag} {p}: the folder {p.parent} does not exist")


def npz_path(path: str | Path) -> Path:
    """The name numpy's savez gives `path` (it adds .npz to a name without it), so it is reported and found again."""
    p = Path(path)
    return p if p.suffix == ".npz" else p.with_name(p.name + ".npz")


def check_device(ap: argparse.ArgumentParser, device: str) -> None:
    """ap.error for a --device torch does not know, or a CUDA device on a machine without one."""
    try:
        kind = torch.device(device).type
    except RuntimeError:
        ap.error(f"--device {device}: not a torch device (cpu, cuda, cuda:1)")
    if kind == "cuda" and not torch.cuda.is_available():
        ap.error(f"--device {device}: PyTorch sees no CUDA device here; train with --device cpu")


def made_from(*files: str | Path, text: str = "") -> str:
    """What a cached result was made from, to be compared before it is reused: each file's path and its bytes' SHA-256,
    and `text` (e.g. a split's clip list) hashed too."""
    parts = [f"{Path(f).resolve()}:{hashlib.sha256(Path(f).read_bytes()).hexdigest() if Path(f).is_file() else ''}" for f in files]
    return "|".join([*parts, hashlib.sha256(text.encode()).hexdigest()])


def check_run_folder(ap: argparse.ArgumentParser, out: str | Path, resume: bool, *files: str) -> None:
    """A new run does not overwrite one in `out` (any of `files` there); --resume needs out/checkpoint.pt."""
    held = [f for f in files if (Path(out) / f).exists()]
    if resume and "checkpoint.pt" not in held:
        ap.error(f"--resume: {Path(out) / 'checkpoint.pt'} does not exist")
    if held and not resume:
        ap.error(f"{out} already holds a run ({', '.join(held)}): --resume continues it; another --out starts a new one")


def dataset_options(ap: argparse.ArgumentParser) -> None:
    """--template and --masks, for a real dataset (VOCASET, Multiface) whose topology is not in its folder."""
    ap.add_argument("--template", help="template of a real dataset (template.json, or a mesh with --masks), as train.train takes")
    ap.add_argument("--masks", help="region masks for a mesh template")


def dataset_of(args: argparse.Namespace):
    """The dataset at args.corpus, with the template dataset_options named."""
    from .data.datasets import open_dataset
    return open_dataset(args.corpus, getattr(args, "template", None), getattr(args, "masks", None))
