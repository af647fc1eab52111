"""The speech front-end's speech set keeps the mesh corpus's test material out and labels every frame."""
import pytest

from talkingface.corpus import kokoro
from talkingface.corpus.plan import is_test_voice
from talkingface.corpus.speech import Voice
from talkingface.frontend import speechset
from talkingface.phones import PHONE_INDEX


def test_the_plan_never_uses_test_voices_or_sentences(monkeypatch):
    monkeypatch.setattr(kokoro, "voice_names", lambda: ["af_a", "bm_b"])
    specs = speechset.plan(20, seed=3)
    banned = speechset.face_test_sentences()
    assert len(specs) == 400 and not any(s.text in banned for s in specs)
    classic = [s for s in specs if s.engine in ("festival", "flite", "espeak")]
    assert classic and not any(is_test_voice(Voice(s.engine, s.voice)) for s in classic)
    assert {s.engine for s in specs} >= {"kokoro", "human"} and any("+" in s.voice for s in specs if s.engine == "kokoro")


def test_a_plan_without_kokoro_says_how_to_set_it_up(monkeypatch):
    monkeypatch.setattr(kokoro, "voice_names", lambda: [])
    with pytest.raises(kokoro.KokoroMissing, match="setup --kokoro"):
        speechset.plan(5, seed=0)


def test_frame_labels_follow_the_phones():
    lab = speechset.frame_labels([("SIL", 0.0, 0.1), ("M", 0.1, 0.25), ("AA", 0.25, 0.4)], 45, 100.0)
    assert lab[5] == PHONE_INDEX["SIL"] and lab[10] == lab[24] == PHONE_INDEX["M"] and lab[25] == PHONE_INDEX["AA"]
    assert lab[44] == PHONE_INDEX["SIL"]  # past the last phone: silence
