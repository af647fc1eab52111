"""Train the speech front-end (the content encoder) on its own, before and apart from the face.

  scripts/py -m talkingface.frontend.train --speech data/speech --corpus data/corpus --out runs/frontend --minutes 30

Frame-wise cross-entropy against the phone labels of the speech set (speechset.py), on random 3 s crops with
frequency warping (vocal-tract length, 0.9-1.1) and SpecAugment-style masks. Every --eval-every steps it is
measured on the mesh corpus's val and test splits, whose voices, sentences and recordings it never trains on.
OUT/frontend.pt carries the encoder's weights (its Mel normalisation included), the model config, and the
evaluation; `talkingface.train.train --frontend OUT/frontend.pt` puts it into the face model, frozen.

On a machine with a GPU and neither the speech set nor the corpus, train from frontend.bank's packed file:

  python -m talkingface.frontend.train --packed runs/bank.npz --device cuda --batch 256 --out runs/frontend --minutes 7
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
import torch.nn.functional as F

from ..cli import check_device, check_run_folder, require_positive, term_as_interrupt
from ..data.datasets import open_dataset
from ..features import AudioConfig
from ..model.config import ModelConfig
from ..model.encoders import ContentEncoder
from ..phones import BILABIALS, PHONE_INDEX
from ..train import articulation as art
from ..train.data import prepare
from ..train.train import load_frontend
from .bank import Bank, PAD_LABEL, spec_augment, timbre, unpack, warp, warp_factors
from .losses import distillation, view_disagreement
from .measure import load_encoder


def widen(enc: ContentEncoder, cfg: ModelConfig, seed: int = 0) -> ContentEncoder:
    """`enc` with cfg.content_channels channels, computing the same function: every weight into a new channel is zero
    (so new channels stay at zero, and the residual blocks pass the old ones through unchanged), and the weights out of
    the new channels are small and random, so the gradient reaches them and they learn. Net2Net's idea
    (Chen et al. 2016) by zeros instead of copies."""
    wide = ContentEncoder(cfg, enc.norm.mean.numel())
    g = torch.Generator().manual_seed(seed)
    state = {}
    for name, old in enc.state_dict().items():
        new = torch.zeros_like(wide.state_dict()[name])
        if new.shape == old.shape:
            state[name] = old.clone()
            continue
        if any(a < b for a, b in zip(new.shape, old.shape)):
            raise ValueError(f"widen: {name} is {tuple(old.shape)}, wider than {tuple(new.shape)}")
        if new.dim() == 3 and new.shape[1] > old.shape[1]:  # (out, in, taps): columns out of the new input channels
            fan_in = new.shape[1] * new.shape[2]
            new[:, old.shape[1]:] = torch.randn(new.shape[0], new.shape[1] - old.shape[1], new.shape[2], generator=g) * (0.5 / fan_in ** 0.5)
            new[old.shape[0]:] = 0
        new[tuple(slice(0, n) for n in old.shape)] = old
        state[name] = new
    wide.load_state_dict(state)
    return wide


def look_further(enc: ContentEncoder, cfg: ModelConfig) -> ContentEncoder:
    """`enc` with the last block cfg.content_ahead adds (encoders.ContentEncoder), computing the same function: the block's
    convolution starts at zero, so the residual passes everything through (gelu(0) = 0), and its gradient is not zero
    (gelu'(0) = 1/2), so it learns what the frames ahead add."""
    if len(getattr(enc, "blocks", ())) != len(ContentEncoder.DILATIONS):
        raise ValueError("look_further: expected a dilated content encoder without a look-ahead block")
    out = ContentEncoder(cfg, enc.norm.mean.numel())
    extra = out.blocks[len(enc.blocks)].conv
    state = enc.state_dict() | {f"blocks.{len(enc.blocks)}.conv.{k}": torch.zeros_like(v) for k, v in extra.state_dict().items()}
    out.load_state_dict(state)
    return out


def load_speech(folder: Path, seen: set[str] | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """A speech set's clips, (log-Mel, phone per Mel frame). With `seen`, a clip already read from another set (the
    same index row: voice, text, seed, augmentation; sets built as variants of one draw share most clips) is left
    out, and every row read is added to it."""
    rows = [json.loads(l) for l in (folder / "index.jsonl").read_text().splitlines()]
    rows = [r for r in rows if "skipped" not in r]
    if not rows:
        raise SystemExit(f"no clips in {folder}: build it with python -m talkingface.frontend.speechset")
    out = []
    for r in rows:
        if seen is not None:
            row = json.dumps(r, sort_keys=True)
            if row in seen:
                continue
            seen.add(row)
        z = np.load(folder / f"{r['key']}.npz")
        out.append((z["mel"].astype(np.float32), z["labels"].astype(np.int64)))
    return out


def forward_augmented(enc: ContentEncoder, mel: torch.Tensor, rng) -> torch.Tensor:
    """The encoder's forward with SpecAugment between its normalisation and its convolutions."""
    x = spec_augment(enc.norm(mel), rng)
    identity = enc.norm
    enc.norm = torch.nn.Identity()
    try:
        return enc(x)
    finally:
        enc.norm = identity


@torch.no_grad()
def evaluate(enc: ContentEncoder, clips: list[tuple[np.ndarray, np.ndarray]], num_classes: int, stride: int) -> dict:
    """Frame accuracy, per-phone recall and /p b m/ heard over (mel, phones) clips."""
    enc.eval()
    tally = art.ContentTally(num_classes)
    dev = next(enc.parameters()).device
    for mel, phones in clips:
        tally.add(enc(torch.from_numpy(mel)[None].to(dev))[0].cpu().numpy(), phones[::stride])
    enc.train()
    return tally.summary()


def read_speech(speech: list[Path], corpus: Path, no_corpus_train: bool, audio: AudioConfig) -> tuple[list, dict]:
    """-> training clips (the speech sets', and the corpus's train split unless no_corpus_train), and the corpus's
    {"val": clips, "test": clips}; each clip (log-Mel (K, n_mels), phone per Mel frame (K,))."""
    seen: set[str] = set()  # a clip that several sets hold is read once
    clips = [c for folder in speech for c in load_speech(folder, seen)]
    ds = open_dataset(corpus)
    prepared = lambda split: [(c.mel, c.phones) for c in (prepare(ds, k, audio) for k in ds.keys(split))]
    if not no_corpus_train:  # its festival and flite voices are few in the speech set; no val/test material
        clips += prepared("train")
    return clips, {split: prepared(split) for split in ("val", "test")}


def read_args_speech(args, audio: AudioConfig) -> tuple[list, dict]:
    """read_speech's clips from --packed, or from --speech and --corpus."""
    if args.packed:
        if args.speech or args.corpus or args.no_corpus_train:
            raise SystemExit("--packed holds the speech and the measuring clips: leave out --speech, --corpus and "
                             "--no-corpus-train (frontend.bank takes them)")
        parts = unpack(args.packed)
        return parts["train"], {s: parts[s] for s in ("val", "test")}
    if not (args.speech and args.corpus):
        raise SystemExit("give --speech and --corpus (or --packed)")
    return read_speech(args.speech, args.corpus, args.no_corpus_train, audio)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.frontend.train", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--speech", type=Path, nargs="+",
                    help="speech set folder(s) (talkingface.frontend.speechset; several seeds are several sets)")
    ap.add_argument("--corpus", type=Path, help="mesh corpus whose val/test splits measure it")
    ap.add_argument("--packed", type=Path, help="instead of --speech and --corpus: one file of frontend.bank's, "
                    "the training speech and the measuring clips together (for a machine that holds neither)")
    ap.add_argument("--device", default="cpu", help="torch device to train on (cpu, cuda); the front-end saved is the same")
    ap.add_argument("--snapshots", action="store_true",
                    help="also keep the front-end at every evaluation (OUT/frontend-step<N>.pt), to choose one on val")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--minutes", type=float, default=30.0, help="training time budget (the cosine schedule spans it)")
    ap.add_argument("--steps", type=int, help="a step budget instead of --minutes (the same run on any machine)")
    ap.add_argument("--batch", type=int, default=16)
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--eval-every", type=int, default=500)
    ap.add_argument("--resume", action="store_true", help="continue from OUT/checkpoint.pt")
    ap.add_argument("--init", help="start from this front-end (a frontend.pt, or a face checkpoint's content encoder, "
                    "its Mel normalisation included); a new run: fresh optimiser and schedule")
    ap.add_argument("--no-corpus-train", action="store_true",
                    help="leave out the mesh corpus's train split (by default its speech trains the front-end too)")
    ap.add_argument("--channels", type=int, default=ModelConfig.content_channels,
                    help="the content encoder's width (default %(default)s); an --init front-end that is narrower is widened "
                         "to it, computing the same function at the start (widen)")
    ap.add_argument("--ahead", type=int, default=0, metavar="FRAMES",
                    help="a last residual block reading one tap FRAMES content frames (20 ms each) ahead: more look-ahead for "
                         "the front-end, and as much more streaming latency (default 0: none). An --init front-end without it "
                         "gets it computing the same function at the start (look_further)")
    ap.add_argument("--consistency", type=float, default=0.0, metavar="WEIGHT",
                    help="train on two views of each crop (two vocal-tract warps, two sets of masks) and add WEIGHT x the "
                         "symmetric KL divergence between their posteriors: hearing a phone the same whatever the voice's "
                         "length of tract, which unseen voices differ in (twice the work per step)")
    ap.add_argument("--timbre", type=float, default=0.0, metavar="FRACTION",
                    help="give this fraction of the crops another timbre (bank.timbre: a smooth random gain along the Mel "
                         "axis, the fine structure across bands partly smoothed); with --consistency each view its own")
    ap.add_argument("--teacher", metavar="FRONTEND",
                    help="distil from this front-end (a frontend.pt or a face checkpoint; A+B+...: their ensemble, the mean "
                         "of their log-posteriors, as frontend.measure hears it), heard on each crop before its masks")
    ap.add_argument("--distill", type=float, default=1.0, metavar="WEIGHT",
                    help="with --teacher: WEIGHT x the KL divergence from the teacher's posteriors to the student's, added "
                         "to the cross-entropy against the labels (which keeps its --bilabial-weight)")
    ap.add_argument("--bilabial-weight", type=float, default=2.0,
                    help="cross-entropy weight of P, B and M frames: a missed bilabial costs a closed mouth")
    args = ap.parse_args(argv)
    if not 0 <= args.timbre <= 1:
        ap.error(f"--timbre: a fraction of the crops, between 0 and 1, not {args.timbre}")
    require_positive(ap, args, "minutes", "steps", "batch", "threads", "eval_every")
    check_run_folder(ap, args.out, args.resume, "checkpoint.pt", "frontend.pt")
    check_device(ap, args.device)
    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    rng = np.random.default_rng(args.seed)
    args.out.mkdir(parents=True, exist_ok=True)
    log = lambda *a: print(*a, file=sys.stderr, flush=True)

    cfg, audio = ModelConfig(content_channels=args.channels, content_ahead=args.ahead), AudioConfig()
    clips, held = read_args_speech(args, audio)
    bank = Bank.from_clips(clips, args.device)
    del clips
    log(f"front-end: {len(bank.starts)} clips, {bank.minutes(audio.feature_rate):.1f} min of speech on {args.device}; "
        f"measured on {len(held['val'])} val / {len(held['test'])} test clips of {args.packed or args.corpus}")

    enc = ContentEncoder(cfg, audio.n_mels)
    enc.norm.mean.copy_(bank.mel.mean(0).cpu())
    enc.norm.std.copy_(bank.mel.std(0).cpu() + 1e-3)
    if args.init:
        init = load_frontend(args.init)
        arch = {k: cfg.to_dict()[k] for k in ("content_arch", "content_classes", "content_stride")}
        init_cfg = ModelConfig.from_dict(init["model_config"])
        if any(init["model_config"][k] != v for k, v in arch.items()) or init_cfg.content_channels > args.channels:
            raise SystemExit(f"--init: {args.init} has another content encoder than {arch | {'content_channels': args.channels}} "
                             f"(it has {init_cfg.content_channels} channels)")
        if init_cfg.content_ahead not in (0, args.ahead):
            raise SystemExit(f"--init: {args.init} reads {init_cfg.content_ahead} content frames further ahead, not --ahead "
                             f"{args.ahead}: a block's look-ahead cannot be changed without changing what it computes")
        narrow = ContentEncoder(init_cfg, audio.n_mels)
        narrow.load_state_dict(init["content"])
        enc = widen(narrow, ModelConfig(**init_cfg.to_dict() | {"content_channels": args.channels}), args.seed) \
            if init_cfg.content_channels < args.channels else narrow
        if init_cfg.content_ahead != args.ahead:
            enc = look_further(enc, cfg)
        log(f"initialised from {args.init} ({init['step']} steps" +
            (f", widened from {init_cfg.content_channels} to {args.channels} channels" if init_cfg.content_channels < args.channels else "") +
            (f", with a last block reading {args.ahead} content frames ahead" if init_cfg.content_ahead != args.ahead else "") + ")")
    enc.to(args.device)
    teacher = None
    if args.teacher:
        teacher, teacher_cfg = load_encoder(args.teacher)
        if (teacher_cfg.content_classes, teacher_cfg.content_stride) != (cfg.content_classes, cfg.content_stride):
            raise SystemExit(f"--teacher: {args.teacher} hears another phone set or stride than the student")
        teacher.to(args.device).eval().requires_grad_(False)
        log(f"distilling from {args.teacher} (weight {args.distill})")
    class_weight = torch.ones(cfg.content_classes, device=args.device)
    class_weight[[PHONE_INDEX[p] for p in BILABIALS]] = args.bilabial_weight
    opt = torch.optim.AdamW(enc.parameters(), lr=args.lr, weight_decay=1e-4)
    step, trained, history = 0, 0.0, []
    ck_path = args.out / "checkpoint.pt"
    if args.resume:
        ck = torch.load(ck_path, map_location="cpu", weights_only=False)
        if ck["model_config"] != cfg.to_dict():
            raise SystemExit(f"--resume: {ck_path} is a {ck['model_config']} front-end, not {cfg.to_dict()} (give the run's own options)")
        enc.load_state_dict(ck["content"])
        enc.to(args.device)
        opt.load_state_dict(ck["optimizer"])
        step, trained, history = ck["step"], ck["trained_seconds"], ck["history"]
        log(f"resumed at step {step} ({trained / 60:.1f} min)")

    def save(path: Path, final: bool = False) -> None:
        paths = {k: str(v) if v else None for k, v in (("corpus", args.corpus), ("packed", args.packed), ("out", args.out))}
        payload = {"content": {k: v.cpu() for k, v in enc.state_dict().items()}, "optimizer": opt.state_dict(),
                   "step": step, "trained_seconds": trained, "history": history, "model_config": cfg.to_dict(),
                   "audio_config": audio.to_dict(), "args": vars(args) | paths | {"speech": [str(f) for f in args.speech or []]}}
        if final:
            payload.pop("optimizer")
        torch.save(payload, path.with_suffix(".tmp"))
        os.replace(path.with_suffix(".tmp"), path)

    term_as_interrupt()  # a SIGTERM (timeout, a job scheduler) saves the checkpoint as Ctrl-C does
    start = time.time() - trained
    losses = []
    progress = (lambda: step / args.steps) if args.steps is not None else (lambda: trained / (60 * args.minutes))
    try:
        while True:
            trained = time.time() - start
            if progress() >= 1:
                break
            for g in opt.param_groups:  # cosine over the budget
                g["lr"] = args.lr * (0.03 + 0.97 * 0.5 * (1 + np.cos(np.pi * min(progress(), 1.0))))
            if args.consistency:
                crop, lab = bank.crops(rng, args.batch, cfg.content_stride)
                views = [timbre(warp(crop, warp_factors(rng, args.batch, crop.device)), rng, args.timbre) for _ in range(2)]
                mel = torch.cat(views)
                logits = forward_augmented(enc, mel, rng)
                lab = torch.cat([lab, lab])
            else:
                mel, lab = bank.batch(rng, args.batch, cfg.content_stride)
                mel = timbre(mel, rng, args.timbre)
                logits = forward_augmented(enc, mel, rng)
            k = min(logits.shape[1], lab.shape[1])
            loss = F.cross_entropy(logits[:, :k].flatten(0, 1), lab[:, :k].flatten(), weight=class_weight, ignore_index=PAD_LABEL)
            if args.consistency:
                loss = loss + args.consistency * view_disagreement(logits[:, :k], lab[:, :k] != PAD_LABEL)
            if teacher is not None:
                with torch.no_grad():
                    heard_by_teacher = teacher(mel)
                loss = loss + args.distill * distillation(logits[:, :k], heard_by_teacher, lab[:, :k] != PAD_LABEL)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(enc.parameters(), 1.0)
            opt.step()
            step += 1
            losses.append(loss.item())
            if step % args.eval_every == 0:
                ev = {s: evaluate(enc, held[s], cfg.content_classes, cfg.content_stride) for s in held}
                history.append({"step": step, "minutes": trained / 60, "loss": float(np.mean(losses[-100:])),
                                **{f"{s}_{m}": ev[s][m] for s in ev for m in ("frame_accuracy", "bilabial_segments_heard")}})
                log(f"step {step}  loss {history[-1]['loss']:.3f}  val acc {100 * ev['val']['frame_accuracy']:.1f}%  "
                    f"test acc {100 * ev['test']['frame_accuracy']:.1f}%  /p b m/ heard {100 * ev['test']['bilabial_segments_heard']:.1f}%  "
                    f"{step / max(trained, 1e-9):.2f} steps/s  ~{trained * (1 / max(progress(), 1e-9) - 1) / 60:.1f} min left")
                save(ck_path)
                if args.snapshots:
                    save(args.out / f"frontend-step{step}.pt", final=True)
    except KeyboardInterrupt:  # Ctrl-C: what was trained is kept, and can be continued
        save(ck_path)
        log(f"interrupted at step {step}: saved {ck_path}; the same command with --resume continues it")
        return 130
    final = {s: evaluate(enc, held[s], cfg.content_classes, cfg.content_stride) for s in held}
    save(ck_path)
    save(args.out / "frontend.pt", final=True)
    (args.out / "frontend_eval.json").write_text(json.dumps({"step": step, "minutes": trained / 60, "history": history,
                                                             "final": final}, indent=1))
    log(f"done: {step} steps, test frame accuracy {100 * final['test']['frame_accuracy']:.1f}%, "
        f"/p b m/ heard {100 * final['test']['bilabial_segments_heard']:.1f}% -> {args.out / 'frontend.pt'}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
