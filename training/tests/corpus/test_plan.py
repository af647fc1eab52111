"""The corpus plan: recorded speech that is missing stops it rather than shifting every later clip, and the
splits hold out subjects, sentences and voices."""
from dataclasses import replace

import pytest

from talkingface.corpus import recorded
from talkingface.corpus.plan import PRESETS, is_test_voice, plan
from talkingface.corpus.speech import Voice, all_voices
from tests.speech_tools import needs_speech_tools

pytestmark = needs_speech_tools


def test_missing_recordings_stop_the_build_and_never_shift_the_other_clips(monkeypatch):
    """Issue 12: without the transcripts package the plan used to skip a random draw per clip, so every
    later clip got another voice and tempo. Now it stops with the packages to install; and the TTS clips of a
    plan without recorded speech are exactly those of the plan with it."""
    cfg = PRESETS["small"]
    _, with_rec = plan(cfg)
    monkeypatch.setattr(recorded, "available", lambda: False)
    with pytest.raises(Exception, match="asterisk-core-sounds-en"):
        plan(cfg)
    _, without = plan(replace(cfg, human_fraction=0.0))
    tts = [(a.key, a.voice, a.text) for a in with_rec if a.recording is None]
    assert len(tts) > 3 and tts == [(b.key, b.voice, b.text) for b in without if b.key in {k for k, _, _ in tts}]


def test_splits_hold_out_subjects_sentences_and_voices(corpus):
    splits = {s: [corpus.load(k) for k in corpus.keys(s)] for s in ("train", "val", "test")}
    subjects = {s: {c.subject for c in clips} for s, clips in splits.items()}
    assert not subjects["train"] & subjects["test"] and not subjects["train"] & subjects["val"]
    texts = {s: {c.meta["text"] for c in clips if c.meta["source"] == "tts"} for s, clips in splits.items()}
    assert not texts["train"] & texts["test"]
    train_voices = {c.meta["voice"] for c in splits["train"] if c.meta["source"] == "tts"}
    assert not any(is_test_voice(Voice(*v.split(":", 1))) for v in train_voices)
    # The held-out voice set is not empty and spans engines.
    assert {v.engine for v in all_voices() if is_test_voice(v)} >= {"festival", "flite", "espeak"}
