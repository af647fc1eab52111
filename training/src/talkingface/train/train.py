"""Train the model on any dataset `open_dataset` reads (or its clips packed by train/packed.py, on a GPU).

  scripts/py -m talkingface.train.train --corpus data/corpus --out runs/default --minutes 55
  scripts/py -m talkingface.train.train --corpus data/corpus --out runs/lg-mlp --decoder MLP --steps 800
  torchrun --nproc-per-node 2 -m talkingface.train.train ...      (DDP; gloo on the CPU, nccl on GPUs)

Checkpoints (OUT/checkpoint.pt, and OUT/final.pt at the end) carry the model and audio configs,
the training arguments and the step, so `--resume` continues exactly and evaluation/export need
nothing else. An OUT that already holds a run is refused unless `--resume` continues it (nothing there is
overwritten by a new run); Ctrl-C saves OUT/checkpoint.pt first, so `--resume` picks up where it stopped.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch
import torch.distributed as dist

from ..data.datasets import open_dataset
from ..features import AudioConfig
from ..geometry.pose_torch import apply_pose
from ..model import lip_closure as lc
from ..model.config import ModelConfig
from ..model.gava import TalkingFace, count_parameters
from ..paths import REPO_ROOT, TEMPLATE_DIR
from ..phones import PHONE_INDEX, SILENCE
from ..cli import CheckpointError, check_device, check_run_folder, read_checkpoint, require_positive, term_as_interrupt
from ..template import Template, TemplateFormatError, load_template
from . import packed
from .data import attach_rest_faces, mel_statistics, prepare, sample_batch
from .frontend_input import content_warp, load_frontend
from .losses import LossWeights, total_loss
from .metrics import eye_region, inner_lip_pairs, lip_region


def checkpoint_template(ck: dict) -> Template:
    """The template a checkpoint was trained on: the path training recorded (as given, or from the repository
    root), or, where that is not on this machine, the shipped template when it has the recorded id."""
    recorded = Path(ck["template_path"])
    masks = ck.get("args", {}).get("masks")
    for path in (recorded, REPO_ROOT / recorded):
        if path.exists():
            return load_template(path, masks)
    shipped = load_template(TEMPLATE_DIR / "template.json")
    if shipped.id != ck["template_id"]:
        raise TemplateFormatError(f"the checkpoint was trained on template {ck['template_id']!r} ({recorded}), which is not "
                                  f"on this machine and is not the shipped {shipped.id!r}: name it (--template)")
    return shipped


def load_checkpoint(path: Path, template: Template | None = None):
    """-> (model, checkpoint dict). `template` defaults to the one the checkpoint names (checkpoint_template)."""
    return model_of(read_checkpoint(path), template, path)


def model_of(ck: dict, template: Template | None = None, name: str | Path = "the checkpoint"):
    """-> (model, ck) from a checkpoint already read (read_checkpoint); `name` says which file in an error."""
    cfg = ModelConfig.from_dict(ck["model_config"])
    audio = AudioConfig(**ck["audio_config"])
    if template is None:
        template = checkpoint_template(ck)
    if template.id != ck["template_id"]:
        raise CheckpointError(f"{name} was trained on template {ck['template_id']}, not {template.id}: every template needs its own model")
    model = TalkingFace(cfg, template, audio)
    model.load_state_dict(ck["model"])
    return model, ck


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m talkingface.train.train", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--corpus", help="dataset folder (our corpus, processed VOCASET or Multiface)")
    src.add_argument("--packed", help="its training clips packed into one file instead (train/packed.py: for a machine without the dataset)")
    ap.add_argument("--device", default="cpu", help="torch device to train on (cpu, cuda); the checkpoint saved is the same")
    ap.add_argument("--template", help="template for a real dataset (template.json, or a mesh with --masks)")
    ap.add_argument("--masks", help="region masks for a mesh template")
    ap.add_argument("--out", required=True, help="run folder for checkpoints and logs")
    ap.add_argument("--features", default="LG", choices=["G", "L", "LG"])
    ap.add_argument("--decoder", default="GAVA", choices=["GAVA", "SA", "MLP"])
    ap.add_argument("--variant", default="paper", choices=["paper", "released"])
    ap.add_argument("--minutes", type=float, help="stop after this much training time")
    ap.add_argument("--steps", type=int, help="stop after this many steps (one of --minutes / --steps)")
    ap.add_argument("--batch-clips", type=int, default=8, help="clips per step (per process under DDP)")
    ap.add_argument("--frames", type=int, default=8, help="consecutive frames per clip crop")
    ap.add_argument("--lr", type=float, default=1e-3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, help="torch CPU threads per process (default: cores / processes)")
    ap.add_argument("--checkpoint-every", type=int, default=200)
    ap.add_argument("--resume", action="store_true", help="continue from OUT/checkpoint.pt")
    ap.add_argument("--paper-loss", action="store_true", help="the paper's Eq. 3 exactly (no unposed or lip reconstruction terms; see losses.py)")
    ap.add_argument("--silence", type=float, default=0.2,
                    help="chance that a crop is pure silence with the rest face as target (data.py); 0 = the paper's data")
    ap.add_argument("--frontend", help="a speech front-end trained on its own (talkingface.frontend.train: OUT/frontend.pt), "
                    "or a face checkpoint whose content encoder to take (models/checkpoint.pt): it replaces the model's and stays frozen")
    ap.add_argument("--tune-frontend", action="store_true", help="with --frontend: fine-tune it with the face instead of freezing it")
    ap.add_argument("--closure-weight", type=float, default=LossWeights.closure,
                    help="extra weight of the gap term on frames where the true lips are closed (losses.py)")
    ap.add_argument("--init", help="start from this checkpoint's weights (same config; a new run: fresh optimiser and schedule)")
    ap.add_argument("--gap-weight", type=float, default=LossWeights.gap, help="weight of the inner-lip gap term (losses.py)")
    ap.add_argument("--content-warp", type=float, nargs=2, metavar=("LO", "HI"),
                    help="with a frozen --frontend: the content encoder hears each crop with its Mel axis warped by a "
                    "factor between LO and HI (or its inverse), a voice it has not heard (see content_warp)")
    ap.add_argument("--template-input", action="store_true",
                    help="vertex tokens also read the subject's neutral face (encoders.HierarchicalFeature; not the paper's, "
                    "not yet shown better: docs/results/README.md)")
    ap.add_argument("--shape-lr-scale", type=float, default=1.0,
                    help="with --template-input: the shape layer's learning rate over --lr (it starts at zero in a fine-tune)")
    ap.add_argument("--lip-closure", type=float, metavar="MM",
                    help="train with the closure retargeted to each face's own lip gap in the loss (model/lip_closure.py), "
                         "this reference gap in mm: the model learns how far to close, the face sets how far that is")
    ap.add_argument("--lip-weight", type=float, default=LossWeights.lips, help="weight of the lip reconstruction term (losses.py)")
    ap.add_argument("--window-future", type=int, choices=range(0, 4), metavar="FRAMES",
                    help=f"content frames (20 ms each) of the window after the animation frame (default "
                         f"{ModelConfig.window_future}); with --init from a model of another, the window moves and the "
                         "training re-learns it. Look-ahead in all: this, the front-end's and half a Mel frame (export.py)")
    return ap


def parse_args(argv=None) -> argparse.Namespace:
    ap = parser()
    args = ap.parse_args(argv)
    if (args.minutes is None) == (args.steps is None):
        ap.error("give exactly one of --minutes and --steps")
    require_positive(ap, args, "minutes", "steps", "batch_clips", "frames", "checkpoint_every", "threads")
    check_run_folder(ap, args.out, args.resume, "checkpoint.pt", "final.pt")
    if args.content_warp and (not args.frontend or args.tune_frontend):
        ap.error("--content-warp needs a frozen --frontend (it degrades what a trained front-end hears)")
    if args.content_warp and not 0.5 < args.content_warp[0] <= args.content_warp[1] < 2:
        ap.error("--content-warp LO HI: factors with 0.5 < LO <= HI < 2, e.g. 1.12 1.22")
    if args.packed and (args.template or args.masks):
        ap.error("--template and --masks are packed with the clips: give them to train.packed")
    check_device(ap, args.device)
    if args.lip_closure and args.device != "cpu":
        ap.error("--lip-closure retargets each face on the CPU: train with --device cpu")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    distributed = int(os.environ.get("WORLD_SIZE", "1")) > 1
    rank = 0
    if distributed:  # NCCL between GPUs, one each (LOCAL_RANK); gloo between CPU processes
        cuda = args.device.startswith("cuda")
        if cuda:
            args.device = f"cuda:{int(os.environ.get('LOCAL_RANK', '0'))}"
            torch.cuda.set_device(args.device)
        dist.init_process_group("nccl" if cuda else "gloo")
        rank = dist.get_rank()
    world = dist.get_world_size() if distributed else 1
    torch.set_num_threads(args.threads or max(1, (os.cpu_count() or 1) // world))
    log = (lambda *a: print(*a, file=sys.stderr, flush=True)) if rank == 0 else (lambda *a: None)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    t0 = time.time()
    if args.packed:
        clips, template, template_path, fps = packed.load(args.packed)
    else:
        ds = open_dataset(args.corpus, args.template, args.masks)
        template, fps = ds.template, ds.fps
        template_path = args.template or str(Path(args.corpus) / "template" / "template.json")
    audio = AudioConfig(fps=int(fps))
    if not args.packed:
        log(f"preparing {len(ds.keys('train'))} training clips (log-Mel, phones, faces: about 20 s per 500 clips)")
        clips = [prepare(ds, k, audio) for k in ds.keys("train")]
    if not (args.frontend and not args.tune_frontend) and all((c.phones == PHONE_INDEX[SILENCE]).all() for c in clips):
        parser().error(f"{args.corpus or args.packed} has no phone alignments (alignments/, as VOCASET has none), so the content "
                 "encoder would learn to hear only silence: pass --frontend models/checkpoint.pt (the shipped speech "
                 "front-end, frozen) or one of your own (talkingface.frontend.train)")
    frontend = load_frontend(args.frontend) if args.frontend else None
    content_keys = ("content_arch", "content_channels", "content_classes", "content_stride", "content_ahead")
    content_cfg = {k: getattr(ModelConfig.from_dict(frontend["model_config"]), k) for k in content_keys} if frontend else {}
    window = {"window_future": args.window_future} if args.window_future is not None else {}
    cfg = ModelConfig(features=args.features, decoder=args.decoder, variant=args.variant,
                      template_input="L" in args.features and args.template_input, **content_cfg, **window)
    log(f"{cfg.name} ({cfg.variant}): {len(clips)} training clips, {sum(c.num_frames for c in clips)} frames, "
        f"prepared in {time.time() - t0:.0f} s; {world} process(es)")

    if args.silence > 0:
        gaps = attach_rest_faces(clips, template, audio)
        log(f"silence crops: {args.silence:.0%} of crops; rest faces' inner-lip gap {min(gaps.values()):.2f}-{max(gaps.values()):.2f} mm "
            f"({len(gaps)} subjects)")

    torch.manual_seed(args.seed)
    model = TalkingFace(cfg, template, audio)
    mean, std = mel_statistics(clips)
    for norm in (model.pose_encoder.norm,) if frontend else (model.content.norm, model.pose_encoder.norm):
        norm.mean.copy_(torch.from_numpy(mean))
        norm.std.copy_(torch.from_numpy(std))
    if args.init:
        init = read_checkpoint(args.init)
        init_cfg = ModelConfig.from_dict(init["model_config"]).to_dict()
        gains_shape = not init_cfg["template_input"] and cfg.template_input  # a model without the shape input gains it, at zero
        # A --frontend replaces the content encoder, so the initial model's may differ from it (e.g. a look-ahead block).
        free = (content_keys if frontend else ()) + tuple(window)
        own = lambda d: {k: v for k, v in d.items() if k not in free}
        if own(init_cfg | ({"template_input": True} if gains_shape else {})) != own(cfg.to_dict()):
            raise SystemExit(f"--init: {args.init} is a {init['model_config']} model, not {cfg.to_dict()}")
        weights = {k: v for k, v in init["model"].items() if not (frontend and k.startswith("content."))}
        missing, unexpected = model.load_state_dict(weights, strict=False)
        replaced = lambda k: bool(frontend) and k.startswith("content.")
        if init["template_id"] != template.id:
            raise SystemExit(f"--init: {args.init} was trained on template {init['template_id']}, not this dataset's {template.id}")
        if unexpected or any(not (k.startswith("hierarchical.shape_in.") or k == "reference" or replaced(k)) for k in missing):
            raise SystemExit(f"--init: {args.init} does not fit: missing {missing}, unexpected {unexpected}")
        moved = f", its window moved to {cfg.window_future} frames ahead" if init_cfg["window_future"] != cfg.window_future else ""
        log(f"initialised from {args.init} (step {init['step']}){', the shape input added at zero' if gains_shape else ''}{moved}")
    # After --init: the front-end replaces the content encoder the initial weights brought.
    if frontend:  # its own Mel normalisation (statistics of its far larger speech set) comes with it
        model.content.load_state_dict(frontend["content"])
        model.content.requires_grad_(args.tune_frontend)
        log(f"front-end {args.frontend} ({frontend['step']} steps){'' if args.tune_frontend else ', frozen'}")
    model.to(args.device)
    shape = [p for n, p in model.named_parameters() if n.startswith("hierarchical.shape_in.")]
    rest = [p for n, p in model.named_parameters() if p.requires_grad and not n.startswith("hierarchical.shape_in.")]
    opt = torch.optim.Adam([{"params": rest, "scale": 1.0}] + ([{"params": shape, "scale": args.shape_lr_scale}] if shape else []), lr=args.lr)
    step, trained_seconds = 0, 0.0
    ck_path = out / "checkpoint.pt"
    if args.resume:
        ck = torch.load(ck_path, map_location="cpu", weights_only=False)
        if ck["model_config"] != cfg.to_dict():
            raise SystemExit(f"--resume: {ck_path} is a {ck['model_config']} model, not {cfg.to_dict()}")
        model.load_state_dict(ck["model"])
        opt.load_state_dict(ck["optimizer"])
        step, trained_seconds = ck["step"], ck["trained_seconds"]
        log(f"resumed at step {step} ({trained_seconds / 60:.1f} min trained)")
    net = torch.nn.parallel.DistributedDataParallel(model, device_ids=[torch.device(args.device).index] if args.device.startswith("cuda") else None) \
        if distributed else model
    log(f"{count_parameters(model):,} parameters ({count_parameters(model) * 4 / 1e6:.2f} MB float32)")

    eye, lips, pairs = (torch.from_numpy(f(template)).to(args.device) for f in (eye_region, lip_region, inner_lip_pairs))
    rng = np.random.default_rng(args.seed * 1000 + rank + step)
    budget_steps = args.steps
    total_est = budget_steps or 0
    weights = LossWeights.paper() if args.paper_loss else LossWeights(lips=args.lip_weight, gap=args.gap_weight, closure=args.closure_weight)

    def save(path: Path) -> None:
        if rank != 0:
            return
        torch.save({"model": {k: v.cpu() for k, v in model.state_dict().items()}, "optimizer": opt.state_dict(), "step": step,
                    "trained_seconds": trained_seconds, "model_config": cfg.to_dict(), "audio_config": audio.to_dict(),
                    "template_id": template.id, "template_path": template_path, "args": vars(args), "world_size": world}
                   | ({"lip_closure": {"reference_gap_mm": args.lip_closure, "split": "train (in the loss)"}} if args.lip_closure else {}),
                   path.with_suffix(".tmp"))
        os.replace(path.with_suffix(".tmp"), path)

    closers = lc.Closers(template, args.lip_closure) if args.lip_closure else None

    def retarget(out_: dict, faces: torch.Tensor) -> dict:
        """The model's offsets with the closure on each clip's own face (--lip-closure), posed again."""
        o = torch.stack([closers(face.numpy()).torch().apply(out_["offsets"][i]) for i, face in enumerate(faces)])
        unposed = faces[:, None] + o
        return {**out_, "offsets": o, "unposed": unposed, "vertices": apply_pose(unposed, out_["pose"])}

    history = []
    term_as_interrupt()  # a SIGTERM (timeout, a job scheduler) saves the checkpoint as Ctrl-C does
    start = time.time() - trained_seconds
    model.train()
    try:
        while True:
            trained_seconds = time.time() - start
            done = (budget_steps is not None and step >= budget_steps) or (args.minutes is not None and trained_seconds >= 60 * args.minutes)
            if distributed:  # every process stops at the same step
                flag = torch.tensor([1.0 if done else 0.0], device=args.device)
                dist.all_reduce(flag, op=dist.ReduceOp.MAX)
                done = flag.item() > 0
            if done:
                break
            # Cosine decay over the budget (steps, or time when the budget is minutes).
            progress = step / budget_steps if budget_steps else trained_seconds / (60 * args.minutes)
            for g in opt.param_groups:
                g["lr"] = g.get("scale", 1.0) * args.lr * (0.05 + 0.95 * 0.5 * (1 + np.cos(np.pi * min(progress, 1.0))))
            b = sample_batch(clips, rng, args.batch_clips, args.frames, cfg, audio, args.silence)
            heard = content_warp(b.mel, rng, *args.content_warp).to(args.device) if args.content_warp else None
            b = b.to(args.device)
            out_ = net(b.mel, b.mel_index, b.template, content_mel=heard)
            if args.lip_closure:
                out_ = retarget(out_, b.template)
            loss, parts = total_loss(out_, b.vertices, b.pose, b.template, b.content_labels, eye, lips, weights, pairs)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
            opt.step()
            step += 1
            history.append(parts)
            if step % 20 == 0 and rank == 0:
                avg = {k: np.mean([h[k] for h in history[-20:]]) for k in parts}
                rate = step / max(time.time() - start, 1e-9)
                left = ((budget_steps - step) / rate) if budget_steps else (60 * args.minutes - trained_seconds)
                log(f"step {step:6d}  rec {avg['rec']:.3f} mm  unposed {avg['rec_unposed']:.3f} mm  lips {avg['rec_lips']:.3f} mm  gap {avg['gap']:.3f} mm  vel {avg['vel']:.4f}  pose {avg['pose']:.2f}  eye {avg['eye']:.3f}  "
                    f"phones {avg['content']:.3f}  lr {opt.param_groups[0]['lr']:.1e}  {rate:.2f} steps/s  ~{left / 60:.1f} min left")
            if step % args.checkpoint_every == 0:
                save(ck_path)
    except KeyboardInterrupt:  # Ctrl-C: what was trained is kept, and can be continued
        save(ck_path)
        log(f"interrupted at step {step}: saved {ck_path}; the same command with --resume continues it")
        return 130
    save(ck_path)
    save(out / "final.pt")
    if rank == 0:
        (out / "train_log.json").write_text(json.dumps({"steps": step, "minutes": trained_seconds / 60, "world_size": world,
                                                         "model_config": cfg.to_dict(), "args": vars(args),
                                                         "last_100": {k: float(np.mean([h[k] for h in history[-100:]])) for k in history[0]} if history else {}},
                                                        indent=1))
        log(f"done: {step} steps in {trained_seconds / 60:.1f} min -> {out / 'final.pt'}")
    if distributed:
        dist.destroy_process_group()
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
