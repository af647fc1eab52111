"""Evaluate trained models on a dataset's test split with the paper's metrics.

  scripts/py -m talkingface.train.evaluate --corpus data/corpus --checkpoint runs/default/final.pt --out docs/results/default.json

Clips spoken by the recorded human voice are also reported on their own ("human"), apart from the
synthetic voices ("synthetic"), and so are those of them whose sentence no clip of the train split says
("human_unheard"; subsets.py says why).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import torch

from ..cli import dataset_of, dataset_options
from ..features import frame_to_mel_index, log_mel
from ..geometry.contours import lip_gap
from ..geometry.pose import apply_pose as apply_pose_np
from ..model import head_motion as hmodel
from ..model import lip_closure as lc
from . import articulation as art
from . import head_motion as hm
from . import subsets, targets
from .data import prepare
from .metrics import clip_metrics, eye_region, lip_region
from .train import load_checkpoint

# The head-motion measures average this many draws of the head's own motion per clip: one draw per clip leaves the
# spread of a subset of a few clips to chance (recorded speech's 11 test clips: a ratio from 1.13 to 1.41 over the
# eight draws, docs/results/default.md), the expectation is what a re-rolling visitor sees.
HEAD_DRAWS = 8
DRAW_STRIDE = 100_003  # more clips than any split has, so no two (clip, draw) pairs share a seed


def evaluate(model, ds, split: str = "test", progress=None, head_rows: list | None = None, head=None, seed: int = 0,
             lip_closure: float | None = None, mouth_gain: float = 1.0, oracle_phones: bool = False,
             head_draws: int = HEAD_DRAWS) -> dict:
    """The paper's metrics and the articulation and head-motion measures on `split`. `head`: the head's own motion
    (model/head_motion.py), drawn with `seed` and added to the predicted pose as the browser does; None: the mean pose.
    The head-motion measures average `head_draws` draws per clip (draw_seed); the paper's metrics take the first.
    `lip_closure`: the reference gap (mm) that retargets the closure to each face as the browser does
    (model/lip_closure.py), with the mouth's amplitude scaled by `mouth_gain`; None: the model's offsets as they are.
    `oracle_phones`: the face decodes the alignment's phones (phone_logits) instead of what its content encoder heard,
    so the articulation measures say what the face would do with a front-end that hears every phone; the content
    encoder's own figures are still its own."""
    model.eval()
    t = ds.template
    closers = lc.Closers(t, lip_closure, mouth_gain) if lip_closure is not None else None
    regions = (lip_region(t), eye_region(t), t.regions["upper_face"])
    per_clip, artic, heads = [], [], []
    tally = {part: art.ContentTally(model.cfg.content_classes) for part in ("all", "human", "human_unheard")}
    keys = ds.keys(split)
    heard_sentences, said = set(subsets.sentences(ds, "train").values()), subsets.sentences(ds, split)
    for i, key in enumerate(keys):
        c = prepare(ds, key, model.audio)
        tags = {"source": c.source, "sentence_heard": said[key] in heard_sentences if key in said else None}
        mel = torch.from_numpy(c.mel)
        with torch.no_grad():
            heard = model.content(mel[None])[0]                               # (Kc, D): once, for the face and the tally
        decoded = phone_logits(c.phones, model.cfg.content_stride, model.cfg.content_classes) if oracle_phones else heard
        pred_unposed, out = animate_unposed(model, c, closers, decoded)
        pred_pose, pred_posed = out["pose"].numpy(), out["vertices"].numpy()
        if closers:
            pred_posed = apply_pose_np(pred_unposed, pred_pose)
        mel_index = frame_to_mel_index(np.arange(c.num_frames), model.audio)
        env = hm.envelope(c.mel, mel_index)
        if head is not None:
            feats, _ = hmodel.clip_features(model, c.mel, c.num_frames)
            mean_pose = pred_pose
            for k in range(head_draws):
                drawn = hmodel.compose(mean_pose, head.sample(feats, draw_seed(seed, i, k)), head.pivot_mm)
                heads.append(hm.clip_head_motion(c.pose, drawn, env) | tags | {"draw": k})
                if k == 0:
                    pred_pose = drawn
            pred_posed = apply_pose_np(pred_unposed, pred_pose)
        else:
            heads.append(hm.clip_head_motion(c.pose, pred_pose, env) | tags | {"draw": 0})
        gt_posed = apply_pose_np(c.vertices, c.pose)
        m = clip_metrics(c.vertices, pred_unposed, gt_posed, pred_posed, c.template, c.pose, pred_pose, regions)
        m.update(key=key, frames=c.num_frames, **tags)
        per_clip.append(m)
        a = art.clip_articulation(art.inner_lip_gap(c.vertices, t), art.inner_lip_gap(pred_unposed, t), c.segments, ds.fps)
        artic.append(a | tags)
        logits = heard.numpy()
        labels = c.phones[:: model.cfg.content_stride]
        tally["all"].add(logits, labels, c.voice)
        for part in ("human", "human_unheard"):
            if subsets.member(tags, part):
                tally[part].add(logits, labels)
        if progress:
            progress(i + 1, len(keys))
    names = [k for k in per_clip[0] if k not in ("key", "source", "frames", "sentence_heard")]

    def summary(rows):
        if not rows:
            return None
        # Frame-weighted for the per-frame errors, per clip for the sequence statistics (as CodeTalker).
        w = np.array([r["frames"] for r in rows], dtype=np.float64)
        return {n: float(np.average([r[n] for r in rows], weights=w if n.startswith("E_") or n.startswith("pose_error") else None))
                for n in names} | {"clips": len(rows)}
    parts = [name for name, _ in subsets.PARTS]
    of = lambda rows, part: [r for r in rows if subsets.member(r, part)]
    articulation = {part: art.summarise(of(artic, part)) for part in parts}
    content = {part: tally[part].summary() if part == "all" or of(artic, part) else None for part in ("all", "human", "human_unheard")}
    content["by_voice"] = tally["all"].voices()
    if head_rows is not None:  # the per-clip speeds, for the Fig. 4 plot
        head_rows.extend(heads)
    head = {part: hm.summarise_draws(of(heads, part)) for part in parts}
    # A dataset without phone alignments (VOCASET) or head poses: what those measures are taken against, said with them.
    missing = [what for what, folder in (("phone alignments", "alignments"), ("head poses", "poses_npy")) if not (ds.root / folder).is_dir()]
    return {"missing": missing, **{part: summary(of(per_clip, part)) for part in parts},
            "silence": silence_probe(model, t, lip_closure, mouth_gain),
            "articulation": articulation, "content_encoder": content, "head_motion": head, "per_clip": per_clip}


def animate_unposed(model, c, closers: "lc.Closers | None", logits: torch.Tensor | None = None) -> tuple[np.ndarray, dict]:
    """A prepared clip's unposed face (F, N, 3) in mm as the browser shows it: the lips closed by each face's own gap
    when `closers` (model/lip_closure.py); and model.animate's whole output. `logits`: what the face decodes (None: what
    its content encoder hears)."""
    out = model.animate(torch.from_numpy(c.mel), torch.from_numpy(c.template), c.num_frames, logits=logits)
    if closers is None:
        return out["unposed"].numpy(), out
    return c.template[None] + closers(c.template).apply(out["offsets"].numpy()), out


def draw_seed(seed: int, clip: int, draw: int) -> int:
    """The seed of the head's own motion for a clip's draw: clip i's first draw is seed + i (one seed for every clip
    would give them all the same draws, and the measures one sample); later draws move on by DRAW_STRIDE."""
    return seed + clip + DRAW_STRIDE * draw


ORACLE_LOGIT = 8.0  # the aligned phone's logit, every other class's is minus this: a posterior of 1 - 4e-6


def phone_logits(phones: np.ndarray, stride: int, num_classes: int) -> torch.Tensor:
    """The alignment's phone per Mel frame -> content logits (ceil(K / stride), D) that are certain of it."""
    labels = torch.from_numpy(np.asarray(phones[::stride], np.int64))
    logits = torch.full((len(labels), num_classes), -ORACLE_LOGIT)
    logits[torch.arange(len(labels)), labels] = ORACLE_LOGIT
    return logits


def silence_probe(model, template, lip_closure: float | None = None, mouth_gain: float = 1.0) -> dict:
    """Two seconds of digital silence: how far apart does the model leave the inner lips (mm)?
    The corpus rig closes them in silence (about 0.4 mm, docs/corpus)."""
    mm = template.to_millimetres()
    tpl = torch.from_numpy(template.vertices * mm)
    out = model.animate(torch.from_numpy(log_mel(np.zeros(2 * model.audio.sample_rate, np.float32), model.audio)), tpl, 2 * model.audio.fps)
    offsets = out["offsets"].numpy()
    if lip_closure is not None:
        offsets = lc.LipClosure(template, tpl.numpy(), lip_closure, mouth_gain).apply(offsets)
    gap = lip_gap(tpl.numpy()[None] + offsets, template)
    neutral = lip_gap(tpl[None].numpy(), template)[0]
    return {"lip_gap_mean_mm": float(gap.mean()), "lip_gap_max_mm": float(gap.max()), "neutral_template_gap_mm": float(neutral)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.train.evaluate", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", required=True)
    ap.add_argument("--checkpoint", required=True)
    ap.add_argument("--split", default="test")
    ap.add_argument("--out", help="write the results JSON here")
    ap.add_argument("--head-seed", type=int, default=0, help="seed of the head's own motion (clip i's first draw is seed + i; when the checkpoint has one)")
    ap.add_argument("--head-draws", type=int, default=HEAD_DRAWS, help=f"draws of the head's own motion per clip that the head-motion "
                    f"measures average (default {HEAD_DRAWS}; the paper's metrics take the first)")
    ap.add_argument("--mean-pose", action="store_true", help="measure the pose head's mean pose alone, without the head's own motion")
    ap.add_argument("--raw-lips", action="store_true", help="the model's offsets as they are, without the checkpoint's lip closure")
    ap.add_argument("--oracle-phones", action="store_true",
                    help="decode the alignment's phones instead of the content encoder's logits: the face with a front-end that "
                         "hears every phone (a diagnosis of what limits articulation, not a result)")
    dataset_options(ap)
    args = ap.parse_args(argv)
    if args.head_draws < 1:
        ap.error(f"--head-draws: one or more, not {args.head_draws}")
    if args.out:  # checked before the work (minutes of it), not after
        out_dir = Path(args.out).parent
        if out_dir.exists() and not out_dir.is_dir():
            ap.error(f"--out {args.out}: {out_dir} is a file, not a folder")
        if Path(args.out).is_dir():
            ap.error(f"--out {args.out} is a folder: give the JSON file's name")
        if Path(args.out).suffix in (".md", ".png"):
            ap.error(f"--out {args.out}: the JSON's name (the report is written beside it as .md, the plot as _head_motion.png)")
    if not Path(args.checkpoint).is_file():
        ap.error(f"--checkpoint {args.checkpoint} does not exist")
    ds = dataset_of(args)
    model, ck = load_checkpoint(Path(args.checkpoint), ds.template)
    t0 = time.time()
    heads: list = []
    head = hmodel.HeadMotion.from_dict(ck["head_motion"]) if "head_motion" in ck and not args.mean_pose else None
    closure, gain = (None, 1.0) if args.raw_lips else lc.calibration(ck)

    def progress(i: int, n: int) -> None:
        if i % 10 == 0 or i == n:
            print(f"  {i}/{n} clips ({time.time() - t0:.0f} s)", file=sys.stderr, flush=True)

    res = evaluate(model, ds, args.split, progress=progress, head_rows=heads, head=head, seed=args.head_seed, lip_closure=closure,
                   mouth_gain=gain, oracle_phones=args.oracle_phones, head_draws=args.head_draws)
    res["oracle_phones"], res["split"] = args.oracle_phones, args.split
    res["lip_closure"] = {"reference_gap_mm": closure, "mouth_gain": gain} if closure is not None else None
    res["checkpoint"] = {"path": args.checkpoint, "step": ck["step"], "minutes": ck["trained_seconds"] / 60,
                         "model_config": ck["model_config"]}
    res["head_motion"]["sampled"] = {"seed": args.head_seed, "draws": args.head_draws} if head is not None else None
    res["head_motion"]["fit"] = ck.get("head_motion_fit") if head is not None else None
    res["eval_seconds"] = time.time() - t0
    issue_targets = args.split == "test" and not args.oracle_phones  # the issues set them on the test split
    res["targets"] = targets.check(res) if issue_targets else None
    a = res["all"]
    for line in missing_notes(res):
        print(f"note: {line}", file=sys.stderr)
    print(f"{ck['model_config']['features']}+{ck['model_config']['decoder']}: E_vl {a['E_vl']:.3f} mm  E_ve {a['E_ve']:.3f} mm  "
          f"FDD {a['FDD']:.4f}  AFDD {a['AFDD']:.4f}  pose {a['pose_error_deg']:.2f} deg  jitter {a['pose_jitter_deg']:.3f} deg"
          + (f"  | human E_vl {res['human']['E_vl']:.3f} mm" if res["human"] else ""))
    ar, ce = res["articulation"]["all"], res["content_encoder"]["all"]
    pct = lambda x: "-" if x is None else f"{100 * x:.1f}%"  # None: nothing of the kind in the split
    print(f"/p b m/ closed {pct(ar['pred_closure'])} (truth {pct(ar['true_closure'])}, chance {pct(ar['chance_closure'])}), "
          f"closed elsewhere {pct(ar['pred_false_closure'])} (truth {pct(ar['true_false_closure'])}), open vowels opened "
          f"{pct(ar['pred_open_vowel_opened'])} (on /p b m/ {pct(ar['pred_bilabial_opened'])}), gap correlation {ar['gap_corr']:.2f}; "
          f"content encoder frame accuracy {pct(ce['frame_accuracy'])}, /p b m/ heard {pct(ce['bilabial_segments_heard'])} "
          f"(in other speech {pct(ce['bilabial_false_calls'])})")
    if args.out:
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        plot = out.with_name(out.stem + "_head_motion.png")
        hm.plot_speed_histogram(heads, plot, f"{ck['model_config']['features']}+{ck['model_config']['decoder']}, "
                                             f"{args.split} split: head rotation per frame")
        out.write_text(json.dumps(res, indent=1))
        out.with_suffix(".md").write_text(markdown(res, args, ck, plot.name))
    return 0


def missing_notes(res: dict) -> list[str]:
    """What the figures mean where the dataset lacks an input (res["missing"])."""
    said = {"phone alignments": "the dataset has no phone alignments: the content encoder's and the articulation figures "
                                "are measured against silence labels, and mean nothing here",
            "head poses": "the dataset has no head poses: the pose figures are measured against a still head"}
    return [said[m] for m in res.get("missing", [])]


def markdown(res: dict, args, ck: dict, head_plot: str) -> str:
    cfg = ck["model_config"]
    rows = []
    for name, label in subsets.labels(args.split):
        r = res.get(name)
        if r:
            rows.append(f"| {label} | {r['clips']} | {r['E_vl']:.3f} | {r['E_ve']:.3f} | {r['E_vl_posed']:.3f} | {r['FDD']:.4f} | "
                        f"{r['AFDD']:.4f} | {r['pose_error_deg']:.2f} | {r['pose_jitter_deg']:.3f} ({r['pose_jitter_gt_deg']:.3f}) | "
                        f"{r['lip_motion_gt']:.2f} / {r['lip_motion_pred']:.2f} |")
    return "\n".join([
        f"# {cfg['features']}+{cfg['decoder']} on the {args.split} split",
        "",
        f"Checkpoint `{args.checkpoint}`: {ck['step']} steps, {ck['trained_seconds'] / 60:.1f} min of training "
        f"({ck.get('world_size', 1)} process(es)). Made by",
        f"`scripts/py -m talkingface.train.evaluate --corpus {args.corpus} --checkpoint {args.checkpoint} --split {args.split} --out {args.out}"
        f"{' --raw-lips' if getattr(args, 'raw_lips', False) else ''}{' --oracle-phones' if getattr(args, 'oracle_phones', False) else ''}`.",
        "",
        *[f"**Note**: {line}" for line in missing_notes(res)],
        *([""] if missing_notes(res) else []),
        *(["**Oracle phones**: the face decodes the alignment's phones (certain, one-hot) instead of what its content encoder",
           "heard: what it would do with a front-end that hears every phone. A diagnosis, not a result; the content encoder's",
           "table below is still its own.", ""] if getattr(args, "oracle_phones", False) else []),
        (f"Lip closure retargeted to each face's own lip gap (reference gap {res['lip_closure']['reference_gap_mm']:.3f} mm, "
         f"the mouth's amplitude x{res['lip_closure'].get('mouth_gain', 1.0):g}, "
         "`training/src/talkingface/model/lip_closure.py`), as the browser does." if res.get("lip_closure") else
         "The model's offsets as they are (no lip closure retargeting)."),
        "",
        "Errors in mm. E_vl / E_ve: mean over frames of the largest lip / eye vertex error on the unposed face (Eq. 8);",
        "E_vl posed: the same with the predicted head pose applied. FDD (Eq. 9, signed) and AFDD (Eq. 10) on the upper face.",
        "Pose error: angle between true and predicted head rotation; jitter: mean second difference of the predicted",
        "rotation per frame (ground truth's in brackets).",
        "",
        "| clips | n | E_vl | E_ve | E_vl posed | FDD | AFDD | pose error (deg) | jitter (deg) | lip motion: true / predicted |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        *rows,
        "",
        "Lip motion: mean over frames of the largest lip-vertex displacement from the neutral face.",
        f"Baseline: a face that never moves scores E_vl {res['all']['E_vl_still_face']:.3f} mm on the same clips.",
        f"Silence (2 s of zeros): inner-lip gap {res['silence']['lip_gap_mean_mm']:.2f} mm on average, at most "
        f"{res['silence']['lip_gap_max_mm']:.2f} (0 = touching, below 0 pressed together; the neutral template: "
        f"{res['silence']['neutral_template_gap_mm']:.2f}).",
        "",
        *art.markdown(res),
        *hm.markdown(res, head_plot),
        *(targets.markdown(res) if res.get("targets") else []),
    ])


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
