"""Command line for the synthetic corpus.

  scripts/py -m talkingface.corpus setup [--kokoro [--kokoro-accented]] [--foreign-voices] [--more-voices] [--diphone-voices] [--mbrola-voices]   install the Debian speech tools (apt) [and Kokoro's voices]
  scripts/py -m talkingface.corpus build --preset small --out data/corpus-small
  scripts/py -m talkingface.corpus build --preset full  --out data/corpus --workers 2
  scripts/py -m talkingface.corpus card  --corpus data/corpus --out docs/corpus
"""
from __future__ import annotations

import argparse
import logging
import os
import shutil
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

from .build import build_corpus
from .clip import ClipBuildError
from .plan import PRESETS
from .speech import DEBIAN_PACKAGES, SpeechToolError, installed


def _progress():
    start = time.time()
    tty = sys.stderr.isatty()
    last = [0.0]

    def report(done: int, total: int, key: str) -> None:
        now = time.time()
        if not tty and now - last[0] < 5 and done != total:
            return
        last[0] = now
        rate = done / max(now - start, 1e-6)
        eta = (total - done) / max(rate, 1e-6)
        bar = "#" * int(30 * done / total)
        line = f"[{bar:<30}] {done}/{total} clips  {now - start:5.0f}s elapsed  ~{eta:4.0f}s left  ({key})"
        print(("\r" + line) if tty else line, end="" if tty and done != total else "\n", file=sys.stderr, flush=True)
    return report


def cmd_setup(args) -> int:
    if args.kokoro or args.kokoro_accented:  # the speech front-end's natural voices (python -m talkingface.frontend.speechset)
        from . import kokoro
        print(f"kokoro: {kokoro.setup(accented=args.kokoro_accented)}: {len(kokoro.voice_names())} English voices, "
              f"{len(kokoro.accented_voice_names())} accented")
    if args.more_voices:  # RHVoice and Pico, from Debian's contrib and non-free sections (corpus/more_voices.py)
        from . import more_voices
        more_voices.setup()
        print(f"more voices: {' '.join(more_voices.available())}")
    if args.diphone_voices:  # festival's and MBROLA's diphone voices, MBROLA's from Debian's non-free section
        from . import diphone_voices
        diphone_voices.setup()
        print(f"diphone voices: {' '.join(diphone_voices.available())}")
    if args.mbrola_voices:  # MBROLA's voices of other languages, from Debian's non-free section (corpus/mbrola_voices.py)
        from . import mbrola_voices
        mbrola_voices.setup()
        print(f"MBROLA voices: {' '.join(mbrola_voices.available())}")
    from .foreign import FOREIGN_PACKAGES
    wanted = DEBIAN_PACKAGES + (FOREIGN_PACKAGES if args.foreign_voices else ())
    missing = [p for p in wanted if not installed(p)]
    if not missing:
        print("speech tools: all installed")
        return 0
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    print(f"installing: {' '.join(missing)}")
    subprocess.run(sudo + ["apt-get", "update", "-qq"], check=True)
    subprocess.run(sudo + ["apt-get", "install", "-y", "-qq", "--no-install-recommends", *missing], check=True,
                   env={**os.environ, "DEBIAN_FRONTEND": "noninteractive"})
    return 0


def cmd_build(args) -> int:
    cfg = replace(PRESETS[args.preset], seed=args.seed)
    bad = ([f"--workers {args.workers} (one or more)"] if args.workers < 1 else []) \
        + ([f"--sentences {args.sentences} (one or more)"] if args.sentences is not None and args.sentences < 1 else []) \
        + ([f"--subjects {' '.join(map(str, args.subjects))} (one or more in each split: training, val and test)"]
           if args.subjects and min(args.subjects) < 1 else [])
    if bad:
        print(f"error: {'; '.join(bad)}", file=sys.stderr)
        return 2
    if args.subjects:
        cfg = replace(cfg, subjects=tuple(args.subjects))
    if args.sentences is not None:
        cfg = replace(cfg, sentences_per_subject=args.sentences)
    for tool in ("festival", "flite", "espeak-ng", "sox"):
        if shutil.which(tool) is None:
            print(f"error: {tool} is missing; run `scripts/py -m talkingface.corpus setup` first", file=sys.stderr)
            return 2
    # Warnings (a recording spoken by a TTS voice) always show; --verbose adds each voice that failed alignment.
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    n = sum(cfg.subjects) * cfg.sentences_per_subject
    print(f"building the {cfg.preset} corpus: {sum(cfg.subjects)} subjects x {cfg.sentences_per_subject} clips = {n} clips, "
          f"seed {cfg.seed}, {args.workers} workers -> {args.out}", file=sys.stderr)
    try:
        meta = build_corpus(Path(args.out), cfg, workers=args.workers, template_path=args.template,
                            overwrite=args.overwrite, progress=_progress())
    except (FileExistsError, SpeechToolError, ClipBuildError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"done: {meta['clips']} clips, {meta['hours'] * 60:.1f} min of audio in {meta['build_seconds']:.0f} s -> {args.out}")
    return 0


def cmd_card(args) -> int:
    from .card import write_card
    path = write_card(Path(args.corpus), Path(args.out))
    print(f"wrote {path}")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.corpus", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    st = sub.add_parser("setup", help="install the Debian packages the corpus needs")
    st.add_argument("--kokoro", action="store_true", help="also fetch the Kokoro voices (hash-pinned) for the speech front-end")
    st.add_argument("--kokoro-accented", action="store_true",
                    help="and Kokoro's 26 other-language voices, which speak English with an accent (corpus/kokoro.py)")
    st.add_argument("--foreign-voices", action="store_true",
                    help="and festival's Italian, Czech and Finnish voices, which speak English through a phone map (corpus/foreign.py)")
    st.add_argument("--more-voices", action="store_true",
                    help="and RHVoice's and SVOX Pico's English voices, from Debian's contrib and non-free sections (corpus/more_voices.py)")
    st.add_argument("--diphone-voices", action="store_true",
                    help="and festival's rab and don and MBROLA's us1, us2, us3 and en1 (corpus/diphone_voices.py)")
    st.add_argument("--mbrola-voices", action="store_true",
                    help="and MBROLA's voices of other languages, about 70 Debian packages (corpus/mbrola_voices.py)")
    st.set_defaults(fn=cmd_setup)
    b = sub.add_parser("build", help="build a corpus")
    b.add_argument("--preset", choices=sorted(PRESETS), default="small")
    b.add_argument("--out", required=True, help="output folder (must be empty or a corpus to --overwrite)")
    b.add_argument("--seed", type=int, default=0)
    b.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    b.add_argument("--subjects", type=int, nargs=3, metavar=("TRAIN", "VAL", "TEST"), help="override the preset's subject counts")
    b.add_argument("--sentences", type=int, help="override clips per subject")
    b.add_argument("--template", type=Path, help="template.json of another face (default: the shipped MediaPipe face)")
    b.add_argument("--overwrite", action="store_true", help="replace an existing corpus in --out")
    b.add_argument("--verbose", action="store_true", help="log every voice that failed alignment, with the reason")
    b.set_defaults(fn=cmd_build)
    c = sub.add_parser("card", help="write the dataset card (statistics and plots)")
    c.add_argument("--corpus", required=True)
    c.add_argument("--out", default="docs/corpus")
    c.set_defaults(fn=cmd_card)
    args = ap.parse_args(argv)
    return args.fn(args)


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
