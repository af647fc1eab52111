"""Build the synthetic talking-face corpus.

For every clip: speech with phone timings (a TTS voice, or a real recording
aligned to its transcript) -> speaking-rate / pitch augmentation -> prosody ->
articulation (coarticulated visemes, blinks, brows) on the subject's face ->
head pose -> recording-channel augmentation of the audio -> files in the
community's VOCASET layout plus poses, alignments and splits.

Every clip draws from its own generator seeded by (corpus seed, clip key), so
the corpus is the same whatever the number of workers.
"""
from __future__ import annotations

import hashlib
import json
import os
import pickle
import shutil
import sys
import time
from dataclasses import asdict, dataclass, field
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from .. import constants
from ..data.datasets import CORPUS_FORMAT, read_wav, write_wav
from ..paths import TEMPLATE_DIR
from ..template import Template, load_template
from . import recorded
from .align import AlignmentError, Aligner
from .augment import augment_channel, augment_speech
from .coarticulation import (SpeakingStyle, articulation_track, blink_track, brow_track, sample_blinks,
                             segments_from_pairs)
from .identity import Subject, apply_identity, sample_subject
from .pose import apply_pose, head_pose_track, pose_about_pivot
from .prosody import frame_energy, frame_pitch, zscore_voiced
from .rig import Rig
from .sentences import generate_sentences
from .speech import SpeechToolError, Voice, all_voices, fit_to_duration, resample, synthesize, tool_versions
from .phonemes import SILENCE

CORPUS_VERSION = 1
BUILDING_MARKER = ".building"


@dataclass(frozen=True)
class CorpusConfig:
    preset: str
    subjects: tuple[int, int, int]   # train, val, test
    sentences_per_subject: int
    sentence_pool: tuple[int, int, int]  # distinct sentences per split
    human_fraction: float = 0.15     # share of clips spoken by the recorded human voice
    clean_fraction: float = 0.25     # share of clips left without augmentation
    seed: int = 0
    sample_rate: int = constants.SAMPLE_RATE
    fps: int = constants.FPS


PRESETS = {
    "full": CorpusConfig("full", (12, 2, 2), 40, (200, 30, 30)),
    "small": CorpusConfig("small", (2, 1, 1), 3, (6, 3, 3), human_fraction=0.25),
}

# Voices that training never hears: a festival voice, a flite voice, a whole espeak accent and two variants.
def is_test_voice(v: Voice) -> bool:
    if v.id in ("festival:ked", "flite:awb"):
        return True
    if v.engine == "espeak":
        accent, variant = v.name.split("+")
        return accent == "en-gb-scotland" or variant in ("klatt3", "f5")
    return False


def _split_of_recording(name: str) -> str:
    """Recorded prompts split by a stable hash of their name: 15% test, 10% val."""
    h = int(hashlib.sha1(name.encode()).hexdigest()[:8], 16) % 100
    return "test" if h < 15 else "val" if h < 25 else "train"


@dataclass
class ClipSpec:
    key: str
    subject: int
    split: str
    seed: int
    text: str = ""
    voice: dict | None = None        # Voice fields for TTS clips
    recording: str | None = None     # asterisk prompt name for human clips
    fallback_voices: list = field(default_factory=list)
    augment: bool = True


def plan(cfg: CorpusConfig) -> tuple[list[Subject], list[ClipSpec]]:
    rng = np.random.default_rng(cfg.seed)
    n_train, n_val, n_test = cfg.subjects
    subjects = [sample_subject(f"Synth{i + 1:02d}", rng) for i in range(n_train + n_val + n_test)]
    split_of_subject = ["train"] * n_train + ["val"] * n_val + ["test"] * n_test
    pools = generate_sentences(sum(cfg.sentence_pool), cfg.seed + 1)
    a, b, _ = cfg.sentence_pool
    sentences = {"train": pools[:a], "val": pools[a : a + b], "test": pools[a + b :]}
    voices = all_voices()
    voice_pool = {"train": [v for v in voices if not is_test_voice(v)], "test": [v for v in voices if is_test_voice(v)]}
    voice_pool["val"] = voice_pool["train"]
    human = {"train": [], "val": [], "test": []}
    if cfg.human_fraction > 0:
        # A corpus that silently lacked its recorded speech would be another corpus (issue 12: a fresh machine
        # missed the transcripts package, and every later clip drew other voices and tempos).
        if not recorded.available():
            raise SpeechToolError(f"recorded speech missing: {recorded.MISSING_HINT}")
        for r in recorded.recordings():
            human[_split_of_recording(r.name)].append(r)
    cursors = {k: 0 for k in sentences}
    specs = []
    for s_idx, subject in enumerate(subjects):
        split = split_of_subject[s_idx]
        order = rng.permutation(len(sentences[split]))
        for k in range(cfg.sentences_per_subject):
            key = f"{subject.name}_sentence{k + 1:02d}"
            seed = int.from_bytes(hashlib.sha256(f"{cfg.seed}:{key}".encode()).digest()[:4], "little")
            spec = ClipSpec(key, s_idx, split, seed, augment=rng.random() >= cfg.clean_fraction)
            pool = voice_pool[split]
            # Voice-engine balance: each engine family gets its share, whatever the pool sizes.
            engines = sorted({v.engine for v in pool})
            engine = engines[rng.integers(len(engines))]
            family = [v for v in pool if v.engine == engine]
            chosen = family[rng.integers(len(family))]
            spec.voice = asdict(chosen)
            # If alignment fails (espeak voices, now and then): three other pool voices, then one whose
            # synthesiser gives the timings itself, so every clip ends up with speech.
            others = [pool[i] for i in rng.permutation(len(pool))[:3]]
            timed = [v for v in pool if v.timing == "synthesiser"]
            spec.fallback_voices = [asdict(v) for v in others + [timed[rng.integers(len(timed))]]]
            # Drawn for every clip, so the draws of later clips never depend on which recordings exist.
            wants_human = rng.random() < cfg.human_fraction
            if human[split] and wants_human:
                spec.recording = human[split][cursors.setdefault("h" + split, 0) % len(human[split])].name
                cursors["h" + split] += 1
            else:
                spec.text = sentences[split][order[k % len(order)]]
            cursors[split] += 1
            specs.append(spec)
    return subjects, specs


# ---- one clip (runs in a worker process) -------------------------------------------------------

_WORKER: dict = {}


def _init_worker(template_path: str, subjects: list[Subject], cfg: CorpusConfig) -> None:
    _WORKER["template"] = load_template(template_path)
    _WORKER["subjects"] = subjects
    _WORKER["cfg"] = cfg
    _WORKER["rigs"] = {}
    _WORKER["faces"] = {}


def _aligner() -> Aligner:
    """A fresh decoder for every clip (about 0.2 s): a reused pocketsphinx decoder carries state from one
    utterance to the next, so alignments, and with them the corpus, would depend on which worker
    happened to take which clips (test_same_seed_same_corpus caught this)."""
    return Aligner()


def _speech(spec: ClipSpec, sr: int) -> tuple[np.ndarray, list, dict]:
    """Audio at sr plus ARPAbet phones; tries fallback voices when alignment fails."""
    if spec.recording:
        if "recordings" not in _WORKER:
            _WORKER["recordings"] = {r.name: r for r in recorded.recordings()}
        rec = _WORKER["recordings"][spec.recording]
        audio, rate = read_wav(rec.path)
        audio = resample(audio, rate, sr)
        try:
            phones, method = _aligner().align(audio, sr, rec.text)
            return audio, phones, {"source": "human", "voice": "human:allison", "recording": rec.name, "text": rec.text,
                                   "timing": "aligned", "align_method": method, "license": recorded.LICENSE}
        except AlignmentError:
            spec.text = rec.text  # speak the same words with a TTS voice instead
    attempts = []
    for vdict in [spec.voice, *spec.fallback_voices]:
        voice = Voice(**vdict)
        audio, phones = synthesize(voice, spec.text, sr)
        info = {"source": "tts", "voice": voice.id, "text": spec.text, "timing": voice.timing}
        if phones is None:
            try:
                phones, method = _aligner().align(audio, sr, spec.text)
                info["align_method"] = method
            except AlignmentError:
                attempts.append(voice.id)
                continue
        if attempts:
            info["voices_failed_alignment"] = attempts
        return audio, phones, info
    raise AlignmentError(f"{spec.key}: no voice could be aligned ({', '.join(attempts)})")


def build_clip(spec: ClipSpec, out: Path) -> dict:
    cfg: CorpusConfig = _WORKER["cfg"]
    template: Template = _WORKER["template"]
    subject: Subject = _WORKER["subjects"][spec.subject]
    sr, fps = cfg.sample_rate, cfg.fps
    rng = np.random.default_rng(spec.seed)
    if subject.name not in _WORKER["rigs"]:
        face = apply_identity(template, subject.identity)
        _WORKER["faces"][subject.name] = face
        _WORKER["rigs"][subject.name] = Rig(template, face)
    rig: Rig = _WORKER["rigs"][subject.name]
    face = _WORKER["faces"][subject.name]

    audio, phones, info = _speech(spec, sr)
    strength = 1.0 if spec.augment else 0.0
    audio, phones, aug_speech = augment_speech(audio, sr, phones, rng, strength)
    duration = len(audio) / sr
    label_end_error_ms = (duration - phones[-1][2]) * 1000  # before any fitting: how well labels and audio agree
    phones = fit_to_duration(phones, duration)
    n_frames = max(1, int(round(duration * fps)))
    segments = segments_from_pairs(phones)

    energy = frame_energy(audio, sr, n_frames, fps)
    pitch = frame_pitch(audio, sr, n_frames, fps)
    voiced = pitch > 0
    speaking = np.zeros(n_frames, dtype=bool)
    for s in segments:
        if s.phone != SILENCE:
            speaking[int(s.start * fps) : int(np.ceil(s.end * fps))] = True
    pitch_z = zscore_voiced(np.log(np.maximum(pitch, 1.0)), voiced)
    energy_z = zscore_voiced(energy, speaking)

    style: SpeakingStyle = subject.style
    params = articulation_track(segments, n_frames, fps, style)
    blinks = sample_blinks(duration, rng, style)
    blink = blink_track(blinks, n_frames, fps)
    brow = brow_track(segments, pitch_z, energy_z, fps, rng, style)
    vertices = rig.deform(params, blink, brow)                      # (F, N, 3) I + O

    angles = head_pose_track(pitch_z, energy_z, speaking, fps, rng, style.pose_liveliness)
    pose = pose_about_pivot(angles, neck_pivot(face, template)).astype(np.float32)

    audio, aug_channel = augment_channel(audio, sr, rng, strength)
    write_wav(out / "wav" / f"{spec.key}.wav", audio, sr)
    np.save(out / "vertices_npy" / f"{spec.key}.npy", vertices.reshape(n_frames, -1))
    np.save(out / "poses_npy" / f"{spec.key}.npy", pose)
    record = {
        "key": spec.key, "subject": subject.name, "split": spec.split, **info,
        "augment": {**aug_speech, **aug_channel}, "duration": round(duration, 4), "frames": n_frames,
        "label_end_error_ms": round(label_end_error_ms, 2),
        "blinks": [[round(b.start, 3), round(b.duration, 3), round(b.amount, 3)] for b in blinks],
        "pose_degrees_max": np.round(np.abs(angles).max(0), 2).tolist(),
        "phones": [[p, round(a, 4), round(b, 4)] for p, a, b in phones],
    }
    (out / "alignments" / f"{spec.key}.json").write_text(json.dumps(record))
    return {k: v for k, v in record.items() if k not in ("phones", "blinks")}


def neck_pivot(face: np.ndarray, template: Template) -> np.ndarray:
    """Where the head turns: behind the face at the height of the mouth corners (about the upper neck)."""
    H = float(face[:, 1].max() - face[:, 1].min())
    corners = np.intersect1d(template.regions["lips_inner_upper"], template.regions["lips_inner_lower"])
    y = float(face[corners, 1].mean()) + 0.1 * H if len(corners) else float(face[:, 1].mean())
    return np.array([float(face[:, 0].mean()), y, float(face[:, 2].max()) - 0.6 * H])


class ClipBuildError(RuntimeError):
    pass


def _worker_build(args):
    spec, out = args
    try:
        return build_clip(spec, Path(out))
    except Exception as e:  # name the clip: a bare traceback from a worker process does not
        raise ClipBuildError(f"clip {spec.key} ({spec.voice and spec.voice['engine']}:{spec.voice and spec.voice['name']}, "
                             f"{spec.recording or spec.text!r}): {type(e).__name__}: {e}") from e


# ---- the whole corpus ------------------------------------------------------------------------

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
    with ctx.Pool(workers, initializer=_init_worker, initargs=(str(template_path), subjects, cfg)) as pool:
        for rec in pool.imap_unordered(_worker_build, [(s, str(out)) for s in specs], chunksize=1):
            records.append(rec)
            if progress:
                progress(len(records), len(specs), rec["key"])
    records.sort(key=lambda r: r["key"])

    faces = {s.name: apply_identity(template, s.identity) for s in subjects}
    with open(out / "templates.pkl", "wb") as f:
        pickle.dump(faces, f, protocol=4)
    splits = {split: [r["key"] for r in records if r["split"] == split] for split in ("train", "val", "test")}
    (out / "splits.json").write_text(json.dumps(splits, indent=1))
    seconds = time.time() - t0
    meta = {
        "format": CORPUS_FORMAT, "version": CORPUS_VERSION, "config": asdict(cfg), "fps": cfg.fps,
        "sample_rate": cfg.sample_rate, "units": template.units, "template_id": template.id,
        "subjects": [dict(s.describe(), split=sp) for s, sp in zip(subjects, ["train"] * cfg.subjects[0] + ["val"] * cfg.subjects[1] + ["test"] * cfg.subjects[2])],
        "voices": {"train": sorted({v.id for v in all_voices() if not is_test_voice(v)}),
                   "test": sorted({v.id for v in all_voices() if is_test_voice(v)})},
        "clips": len(records), "hours": round(sum(r["duration"] for r in records) / 3600, 4),
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
