"""The speech front-end's own training speech: every voice the project can get, no meshes.

The content encoder (our DeepSpeech stand-in) learns phones from log-Mel. The mesh corpus has 35 minutes of
speech from a few dozen voices; phone recognition is limited by how many voices it has heard (issue 14), so the
front-end trains apart from the face, on this set:

- Kokoro-82M's 28 natural English voices (corpus/kokoro.py), and blends of two of them, at varied speeds; with
  `--kokoro-voices accented|all`, its 26 other-language voices speaking English (accented voices); with
  `--accents SHARE`, that share of them given the phonemes of one of espeak-ng's English accents (kokoro.ACCENTS);
  with `--extrapolate SHARE`, that share of them said by a voice beyond two of Kokoro's (EXTRAPOLATE: a speaker
  that is neither, and not between them);
- festival, flite and espeak-ng voices (corpus/speech.py); with `--foreign SHARE`, that share of the synthetic clips said by
  festival's Italian, Czech and Finnish diphone voices through a phone map (corpus/foreign.py): more voices of the
  older synthesisers' kind, which the front-end hears worst;
- with `--more-voices SHARE`, that share of the synthetic clips said by RHVoice's and SVOX Pico's English voices
  (corpus/more_voices.py): two more synthesiser families; with `--diphone-voices SHARE`, that share given to festival's
  rab and don and MBROLA's us1, us2, us3 and en1 (corpus/diphone_voices.py): six more diphone voices; with
  `--mbrola-voices SHARE`, that share given to MBROLA's voices of other languages saying the English phones
  (corpus/mbrola_voices.py): about forty more real speakers, men and women;
- the recorded human speech of the corpus's train split (one speaker, real microphones).

Phone labels: the synthesiser's own timings (festival, flite) or pocketsphinx forced alignment (the rest).
Each clip gets the corpus's augmentation (tempo, pitch, microphone, room, noise, band, level) with
probability AUGMENT_SHARE; with `--vocode SHARE`, that share of the clips is first said through a vocoder
(corpus/augment.py, vocode: the voice's own source replaced by pulses at its pitch), as older synthesisers sound. The face corpus's test voices, test sentences and test recordings never occur here,
so its test split measures the front-end on held-out voices.

Output: one .npz per clip (log-Mel as float16, a phone class per Mel frame) and an index.jsonl.
  scripts/py -m talkingface.frontend.speechset --out data/speech --minutes 120 --workers 2
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from dataclasses import asdict, dataclass
from functools import lru_cache
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from ..corpus import diphone_voices, foreign, kokoro, mbrola_voices, more_voices, recorded
from ..corpus.align import AlignmentError, Aligner
from ..corpus.augment import augment_channel, augment_speech, vocode
from ..corpus.plan import PRESETS, is_test_voice, split_of_recording
from ..corpus.sentences import generate_sentences
from ..corpus.speech import Voice, all_voices, fit_to_duration, synthesize
from ..features import AudioConfig, log_mel
from ..phones import frame_labels
from ..wav import read_wav, resample

AUGMENT_SHARE = 0.7
SHARES = {"kokoro": 0.6, "classic": 0.25, "human": 0.15}  # of the clips; the human share is capped by the recordings


@dataclass
class SpeechSpec:
    key: str
    engine: str          # "kokoro", "festival", "flite", "espeak", "foreign", "more", "diphone", "mbrola" or "human"
    voice: str           # voice name, a Kokoro blend "a*0.7+b", or the recording's name
    text: str
    speed: float
    seed: int


def face_test_sentences(seed: int = 0) -> set[str]:
    """The mesh corpus's val and test sentences (full preset): the front-end never trains on them."""
    cfg = PRESETS["full"]
    pools = generate_sentences(sum(cfg.sentence_pool), seed + 1)
    return set(pools[cfg.sentence_pool[0]:])


def texts(n: int, seed: int) -> list[str]:
    """Sentences from the corpus's grammar (another seed) and the recordings' train-split transcripts."""
    banned = face_test_sentences()
    out = [s for s in generate_sentences(n + len(banned), seed + 1000) if s not in banned][:n]
    if recorded.available():
        out += [r.text for r in recorded.recordings() if split_of_recording(r.name) == "train"]
    return out


KOKORO_VOICES = ("english", "accented", "all")


# A voice beyond two of Kokoro's: w a + (1 - w) b with w drawn from this range, a style vector on the far side of a
# from b. The front-end hears these as new speakers (the shipped one: 70% of frames at w = 1.5 against 88% for a
# itself, on eight sentences); past about 2 the speech itself degrades.
EXTRAPOLATE = (1.2, 1.8)


def plan(minutes: float, seed: int, kokoro_voices: str = "english", foreign_share: float = 0.0,
         accent_share: float = 0.0, extrapolate_share: float = 0.0, more_share: float = 0.0,
         diphone_share: float = 0.0, mbrola_share: float = 0.0) -> list[SpeechSpec]:
    """`kokoro_voices`: Kokoro's 28 English voices, its 26 accented ones (corpus/kokoro.py), or all 54.
    `foreign_share`: the share of the synthetic clips given instead to festival's foreign voices (corpus/foreign.py;
    the recorded speech stays), drawn from a generator of their own, so with 0 the plan is the one made before the
    option existed. `accent_share`: the share of Kokoro's clips said with one of espeak-ng's English accents
    (kokoro.ACCENTS: the voice name gets "@accent"), from a generator of its own too. `extrapolate_share`: the share of
    Kokoro's clips whose voice is one beyond two of them ("a*w+b" with w > 1, EXTRAPOLATE), its generator its own.
    `more_share`: the share of the synthetic clips given to RHVoice's and Pico's voices (corpus/more_voices.py), drawn
    after the foreign voices, from a generator of its own. `diphone_share`: the share of the synthetic clips given to
    festival's and MBROLA's diphone voices (corpus/diphone_voices.py), from a generator of its own. `mbrola_share`: the
    share of the synthetic clips given to MBROLA's voices of other languages (corpus/mbrola_voices.py), drawn last,
    from a generator of its own."""
    rng = np.random.default_rng(seed)
    n = int(minutes * 60 / 3.0)  # clips average about 3 s
    pool = texts(max(n, 400), seed)
    k_voices = (kokoro.voice_names() if kokoro_voices != "accented" else []) + \
        (kokoro.accented_voice_names() if kokoro_voices != "english" else [])
    if not k_voices:
        flag = "--kokoro" if kokoro_voices == "english" else "--kokoro --kokoro-accented"
        raise kokoro.KokoroMissing(f"Kokoro's {kokoro_voices} voices are not set up: run `scripts/py -m talkingface.corpus setup {flag}`")
    classic = [v for v in all_voices() if not is_test_voice(v)]
    others = foreign.available() if foreign_share > 0 else []
    if foreign_share > 0 and not others:
        raise foreign.SpeechToolError("festival's foreign voices are not installed: run `scripts/py -m talkingface.corpus setup --foreign-voices`")
    frng = np.random.default_rng([seed, 2])
    arng = np.random.default_rng([seed, 3])
    xrng = np.random.default_rng([seed, 4])
    mrng = np.random.default_rng([seed, 5])
    more = more_voices.available() if more_share > 0 else []
    if more_share > 0 and not more:
        raise foreign.SpeechToolError("RHVoice and Pico are not installed: run `scripts/py -m talkingface.corpus setup --more-voices`")
    drng = np.random.default_rng([seed, 6])
    diphones = diphone_voices.available() if diphone_share > 0 else []
    if diphone_share > 0 and not diphones:
        raise foreign.SpeechToolError(f"festival's and MBROLA's diphone voices are not installed: run `{diphone_voices.SETUP}`")
    brng = np.random.default_rng([seed, 7])
    mbrolas = mbrola_voices.available() if mbrola_share > 0 else []
    if mbrola_share > 0 and not mbrolas:
        raise foreign.SpeechToolError(f"MBROLA's voices of other languages are not installed: run `{mbrola_voices.SETUP}`")
    humans = [r for r in recorded.recordings() if split_of_recording(r.name) == "train"] if recorded.available() else []
    specs = []
    for i in range(n):
        key = f"s{i:05d}"
        clip_seed = int.from_bytes(hashlib.sha256(f"{seed}:{key}".encode()).digest()[:4], "little")
        r = rng.random()
        text = pool[rng.integers(len(pool))]
        if r < SHARES["human"] and humans:
            h = humans[rng.integers(len(humans))]
            specs.append(SpeechSpec(key, "human", h.name, h.text, 1.0, clip_seed))
        elif r < SHARES["human"] + SHARES["classic"]:
            v = classic[rng.integers(len(classic))]
            specs.append(SpeechSpec(key, v.engine, v.name, text, 1.0, clip_seed))
        else:
            a = k_voices[rng.integers(len(k_voices))]
            if rng.random() < 0.3:  # a voice between two voices
                b = k_voices[rng.integers(len(k_voices))]
                a = f"{a}*{rng.uniform(0.3, 0.7):.2f}+{b}" if b != a else a
            specs.append(SpeechSpec(key, "kokoro", a, text, float(rng.uniform(0.85, 1.2)), clip_seed))
        if accent_share > 0:  # drawn for every clip, so the accents do not depend on which clips are Kokoro's
            accented, accent = arng.random() < accent_share, kokoro.ACCENTS[arng.integers(len(kokoro.ACCENTS))]
            if accented and specs[-1].engine == "kokoro":
                specs[-1] = SpeechSpec(key, "kokoro", f"{specs[-1].voice}@{accent}", text, specs[-1].speed, clip_seed)
        if extrapolate_share > 0:  # drawn for every clip, as the accents
            beyond, pair, w = xrng.random() < extrapolate_share, xrng.integers(len(k_voices), size=2), xrng.uniform(*EXTRAPOLATE)
            if beyond and specs[-1].engine == "kokoro" and pair[0] != pair[1]:
                voice, _, accent = specs[-1].voice.partition("@")
                voice = f"{k_voices[pair[0]]}*{w:.2f}+{k_voices[pair[1]]}" + (f"@{accent}" if accent else "")
                specs[-1] = SpeechSpec(key, "kokoro", voice, text, specs[-1].speed, clip_seed)
        if others and frng.random() < foreign_share and specs[-1].engine != "human":  # the one real voice stays
            specs[-1] = SpeechSpec(key, "foreign", others[frng.integers(len(others))], text, float(frng.uniform(0.85, 1.15)), clip_seed)
        if more and mrng.random() < more_share and specs[-1].engine != "human":
            specs[-1] = SpeechSpec(key, "more", more[mrng.integers(len(more))], text, 1.0, clip_seed)
        if diphones:  # drawn for every clip, so the other clips do not depend on which are changed
            given, voice, speed = drng.random() < diphone_share, diphones[drng.integers(len(diphones))], drng.uniform(0.85, 1.15)
            if given and specs[-1].engine != "human":
                specs[-1] = SpeechSpec(key, "diphone", voice, text, float(speed), clip_seed)
        if mbrolas:  # drawn for every clip, as the diphone voices
            given, voice, speed = brng.random() < mbrola_share, mbrolas[brng.integers(len(mbrolas))], brng.uniform(0.85, 1.15)
            if given and specs[-1].engine != "human":
                specs[-1] = SpeechSpec(key, "mbrola", voice, text, float(speed), clip_seed)
    return specs


@lru_cache(maxsize=1)
def _recordings() -> dict:
    """The recordings by name, read once per process (the transcripts are a gzip file)."""
    return {r.name: r for r in recorded.recordings()}


def speak(spec: SpeechSpec, sr: int) -> tuple[np.ndarray, list]:
    """Audio at sr and its phones (synthesiser timings or forced alignment)."""
    if spec.engine == "human":
        rec = _recordings()[spec.voice]
        audio, rate = read_wav(rec.path)
        audio = resample(audio, rate, sr)
        phones = None
    elif spec.engine == "foreign":
        audio, phones = foreign.synthesize_foreign(spec.voice, spec.text, sr, spec.speed, spec.seed)
    elif spec.engine == "more":
        audio, phones = more_voices.synthesize(spec.voice, spec.text, sr), None
    elif spec.engine == "diphone":
        audio, phones = diphone_voices.synthesize(spec.voice, spec.text, sr, spec.speed), None
    elif spec.engine == "mbrola":
        audio, phones = mbrola_voices.synthesize_mbrola(spec.voice, spec.text, sr, spec.speed, spec.seed)
    elif spec.engine == "kokoro":
        audio = resample(kokoro.synthesize(spec.voice, spec.text, spec.speed), kokoro.KOKORO_RATE, sr)
        audio = np.concatenate([np.zeros(int(0.2 * sr), np.float32), audio, np.zeros(int(0.2 * sr), np.float32)])
        phones = None
    else:
        audio, phones = synthesize(Voice(spec.engine, spec.voice), spec.text, sr)
    if phones is None:
        phones, _ = Aligner().align(audio, sr, spec.text)  # a fresh decoder per clip: no state between clips
    return audio, phones


def build_one(args) -> dict:
    spec, out, vocode_share = args
    audio_cfg = AudioConfig()
    rng = np.random.default_rng(spec.seed)
    try:
        audio, phones = speak(spec, audio_cfg.sample_rate)
    except (AlignmentError, RuntimeError) as e:  # recorded as skipped with its reason; the set goes on
        return asdict(spec) | {"skipped": f"{type(e).__name__}: {e}"}
    # Vocoding draws from a generator of its own: with --vocode 0 a set is the one built before the option existed.
    vrng = np.random.default_rng([spec.seed, 1])
    vocoded = bool(vrng.random() < vocode_share)
    if vocoded:
        audio = vocode(audio, audio_cfg.sample_rate, vrng)
    strength = 1.0 if rng.random() < AUGMENT_SHARE else 0.0
    audio, phones, a1 = augment_speech(audio, audio_cfg.sample_rate, phones, rng, strength)
    phones = fit_to_duration(phones, len(audio) / audio_cfg.sample_rate)
    audio, a2 = augment_channel(audio, audio_cfg.sample_rate, rng, strength)
    mel = log_mel(audio, audio_cfg)
    labels = frame_labels(phones, len(mel), audio_cfg.feature_rate, np.int8)
    np.savez(Path(out) / f"{spec.key}.npz", mel=mel.astype(np.float16), labels=labels)
    return asdict(spec) | {"seconds": round(len(audio) / audio_cfg.sample_rate, 3), "augment": a1 | a2 | ({"vocoded": True} if vocoded else {})}


def build(out: Path, minutes: float, seed: int, workers: int, kokoro_voices: str = "english", first: int | None = None,
          vocode_share: float = 0.0, foreign_share: float = 0.0, accent_share: float = 0.0, extrapolate_share: float = 0.0,
          more_share: float = 0.0, diphone_share: float = 0.0, mbrola_share: float = 0.0) -> dict:
    """`first`: build only the plan's first clips (a set that was stopped, rebuilt exactly). `vocode_share`: the share of
    clips said through a vocoder first (corpus/augment.py, vocode), as older synthesisers' voices sound. `foreign_share`:
    the share of the synthetic clips said by festival's foreign voices (plan, corpus/foreign.py). `accent_share`: the share
    of Kokoro's clips said with an espeak-ng accent (plan). `extrapolate_share`: the share of Kokoro's clips said by a
    voice beyond two of its voices (plan). `more_share`: the share of the synthetic clips said by RHVoice's and Pico's voices.
    `diphone_share`: the share of the synthetic clips said by festival's and MBROLA's diphone voices (plan).
    `mbrola_share`: the share of the synthetic clips said by MBROLA's voices of other languages (plan)."""
    specs = plan(minutes, seed, kokoro_voices, foreign_share, accent_share, extrapolate_share, more_share, diphone_share,
                 mbrola_share)[:first]  # before the folder: a voice missing leaves nothing behind
    out.mkdir(parents=True, exist_ok=True)
    done = {json.loads(l)["key"] for l in (out / "index.jsonl").read_text().splitlines()} if (out / "index.jsonl").exists() else set()
    todo = [s for s in specs if s.key not in done]  # a build that was stopped continues where it was
    t0, n = time.time(), 0
    print(f"speech set: {len(specs)} clips planned, {len(todo)} to build, {workers} workers -> {out}", file=sys.stderr)
    with get_context("fork").Pool(workers) as pool, open(out / "index.jsonl", "a") as index:
        for rec in pool.imap_unordered(build_one, [(s, str(out), vocode_share) for s in todo], chunksize=2):
            index.write(json.dumps(rec) + "\n")
            index.flush()
            n += 1
            if n % 50 == 0 or n == len(todo):
                el = time.time() - t0
                print(f"  {n}/{len(todo)} clips, {el:.0f} s, ~{el / n * (len(todo) - n):.0f} s left", file=sys.stderr, flush=True)
    rows = [json.loads(l) for l in (out / "index.jsonl").read_text().splitlines()]
    ok = [r for r in rows if "skipped" not in r]
    meta = {"clips": len(ok), "skipped": len(rows) - len(ok), "minutes": round(sum(r["seconds"] for r in ok) / 60, 1),
            "seed": seed, "voices": len({r["voice"] for r in ok}), "vocoded": sum(bool(r["augment"].get("vocoded")) for r in ok),
            "by_engine": {e: sum(r["engine"] == e for r in ok) for e in sorted({r["engine"] for r in ok})}}
    (out / "meta.json").write_text(json.dumps(meta, indent=1))
    return meta


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m talkingface.frontend.speechset", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--minutes", type=float, default=120.0, help="planned speech (before skips), minutes")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--kokoro-voices", choices=KOKORO_VOICES, default="english",
                    help="Kokoro's English voices, its accented ones (setup --kokoro-accented), or all of them")
    ap.add_argument("--first", type=int, help="build only the plan's first N clips (the plan itself is that of --minutes)")
    shares = {  # options that give a share of the clips to something; each drawn from a generator of its own (plan)
        "vocode": "say this share of the clips through a vocoder first: buzzy, as diphone and parametric voices "
                  "(festival's, flite's) sound",
        "foreign": "give this share of the clips to festival's Italian, Czech and Finnish voices speaking English "
                   "(setup --foreign-voices; corpus/foreign.py)",
        "accents": "say this share of Kokoro's clips with one of espeak-ng's English accents (Caribbean, New York, "
                   "Lancaster, West Midlands, RP; not the Scottish one, which the test split holds out)",
        "extrapolate": "say this share of Kokoro's clips with a voice beyond two of its voices (w a + (1 - w) b, "
                       f"w from {EXTRAPOLATE[0]} to {EXTRAPOLATE[1]}): speakers that are none of its 54",
        "more_voices": "give this share of the synthetic clips to RHVoice's and SVOX Pico's English voices "
                       "(setup --more-voices; corpus/more_voices.py)",
        "diphone_voices": "give this share of the synthetic clips to festival's rab and don and MBROLA's us1, us2, us3 "
                          "and en1 (setup --diphone-voices; corpus/diphone_voices.py)",
        "mbrola_voices": "give this share of the synthetic clips to MBROLA's voices of other languages saying the English "
                         "phones (setup --mbrola-voices; corpus/mbrola_voices.py)"}
    for name, text in shares.items():
        ap.add_argument(f"--{name.replace('_', '-')}", type=float, default=0.0, metavar="SHARE", help=f"{text} (default 0)")
    args = ap.parse_args(argv)
    for name in shares:
        if not 0.0 <= getattr(args, name) <= 1.0:
            ap.error(f"--{name.replace('_', '-')} is a share of the clips, from 0 to 1 (got {getattr(args, name)})")
    meta = build(args.out, args.minutes, args.seed, args.workers, args.kokoro_voices, args.first, args.vocode, args.foreign, args.accents,
                 args.extrapolate, args.more_voices, args.diphone_voices, args.mbrola_voices)
    print(f"done: {meta['clips']} clips ({meta['skipped']} skipped), {meta['minutes']} min, {meta['voices']} voices -> {args.out}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
