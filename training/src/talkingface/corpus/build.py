"""Build the synthetic talking-face corpus: plan it (plan.py), make every clip in worker processes
(clip.py), then write what describes the whole (templates.pkl, splits.json, meta.json, clips.jsonl) in the
community's VOCASET layout plus poses, alignments and splits.

Every clip draws from its own generator seeded by (corpus seed, clip key), so the corpus is the same
whatever the number of workers.
"""
from __future__ import annotations

import json
import logging
import pickle
import shutil
import sys
import time
from dataclasses import asdict
from multiprocessing import get_context
from pathlib import Path

from ..data.datasets import CORPUS_FORMAT
from ..paths import TEMPLATE_DIR
from ..template import load_template
from .clip import build_in_worker, init_worker
from .identity import apply_identity
from .plan import CorpusConfig, is_test_voice, plan
from .speech import all_voices, tool_versions

CORPUS_VERSION = 1
BUILDING_MARKER = ".building"

log = logging.getLogger(__name__)


def build_corpus(out: Path, cfg: CorpusConfig, workers: int = 2, template_path: Path | None = None,
                 overwrite: bool = False, progress=None) -> dict:
    t0 = time.time()
    out = Path(out)
    template_path = Path(template_path or TEMPLATE_DIR / "template.json")
    if out.exists() and any(out.iterdir()):
        if not overwrite:
            raise FileExistsError(f"{out} already exists and is not empty: choose another --out or pass --overwrite")
        if not ((out / "meta.json").exists() or (out / BUILDING_MARKER).exists()):
            raise FileExistsError(f"{out} is not a corpus built by this tool; refusing to overwrite it")
        shutil.rmtree(out)
    template = load_template(template_path)
    subjects, specs = plan(cfg)
    out.mkdir(parents=True, exist_ok=True)
    # Marks an unfinished build, so an interrupted one can be replaced with --overwrite.
    (out / BUILDING_MARKER).write_text("a corpus build started here and has not finished\n")
    for d in ("wav", "vertices_npy", "poses_npy", "alignments", "template"):
        (out / d).mkdir(parents=True, exist_ok=True)
    shutil.copy(template_path, out / "template" / "template.json")
    shutil.copy(template_path.parent / json.loads(template_path.read_text())["binary"], out / "template")

    records = []
    ctx = get_context("fork" if sys.platform.startswith("linux") else "spawn")
    with ctx.Pool(workers, initializer=init_worker, initargs=(str(template_path), subjects, cfg)) as pool:
        for rec in pool.imap_unordered(build_in_worker, [(s, str(out)) for s in specs], chunksize=1):
            records.append(rec)
            if progress:
                progress(len(records), len(specs), rec["key"])
    records.sort(key=lambda r: r["key"])

    faces = {s.name: apply_identity(template, s.identity) for s in subjects}
    with open(out / "templates.pkl", "wb") as f:
        pickle.dump(faces, f, protocol=4)
    splits = {split: [r["key"] for r in records if r["split"] == split] for split in ("train", "val", "test")}
    (out / "splits.json").write_text(json.dumps(splits, indent=1))
    unaligned = recordings_spoken_by_tts(records)
    if unaligned:
        log.warning("%d clip(s) planned as recorded speech are spoken by a TTS voice, their recording could not be "
                    "aligned: %s (meta.json lists them with the reasons)", len(unaligned), ", ".join(unaligned))
    seconds = time.time() - t0
    meta = {
        "format": CORPUS_FORMAT, "version": CORPUS_VERSION, "config": asdict(cfg), "fps": cfg.fps,
        "sample_rate": cfg.sample_rate, "units": template.units, "template_id": template.id,
        "subjects": [dict(s.describe(), split=sp) for s, sp in zip(subjects, ["train"] * cfg.subjects[0] + ["val"] * cfg.subjects[1] + ["test"] * cfg.subjects[2])],
        "voices": {"train": sorted({v.id for v in all_voices() if not is_test_voice(v)}),
                   "test": sorted({v.id for v in all_voices() if is_test_voice(v)})},
        "clips": len(records), "hours": round(sum(r["duration"] for r in records) / 3600, 4),
        # Clips whose recording could not be aligned, spoken by a TTS voice instead (clip.py): key -> recording, reason.
        "recordings_failed_alignment": unaligned,
        "build_seconds": round(seconds, 1), "workers": workers,
        # The speech and the alignments depend on these tools' versions: a corpus is reproduced with the same ones.
        "tool_versions": tool_versions(),
        "pose_convention": "poses_npy: (frames, 6) = axis-angle (rad) and translation; posed y = R (I + O) + t",
        "frame_convention": "frame i shows the face at t = i / fps",
    }
    (out / "meta.json").write_text(json.dumps(meta, indent=1))
    (out / "clips.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    (out / BUILDING_MARKER).unlink()
    return meta


def recordings_spoken_by_tts(records: list[dict]) -> dict[str, dict]:
    """Clip key -> {recording, reason} for every clip planned as recorded speech whose alignment failed."""
    return {r["key"]: r["recording_failed_alignment"] for r in records if "recording_failed_alignment" in r}
