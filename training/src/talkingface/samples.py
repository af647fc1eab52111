"""Sample clips for the demo: test-split clips of the corpus (unseen subjects, voices and sentences) with
their ground truth, so the page can show the error heat map and a side-by-side (paper Fig. 5).

  scripts/py -m talkingface.samples --corpus data/corpus --out models/samples

Per clip: NAME.wav (16-bit PCM, the corpus audio), NAME.gt.bin (little-endian: the subject's neutral
face as float32 (N, 3) in template units, then per frame the offsets of the ground-truth unposed face
from it as int16 micrometres (F, N, 3), then the pose as float32 (F, 6): axis-angle (rad), translation
(template units)). index.json lists them with text, voice, frame count and SHA-256 of each file.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

import numpy as np

from .data.datasets import open_dataset
from .geometry.contours import lip_gap
from .wav import write_wav

DEFAULT_COUNT = 3


def pick(ds, count: int, min_seconds: float = 2.5, max_seconds: float = 5.0) -> list[str]:
    """Short test clips (a sentence, not a word): the recorded human voice first, then synthetic voices,
    each from another voice and, while there are two subjects, from both."""
    rows = []
    for key in ds.keys("test"):
        meta = json.loads((ds.root / "alignments" / f"{key}.json").read_text())
        if min_seconds <= meta["duration"] <= max_seconds:
            rows.append((meta["source"] != "human", meta["duration"], key, meta["subject"], meta["voice"]))
    rows.sort()
    chosen, subjects, voices = [], set(), set()
    for _, _, key, subject, voice in rows:
        if voice in voices or (subject in subjects and len(subjects) < 2):
            continue
        chosen.append(key)
        subjects.add(subject)
        voices.add(voice)
        if len(chosen) == count:
            break
    return chosen


def write_sample(ds, key: str, out: Path) -> dict:
    clip = ds.load(key)
    mm = ds.mm_per_unit
    micrometres = np.round((clip.vertices - clip.template[None]) * mm * 1000.0)
    if np.abs(micrometres).max() > 32767:
        raise ValueError(f"{key}: an offset exceeds 32.7 mm, which int16 micrometres cannot hold")
    pose = clip.pose if clip.pose is not None else np.zeros((clip.num_frames, 6), np.float32)
    body = (clip.template.astype("<f4").tobytes() + micrometres.astype("<i2").tobytes() + pose.astype("<f4").tobytes())
    (out / f"{key}.gt.bin").write_bytes(body)
    write_wav(out / f"{key}.wav", clip.audio, clip.sample_rate)
    return {"name": key, "text": clip.meta.get("text", ""), "voice": clip.meta.get("voice", ""), "source": clip.meta.get("source", ""),
            "subject": clip.subject, "frames": int(clip.num_frames), "fps": float(ds.fps), "seconds": float(len(clip.audio) / clip.sample_rate),
            "audio": f"{key}.wav", "ground_truth": f"{key}.gt.bin", "vertices": int(clip.vertices.shape[1]),
            # The aligned phones (ARPAbet, start s, end s): the demo's timeline labels and the e2e closure test.
            "phones": [[p, round(float(a), 4), round(float(b), 4)] for p, a, b in clip.phones or []],
            # The truth's inner-lip gap per frame (mm, geometry/contours.py): the timeline's truth curve, and the
            # fixture src/template/lip-gap.ts is tested against.
            "lip_gap_mm": np.round(lip_gap(clip.vertices, ds.template) * mm, 4).tolist()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.samples", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", required=True)
    ap.add_argument("--out", type=Path, default=Path("models/samples"))
    ap.add_argument("--count", type=int, default=DEFAULT_COUNT)
    args = ap.parse_args(argv)
    if args.count <= 0:
        ap.error(f"--count must be above 0, not {args.count}")
    ds = open_dataset(args.corpus)
    if ds.layout != "corpus":
        raise SystemExit("samples come from our corpus (it has the alignments with text and voice)")
    args.out.mkdir(parents=True, exist_ok=True)
    # The samples written before (listed in their index.json) are replaced; no other file in OUT is touched.
    before = args.out / "index.json"
    if before.exists():
        for c in json.loads(before.read_text()).get("clips", []):
            for field in ("audio", "ground_truth"):
                if c.get(field) and "/" not in c[field]:
                    (args.out / c[field]).unlink(missing_ok=True)
    clips = [write_sample(ds, key, args.out) for key in pick(ds, args.count)]
    for c in clips:
        for field in ("audio", "ground_truth"):
            c[f"{field}_sha256"] = hashlib.sha256((args.out / c[field]).read_bytes()).hexdigest()
    index = {"format": "talking-face-samples", "version": 1, "template_id": ds.template.id, "units": ds.meta["units"],
             "layout": "gt.bin: float32 (N,3) subject neutral face; int16 (F,N,3) offsets in micrometres; float32 (F,6) pose",
             "clips": clips}
    (args.out / "index.json").write_text(json.dumps(index, indent=1) + "\n")
    total = sum((args.out / c[f]).stat().st_size for c in clips for f in ("audio", "ground_truth"))
    print(f"{len(clips)} sample clips ({total / 1e6:.2f} MB) -> {args.out}: " + ", ".join(c["name"] for c in clips))
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
