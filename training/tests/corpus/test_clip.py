"""The clips of the small preset corpus (built once, conftest.py), checked clip by clip: the geometry the rig
makes of the phones, the blinks, the labels against the audio, the head pose; and a recording that cannot be
aligned still makes a clip, which says so."""
import logging

import numpy as np
import pytest

from talkingface.corpus import clip as clip_module
from talkingface.corpus import recorded
from talkingface.corpus.checks import eye_gap_mm, gaps_at, lip_gap_mm
from talkingface.corpus.plan import ClipSpec
from talkingface.geometry.pose import pose_degrees, pose_step_degrees
from talkingface.phones import BILABIALS, OPEN_VOWELS
from tests.speech_tools import NoAlignment, needs_speech_tools

pytestmark = needs_speech_tools


def all_clips(ds):
    return [ds.load(k) for split in ("train", "val", "test") for k in ds.keys(split)]


def test_lips_touch_at_every_bilabial(corpus):
    gaps = []
    for clip in all_clips(corpus):
        gap = lip_gap_mm(clip, corpus.template, corpus.mm_per_unit)
        gaps += [g for _, _, g in gaps_at(clip, gap, BILABIALS)]
    assert len(gaps) > 5
    assert max(gaps) < 0.5, f"inner lips {max(gaps):.2f} mm apart at a bilabial"


def test_lips_open_on_open_vowels(corpus):
    gaps = []
    for clip in all_clips(corpus):
        gap = lip_gap_mm(clip, corpus.template, corpus.mm_per_unit)
        gaps += [g for _, _, g in gaps_at(clip, gap, OPEN_VOWELS, min_duration=0.08)]
    assert len(gaps) > 5
    assert min(gaps) > 2.0, f"an open vowel with the lips only {min(gaps):.2f} mm apart"
    assert np.median(gaps) > 6.0


def test_silence_relaxes_to_a_closed_mouth(corpus):
    for clip in all_clips(corpus):
        gap = lip_gap_mm(clip, corpus.template, corpus.mm_per_unit)
        # The first frame of every clip is inside the leading pause.
        assert clip.phones[0][0] == "SIL"
        if clip.phones[0][2] > 0.25:
            assert gap[0] < 0.6, f"{clip.key}: lips {gap[0]:.2f} mm apart in the leading silence"


def test_blinks_close_the_lids(corpus):
    closed = []
    for clip in all_clips(corpus):
        eye = eye_gap_mm(clip, corpus.template, corpus.mm_per_unit)
        for start, dur, amount in clip.meta["blinks"]:
            k = int(round((start + 0.35 * dur) * clip.fps))
            if k < clip.num_frames and amount == 1.0:
                closed.append(eye[k])
        assert eye.max() > 3.0  # eyes are open between blinks
    assert closed and max(closed) < 0.3


def test_labels_end_with_their_audio(corpus):
    for clip in all_clips(corpus):
        assert abs(clip.meta["label_end_error_ms"]) <= 20.0, clip.key
        assert clip.phones[-1][2] == pytest.approx(clip.audio.size / clip.sample_rate, abs=1e-3)
        assert clip.num_frames == round(clip.audio.size / clip.sample_rate * clip.fps)


def test_pose_is_smooth_and_plausible(corpus):
    for clip in all_clips(corpus):
        assert pose_step_degrees(clip.pose).max() < 1.5, clip.key
        assert pose_degrees(clip.pose).max() < 15.0
    moves = np.concatenate([pose_degrees(c.pose) for c in all_clips(corpus)])
    assert 1.0 < np.median(moves) < 8.0  # a few degrees, as in the paper's Fig. 4


def test_a_recording_that_cannot_be_aligned_is_spoken_by_tts_and_says_so(monkeypatch, caplog):
    monkeypatch.setattr(clip_module, "_aligner", NoAlignment)
    rec = recorded.recordings()[0]
    spec = ClipSpec("Synth01_sentence01", 0, "train", 0, voice={"engine": "flite", "name": "slt"}, recording=rec.name)
    with caplog.at_level(logging.WARNING, logger=clip_module.__name__):
        audio, phones, info = clip_module._speech(spec, 16000)
    assert info["source"] == "tts" and info["voice"] == "flite:slt" and info["text"] == rec.text and len(audio) and phones
    assert info["recording_failed_alignment"] == {"recording": rec.name, "reason": f"test: {rec.text!r} will not align"}
    warned = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warned) == 1 and spec.key in warned[0] and rec.name in warned[0] and "will not align" in warned[0]
