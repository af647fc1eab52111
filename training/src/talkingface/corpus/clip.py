"""One clip of the corpus, made in a worker process: speech with phone timings (a TTS voice, or a real
recording aligned to its transcript) -> speaking-rate / pitch augmentation -> prosody -> articulation
(coarticulated visemes, blinks, brows) on the subject's face -> head pose -> recording-channel augmentation
of the audio -> its files (wav/, vertices_npy/, poses_npy/, alignments/) and its record.
"""
from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np

from ..geometry.pose import pose_about_pivot
from ..phones import SILENCE
from ..template import Template, load_template
from ..wav import read_wav, resample, write_wav
from . import recorded
from .align import AlignmentError, Aligner
from .augment import augment_channel, augment_speech
from .coarticulation import (SpeakingStyle, articulation_track, blink_track, brow_track, sample_blinks,
                             segments_from_pairs)
from .head_pose import head_pose_track
from .identity import Subject, apply_identity
from .plan import ClipSpec, CorpusConfig
from .prosody import frame_energy, frame_pitch, zscore_voiced
from .rig import Rig
from .speech import Voice, fit_to_duration, synthesize

log = logging.getLogger(__name__)

_WORKER: dict = {}


def init_worker(template_path: str, subjects: list[Subject], cfg: CorpusConfig) -> None:
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
    fallback = {}
    if spec.recording:
        if "recordings" not in _WORKER:
            _WORKER["recordings"] = {r.name: r for r in recorded.recordings()}
        rec = _WORKER["recordings"][spec.recording]
        audio, rate = read_wav(rec.path)
        audio = resample(audio, rate, sr)
        try:
            phones, method = _aligner().align(audio, sr, rec.text)
        except AlignmentError as e:
            # The clip is still made, from the same words in a TTS voice (below), and says so: its record names
            # the recording and the reason, and the build counts such clips in meta.json and the dataset card.
            log.warning("clip %s: recording %s could not be aligned (%s); a TTS voice speaks its words instead",
                        spec.key, rec.name, e)
            spec.text = rec.text
            fallback = {"recording_failed_alignment": {"recording": rec.name, "reason": str(e)}}
        else:
            return audio, phones, {"source": "human", "voice": "human:allison", "recording": rec.name, "text": rec.text,
                                   "timing": "aligned", "align_method": method, "license": recorded.LICENSE}
    attempts, reasons = [], []
    for vdict in [spec.voice, *spec.fallback_voices]:
        voice = Voice(**vdict)
        audio, phones = synthesize(voice, spec.text, sr)
        info = {"source": "tts", "voice": voice.id, "text": spec.text, "timing": voice.timing}
        if phones is None:
            try:
                phones, method = _aligner().align(audio, sr, spec.text)
                info["align_method"] = method
            except AlignmentError as e:
                # Expected now and then (espeak-ng voices, speech.py): the next voice speaks the clip, and the
                # record lists the voices that failed.
                log.info("clip %s: voice %s could not be aligned (%s); trying the next voice", spec.key, voice.id, e)
                attempts.append(voice.id)
                reasons.append(f"{voice.id}: {e}")
                continue
        if attempts:
            info["voices_failed_alignment"] = attempts
        return audio, phones, info | fallback
    raise AlignmentError(f"{spec.key}: no voice could be aligned ({'; '.join(reasons)})")


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
    """A clip failed to build; the message names the clip, its voice and words, and the cause."""


def build_in_worker(args):
    spec, out = args
    try:
        return build_clip(spec, Path(out))
    except Exception as e:  # name the clip: a bare traceback from a worker process does not
        raise ClipBuildError(f"clip {spec.key} ({spec.voice and spec.voice['engine']}:{spec.voice and spec.voice['name']}, "
                             f"{spec.recording or spec.text!r}): {type(e).__name__}: {e}") from e
