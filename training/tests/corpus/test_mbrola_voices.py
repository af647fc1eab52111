"""MBROLA's voices of other languages speaking English: a phone for every English phone, a break where a voice lacks
a diphone, English labels at the times MBROLA was given."""
import shutil

import numpy as np
import pytest

from talkingface.corpus import mbrola_voices as mv
from talkingface.corpus.speech import SpeechToolError
from talkingface.phones import BILABIALS, PHONES, SILENCE


def test_every_english_phone_has_candidates_and_bilabials_are_said_as_they_are():
    assert set(mv.CANDIDATES) == set(PHONES) - {SILENCE}
    for p in BILABIALS:
        assert mv.CANDIDATES[p][0] == p.lower()
    assert set(mv.NEEDED) <= set(mv.CANDIDATES) and not set(mv.USABLE) & set(mv.ENGLISH)
    # every vowel candidate starts with a character the intonation reads as a vowel, no consonant's first does
    assert all(c.split()[0][0] in mv.VOWEL_STARTS for p in mv.VOWELS for c in mv.CANDIDATES[p])
    assert not any(c and c[0] in mv.VOWEL_STARTS for p in set(mv.CANDIDATES) - mv.VOWELS - {"W", "Y", "ER"} for c in mv.CANDIDATES[p])


def test_a_missing_pair_gets_a_break_and_every_phone_keeps_its_span():
    segs = [("_", 100, []), ("b", 60, []), ("m", 70, []), ("a", 150, [(0.075, 120.0)]), ("b", 60, []), ("_", 100, [])]
    owner = [0, 1, 2, 3, 4, 5]
    out, own = mv._break_pairs(segs, owner, {("b", "m"), ("b", "_")})
    assert [n for n, _, _ in out] == ["_", "b", "_", "m", "a", "b", "_"]   # "b _" is a pause already: left alone
    assert sum(ms for _, ms, _ in out) == sum(ms for _, ms, _ in segs)
    spans = lambda ss, oo: {o: sum(ms for (_, ms, _), x in zip(ss, oo) if x == o) for o in set(oo)}
    before, after = spans(segs, owner), spans(out, own)
    assert after[1] + after[2] == before[1] + before[2] and after[1] == 60 + mv.BREAK_MS - 0 or after[2] == 70 - mv.BREAK_MS
    assert mv._pho(out).splitlines()[4] == "a 150 50 120"                   # pitch targets as % of the segment
    assert mv._break_pairs(segs, owner, set()) == (segs, owner)


def test_a_voice_outside_the_installed_ones_is_refused_with_the_setup_command(monkeypatch):
    monkeypatch.setattr(mv, "database", lambda name: mv.ROOT / "no-such-voice" / name)
    with pytest.raises(SpeechToolError, match="setup --mbrola-voices"):
        mv.synthesize_mbrola("mbrola:de4", "a pin", 16000)
    monkeypatch.setattr(mv.shutil, "which", lambda tool: None)
    assert mv.available() == []


@pytest.mark.skipif(not mv.available() or shutil.which("festival") is None,
                    reason="MBROLA's voices are not installed: scripts/py -m talkingface.corpus setup --mbrola-voices")
def test_the_installed_voices_are_the_usable_ones_and_say_english_with_english_labels():
    assert all(mv.usable(n.split(":")[1]) for n in mv.available())
    name = "mbrola:de4" if "mbrola:de4" in mv.available() else mv.available()[0]
    audio, phones = mv.synthesize_mbrola(name, "Bob made a map.", 16000, 1.0, seed=1)
    names = [p for p, _, _ in phones]
    assert names[0] == names[-1] == SILENCE and names.count("M") == 2 and names.count("B") == 2 and "P" in names
    assert all(b > a for _, a, b in phones) and all(phones[i][2] == phones[i + 1][1] for i in range(len(phones) - 1))
    assert len(audio) == pytest.approx(phones[-1][2] * 16000, abs=160)  # MBROLA ends a few ms early, whatever the length
    voiced = audio[int(phones[1][1] * 16000): int(phones[-2][2] * 16000)]
    assert np.sqrt(np.mean(voiced ** 2)) > 0.01  # it spoke
    slow, slow_phones = mv.synthesize_mbrola(name, "Bob made a map.", 16000, 0.8, seed=1)
    assert slow_phones[-1][2] == pytest.approx(phones[-1][2] / 0.8, rel=0.05)
