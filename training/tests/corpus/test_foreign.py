"""festival's foreign voices speaking English: every English phone has a sound, labels stay English, times exact."""
import numpy as np
import pytest

from talkingface.corpus import foreign
from talkingface.frontend import speechset
from talkingface.phones import BILABIALS, PHONES, SILENCE


def test_every_english_phone_has_a_sound_and_bilabials_stay_bilabial():
    for lang, table in foreign.PHONE_MAPS.items():
        assert set(table) == set(PHONES) - {SILENCE}, lang
        for p in BILABIALS:
            assert table[p] == p.lower(), (lang, p)


def test_segments_keep_durations_and_say_each_phone_by_its_owner():
    phones = [("SIL", 0.0, 0.2), ("HH", 0.2, 0.26), ("AY", 0.26, 0.46), ("B", 0.46, 0.52), ("AA", 0.52, 0.7), ("B", 0.7, 0.76),
              ("SIL", 0.76, 1.0)]
    it = foreign.FOREIGN_VOICES["pc_diphone"]
    segs, owner = foreign.segments(phones, it, 1.0, np.random.default_rng(0))
    assert [s[0] for s in segs] == ["#", "a", "i", "b", "a", "b", "#"]  # Italian has no /h/: the diphthong says it
    assert owner == [0, 2, 2, 3, 4, 5, 6]
    assert sum(s[1] for s in segs) == pytest.approx(1.0)
    assert segs[1][1] == pytest.approx((0.06 + 0.2) / 2)  # the /h/'s time went to the next phone, said in two
    slow, _ = foreign.segments(phones, it, 0.8, np.random.default_rng(0))
    assert sum(s[1] for s in slow) == pytest.approx(1.25)
    assert all(s[2] for s in segs if s[0] in ("a", "i")) and all(60 < f < 300 for s in segs for _, f in s[2])


def test_czech_clusters_take_the_voicing_of_their_last_obstruent():
    assert foreign.assimilate(["d", "k", "a", "t", "b", "a", "z"], "#") == ["t", "k", "a", "d", "b", "a", "s"]
    assert foreign.assimilate(["a", "b", "#"], "#") == ["a", "p", "#"]


def test_the_plan_gives_a_share_to_foreign_voices_and_leaves_the_rest_as_it_was(monkeypatch):
    monkeypatch.setattr(speechset.kokoro, "voice_names", lambda: ["af_a", "bm_b"])
    monkeypatch.setattr(foreign, "available", lambda: ["pc_diphone", "czech_dita"])
    base = speechset.plan(20, seed=3)
    mixed = speechset.plan(20, seed=3, foreign_share=0.3)
    moved = [m for b, m in zip(base, mixed) if b != m]
    synthetic = [b for b in base if b.engine != "human"]
    assert 0.2 < len(moved) / len(synthetic) < 0.4
    assert all(m.engine == "foreign" and m.voice in ("pc_diphone", "czech_dita") for m in moved)
    assert all(m.text == b.text for b, m in zip(base, mixed))
    assert [b for b in base if b.engine == "human"] == [m for m in mixed if m.engine == "human"]  # the real voice stays
    monkeypatch.setattr(foreign, "available", lambda: [])
    with pytest.raises(RuntimeError, match="setup --foreign-voices"):
        speechset.plan(5, seed=0, foreign_share=0.3)


@pytest.mark.skipif(not foreign.available(), reason="festival's foreign voices are not installed (corpus setup --foreign-voices)")
def test_a_foreign_voice_says_the_sentence_with_english_labels_and_festivals_times():
    name = foreign.available()[0]
    audio, phones = foreign.synthesize_foreign(name, "Bob made a map.", 16000, 1.0, seed=1)
    names = [p for p, _, _ in phones]
    assert names[0] == names[-1] == SILENCE and names.count("M") == 2 and names.count("B") == 2 and "P" in names
    assert all(b > a for _, a, b in phones) and all(phones[i][2] == phones[i + 1][1] for i in range(len(phones) - 1))
    assert len(audio) == pytest.approx(phones[-1][2] * 16000, abs=2)
    voiced = audio[int(phones[1][1] * 16000): int(phones[-2][2] * 16000)]
    assert np.sqrt(np.mean(voiced ** 2)) > 0.01  # it spoke


def test_english_phones_end_where_their_last_segment_ends_and_missing_bilabial_diphones_refuse():
    english = [("SIL", 0.0, 0.2), ("AY", 0.2, 0.4), ("B", 0.4, 0.5)]
    assert foreign.english_spans(english, [0, 1, 1, 2], [0.2, 0.3, 0.42, 0.5]) == [("SIL", 0.0, 0.2), ("AY", 0.2, 0.42), ("B", 0.42, 0.5)]
    foreign.refuse_missing("v", [("a", "i")], foreign.PHONE_MAPS["it"])             # one, away from /p b m/: kept
    with pytest.raises(foreign.SpeechToolError, match="lacks diphones"):
        foreign.refuse_missing("v", [("a", "b")], foreign.PHONE_MAPS["it"])
    with pytest.raises(foreign.SpeechToolError, match="lacks diphones"):
        foreign.refuse_missing("v", [("a", "i")] * (foreign.MAX_MISSING + 1), foreign.PHONE_MAPS["it"])
