"""The dataset card: statistics and plots of a built corpus, written as Markdown + PNG.

  scripts/py -m talkingface.corpus card --corpus data/corpus --out docs/corpus
"""
from __future__ import annotations

import collections
import json
from pathlib import Path

import numpy as np

from ..data.datasets import open_dataset
from ..geometry.pose import pose_degrees, pose_step_degrees
from ..phones import BILABIALS, OPEN_VOWELS, PHONES, SILENCE
from .checks import eye_gap_mm, gaps_at, lip_gap_mm


def write_card(corpus_dir: Path, out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ds = open_dataset(corpus_dir)
    meta = ds.meta
    out.mkdir(parents=True, exist_ok=True)
    records = [json.loads(line) for line in (corpus_dir / "clips.jsonl").read_text().splitlines()]
    by_split = collections.defaultdict(list)
    for r in records:
        by_split[r["split"]].append(r)

    phone_counts = collections.Counter()
    phone_seconds = collections.Counter()
    pose_all, step_max, bil, opn, blinks_per_min = [], [], [], [], []
    speech_seconds = 0.0
    blink_list = []
    example = None
    for r in records:
        clip = ds.load(r["key"])
        for p, a, b in clip.phones:
            phone_counts[p] += 1
            phone_seconds[p] += b - a
        lip = lip_gap_mm(clip, ds.template, ds.mm_per_unit)
        bil += [g for _, _, g in gaps_at(clip, lip, BILABIALS)]
        opn += [g for _, _, g in gaps_at(clip, lip, OPEN_VOWELS, 0.08)]
        pose_all.append(pose_degrees(clip.pose))
        step_max.append(pose_step_degrees(clip.pose).max())
        speech_seconds += clip.audio.size / clip.sample_rate
        blink_list += clip.meta["blinks"]
        if example is None and r["source"] == "tts" and r["split"] == "test" and 3.0 < r["duration"] < 5.0:
            example = (clip, lip, eye_gap_mm(clip, ds.template, ds.mm_per_unit))
    blinks_per_min = 60 * len(blink_list) / max(speech_seconds, 1e-9)
    expected_per_min = np.mean([120 / sum(s["style"]["blink_interval"]) for s in meta["subjects"]])
    blink_ms = 1000 * np.mean([b[1] for b in blink_list]) if blink_list else 0.0
    partial = np.mean([b[2] < 1 for b in blink_list]) if blink_list else 0.0
    pose_all = np.concatenate(pose_all)

    # Phoneme coverage.
    fig, ax = plt.subplots(figsize=(11, 3.2))
    names = [p for p in PHONES if p != SILENCE]
    ax.bar(names, [phone_counts[p] for p in names], color="#4a78b5")
    ax.set_ylabel("segments")
    ax.set_title("Phone coverage (ARPAbet, all clips)")
    ax.tick_params(axis="x", labelrotation=90, labelsize=8)
    fig.tight_layout()
    fig.savefig(out / "phones.png", dpi=90)
    plt.close(fig)

    # Durations.
    fig, ax = plt.subplots(figsize=(5, 3))
    ax.hist([r["duration"] for r in records], bins=30, color="#5a9c6b")
    ax.set_xlabel("clip duration (s)")
    ax.set_ylabel("clips")
    fig.tight_layout()
    fig.savefig(out / "durations.png", dpi=90)
    plt.close(fig)

    # Pose movement (the paper's Fig. 4 shows the same histogram for its augmented VOCASET).
    fig, ax = plt.subplots(figsize=(5, 3))
    ax.hist(pose_all, bins=40, color="#b5714a")
    ax.set_xlabel("head rotation from neutral (degrees)")
    ax.set_ylabel("frames")
    fig.tight_layout()
    fig.savefig(out / "pose.png", dpi=90)
    plt.close(fig)

    # One clip: lip aperture and eye opening against its phone track.
    if example:
        clip, lip, eye = example
        t = np.arange(clip.num_frames) / clip.fps
        fig, (ax, ax2) = plt.subplots(2, 1, figsize=(11, 4.2), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
        ax.plot(t, lip, color="#b03a48", label="inner-lip opening (mm)")
        for p, a, b in clip.phones:
            color = "#ffd9d9" if p in BILABIALS else "#e8f0ff" if p in OPEN_VOWELS else None
            if color:
                ax.axvspan(a, b, color=color, zorder=0)
            if p != SILENCE:
                ax.text(0.5 * (a + b), ax.get_ylim()[1] * 0.02 + lip.max() * 1.02, p, ha="center", fontsize=7)
        ax.set_ylabel("mm")
        ax.set_title(f"{clip.key} ({clip.meta['voice']}): \"{clip.meta['text']}\"  red: /p b m/, blue: open vowels", fontsize=9)
        ax.legend(loc="upper right", fontsize=8)
        ax2.plot(t, eye, color="#333")
        ax2.set_ylabel("eye (mm)")
        ax2.set_xlabel("time (s)")
        fig.tight_layout()
        fig.savefig(out / "lip_aperture.png", dpi=90)
        plt.close(fig)

    voices = collections.Counter(r["voice"].split(":")[0] for r in records)
    aligned = [r for r in records if r["timing"] == "aligned"]
    aug = collections.Counter(k for r in records for k in r["augment"] if k != "gain_db")
    rows = []
    for split in ("train", "val", "test"):
        rs = by_split[split]
        rows.append(f"| {split} | {len({r['subject'] for r in rs})} | {len(rs)} | {sum(r['duration'] for r in rs) / 60:.1f} | "
                    f"{sum(r['source'] == 'human' for r in rs)} | {len({r['voice'] for r in rs})} |")
    missing = [p for p in PHONES if phone_counts[p] == 0]
    cfg = meta["config"]
    tools = ", ".join(f"{k} {v}" for k, v in meta.get("tool_versions", {}).items()) or "versions not recorded"
    text = f"""# Dataset card: the synthetic talking-face corpus

Generated by `scripts/py -m talkingface.corpus card --corpus {corpus_dir} --out {out}` from a corpus built with
`scripts/py -m talkingface.corpus build --preset {cfg['preset']} --seed {cfg['seed']} --out {corpus_dir}` (corpus format version {meta['version']}).
Every number below is computed from the files of that corpus.

## What it is
Speech with phone timings and, for every 1/{meta['fps']} s frame, the exact 3D face that a procedural articulation
rig makes of it, on the MediaPipe canonical face (template `{meta['template_id']}`, units {meta['units']}), plus a head-pose
track. It stands in for VOCASET's 4D scans with the paper's pose augmentation. Layout: `wav/`, `vertices_npy/` (frames x N*3, unposed I + O), `templates.pkl` (subject -> neutral face),
`poses_npy/` (frames x 6: axis-angle + translation, posed y = R (I + O) + t), `alignments/` (phones, voice, text,
augmentation, blinks), `splits.json`, `meta.json`, `template/` (topology and regions).

## Size
{meta['clips']} clips, {speech_seconds / 60:.1f} minutes of audio, {len(meta['subjects'])} subjects; built in {meta['build_seconds']:.0f} s
with {meta['workers']} worker processes.

| split | subjects | clips | minutes | recorded-speech clips | distinct voices |
| --- | --- | --- | --- | --- | --- |
{chr(10).join(rows)}

Test subjects, test sentences and test voices never occur in training. Held-out voices:
{', '.join(meta['voices']['test'])}.

Built with (Debian packages and Python packages the speech and alignments depend on):
{tools}.

## Voices
Clips per engine: {', '.join(f'{k} {v}' for k, v in sorted(voices.items()))}. Festival and flite give their own phone
timings; espeak-ng and the recorded speech (Debian's asterisk-core-sounds-en-wav, one female speaker, CC-BY-SA-3.0)
are force-aligned with pocketsphinx ({len(aligned)} clips: {sum(r.get('align_method') == 'two-pass' for r in aligned)} two-pass,
{sum(r.get('align_method') == 'one-pass-phones' for r in aligned)} by the one-pass fallback;
{sum('voices_failed_alignment' in r for r in records)} clips switched voice after a failed alignment).
{recorded_fallback(meta)}
The aligner's accuracy against synthesiser ground truth is checked in `training/tests/corpus/test_align.py`
(mean boundary error below 25 ms).

## Phonemes
All {len(PHONES) - 1} ARPAbet phones occur{'' if not missing or missing == [SILENCE] else ' except ' + ', '.join(missing)}; rarest:
{', '.join(f'{p} {phone_counts[p]}' for p in sorted(names, key=lambda p: phone_counts[p])[:5])}.

![phone coverage](phones.png)

![durations](durations.png)

## Geometry checks (all clips)
- Inner lips at the centre frame of each /p b m/ ({len(bil)} segments): largest gap {max(bil, default=0):.2f} mm.
- Open vowels /aa ae ah ao aw ay/ of at least 80 ms ({len(opn)}): opening min {min(opn, default=0):.1f} mm,
  median {np.median(opn) if opn else 0:.1f} mm.
- Blinks: {blinks_per_min:.1f} per minute ({len(blink_list)} blinks; the subjects' styles give {expected_per_min:.1f} on average,
  intervals between {min(s['style']['blink_interval'][0] for s in meta['subjects']):.1f} and
  {max(s['style']['blink_interval'][1] for s in meta['subjects']):.1f} s), {blink_ms:.0f} ms long on average, {100 * partial:.0f}% partial.
- Head pose: median rotation {np.median(pose_all):.1f} degrees, 95th percentile {np.percentile(pose_all, 95):.1f};
  largest frame-to-frame change {max(step_max):.2f} degrees.

![pose movement](pose.png)

![lip aperture against the phone track](lip_aperture.png)

## Augmentation
{len(records) - sum(1 for r in records if len(r['augment']) > 1)} clips are clean (level only). Counts:
{', '.join(f'{k} {v}' for k, v in sorted(aug.items()))}.

## Licences
Face template: MediaPipe canonical face, Apache-2.0 (models/template/NOTICE). Recorded speech:
asterisk-core-sounds-en-wav, CC-BY-SA-3.0. Synthetic speech: festival, flite and espeak-ng output.
"""
    path = out / "README.md"
    path.write_text(text)
    return path


def recorded_fallback(meta: dict) -> str:
    """The card's line on clips planned as recorded speech that a TTS voice speaks (their alignment failed)."""
    failed = meta.get("recordings_failed_alignment")
    if failed is None:
        return "(This corpus predates the count of recordings whose alignment failed.)"
    if not failed:
        return "Every recording planned for a clip was aligned."
    return (f"{len(failed)} clip(s) planned as recorded speech are spoken by a TTS voice instead, their recording could not be "
            "aligned: " + "; ".join(f"{k} ({v['recording']}: {v['reason']})" for k, v in sorted(failed.items())) + ".")
