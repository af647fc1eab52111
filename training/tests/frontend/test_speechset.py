"""The speech front-end's speech set keeps the mesh corpus's test material out and labels every frame."""
from contextlib import contextmanager

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


def test_the_kokoro_voices_option_picks_english_accented_or_all(monkeypatch):
    monkeypatch.setattr(kokoro, "voice_names", lambda: ["af_a", "bm_b"])
    monkeypatch.setattr(kokoro, "accented_voice_names", lambda: ["accented/ff_c", "accented/zm_d"])
    def voices(which):
        return {part.split("*")[0] for s in speechset.plan(20, seed=3, kokoro_voices=which) if s.engine == "kokoro" for part in s.voice.split("+")}
    assert voices("english") == {"af_a", "bm_b"}
    assert voices("accented") == {"accented/ff_c", "accented/zm_d"}
    assert voices("all") == {"af_a", "bm_b", "accented/ff_c", "accented/zm_d"}
    monkeypatch.setattr(kokoro, "accented_voice_names", lambda: [])
    with pytest.raises(kokoro.KokoroMissing, match="--kokoro-accented"):
        speechset.plan(5, seed=0, kokoro_voices="accented")


def test_the_accents_option_gives_kokoro_clips_an_accent_and_leaves_the_rest_of_the_plan(monkeypatch):
    monkeypatch.setattr(kokoro, "voice_names", lambda: ["af_a", "bm_b"])
    plain, accented = speechset.plan(20, seed=3), speechset.plan(20, seed=3, accent_share=0.5)
    changed = [(a, b) for a, b in zip(plain, accented) if a != b]
    k = sum(s.engine == "kokoro" for s in plain)
    assert all(a.engine == b.engine == "kokoro" and b.voice.startswith(a.voice + "@") for a, b in changed)
    assert 0.35 * k < len(changed) < 0.65 * k
    accents = {b.voice.split("@")[1] for _, b in changed}
    assert accents <= set(kokoro.ACCENTS) and len(accents) >= 3 and "en-gb-scotland" not in kokoro.ACCENTS
    with pytest.raises(ValueError, match="unknown accent"):
        kokoro.phonemes("a pin", False, "en-gb-scotland")


def test_the_extrapolate_option_gives_kokoro_clips_a_voice_beyond_two_and_leaves_the_rest_of_the_plan(monkeypatch, tmp_path):
    monkeypatch.setattr(kokoro, "voice_names", lambda: ["af_a", "bm_b", "am_c"])
    plain, beyond = speechset.plan(20, seed=3), speechset.plan(20, seed=3, extrapolate_share=0.5)
    changed = [(a, b) for a, b in zip(plain, beyond) if a != b]
    k = sum(s.engine == "kokoro" for s in plain)
    assert all(a.engine == b.engine == "kokoro" and (a.key, a.text, a.speed) == (b.key, b.text, b.speed) for a, b in changed)
    assert 0.25 * k < len(changed) < 0.65 * k
    for _, b in changed:
        first, second = b.voice.split("+")
        name, w = first.split("*")
        assert speechset.EXTRAPOLATE[0] <= float(w) <= speechset.EXTRAPOLATE[1] and name != second
    # The style vector lies beyond the first voice, away from the second: w a + (1 - w) b.
    with _style_tables(monkeypatch, tmp_path, {"voices/af_a": 1.0, "voices/bm_b": 3.0}):
        assert kokoro.style("af_a*1.5+bm_b", 12)[0] == 1.5 * 1.0 - 0.5 * 3.0


def test_an_accented_voice_reads_its_own_style_table(monkeypatch, tmp_path):
    with _style_tables(monkeypatch, tmp_path, {"voices/af_a": 1.0, "voices-accented/ff_c": 3.0}):
        assert kokoro.style("accented/ff_c", 12)[0] == 3.0 and kokoro.style("af_a", 12)[0] == 1.0
        assert kokoro.style("accented/ff_c*0.25+af_a", 12)[0] == 0.25 * 3.0 + 0.75 * 1.0
        assert kokoro.accented_voice_names() == ["accented/ff_c"]


@contextmanager
def _style_tables(monkeypatch, tmp_path, tables: dict):
    """Kokoro's style tables as constant files ("folder/name" -> value) under tmp_path, read afresh inside."""
    import numpy as np
    for rel, value in tables.items():
        (tmp_path / rel).parent.mkdir(exist_ok=True)
        np.full((510, 256), value, "<f4").tofile(tmp_path / f"{rel}.bin")
    monkeypatch.setattr(kokoro, "HOME", tmp_path)
    kokoro._style_table.cache_clear()
    try:
        yield
    finally:
        kokoro._style_table.cache_clear()


def test_the_vocoder_keeps_the_words_and_replaces_the_source():
    """A vowel at 140 Hz with a formant near 700 Hz, vocoded: the same length, the envelope kept (the formant still
    stands out), and pitched at its own F0 by the vocoder's pulses; noise stays unvoiced noise."""
    import numpy as np
    from talkingface.corpus.augment import vocode
    sr, f0 = 16000, 140.0
    t = np.arange(int(1.0 * sr)) / sr
    vowel = sum(np.exp(-(((k * f0) - 700) / 300) ** 2) * np.sin(2 * np.pi * k * f0 * t) for k in range(1, 40)).astype(np.float32)
    y = vocode(0.5 * vowel / np.abs(vowel).max(), sr, np.random.default_rng(0), noise_mix=0.0)
    assert y.shape == vowel.shape and np.isfinite(y).all() and 0.1 < np.abs(y).max() <= 0.5 + 1e-6
    mid = y[4000:12000].astype(np.float64)
    spec = np.abs(np.fft.rfft(mid * np.hanning(len(mid))))
    freqs = np.fft.rfftfreq(len(mid), 1 / sr)
    assert spec[(freqs > 500) & (freqs < 900)].mean() > 5 * spec[(freqs > 2500) & (freqs < 4000)].mean()  # the formant
    ac = np.correlate(mid, mid, "full")[len(mid) - 1:]
    lag = np.argmax(ac[int(sr / 300):int(sr / 80)]) + int(sr / 300)
    assert abs(sr / lag - f0) < 5  # periodic at the speech's own pitch
    noise = np.random.default_rng(1).standard_normal(sr).astype(np.float32) * 0.1
    z = vocode(noise, sr, np.random.default_rng(2))
    zc = np.correlate(z[4000:12000], z[4000:12000], "full")[7999:]
    assert zc[int(sr / 300):int(sr / 80)].max() < 0.3 * zc[0]  # no pitch where there was none


@pytest.mark.parametrize("module, voices, option, engine", [
    ("more_voices", ["rhvoice:bdl", "pico:en-GB"], "more_share", "more"),
    ("diphone_voices", ["festival:rab", "festival:us1"], "diphone_share", "diphone"),
    ("mbrola_voices", ["mbrola:de4", "mbrola:fr2"], "mbrola_share", "mbrola")])
def test_a_voices_option_gives_synthetic_clips_to_its_voices_and_leaves_the_rest(monkeypatch, module, voices, option, engine):
    import importlib
    voice_module = importlib.import_module(f"talkingface.corpus.{module}")
    monkeypatch.setattr(kokoro, "voice_names", lambda: ["af_a", "bm_b"])
    monkeypatch.setattr(voice_module, "available", lambda: voices)
    plain, given = speechset.plan(20, seed=3), speechset.plan(20, seed=3, **{option: 0.3})
    changed = [(a, b) for a, b in zip(plain, given) if a != b]
    synthetic = sum(s.engine != "human" for s in plain)
    assert all(a.engine != "human" and b.engine == engine and (a.key, a.text) == (b.key, b.text) for a, b in changed)
    assert all(0.85 <= b.speed <= 1.15 for _, b in changed)
    assert 0.15 * synthetic < len(changed) < 0.45 * synthetic
    assert {b.voice for _, b in changed} == set(voices)
    monkeypatch.setattr(voice_module, "available", lambda: [])
    with pytest.raises(RuntimeError, match=f"setup --{module.replace('_', '-')}"):
        speechset.plan(5, seed=0, **{option: 0.3})


def test_the_voice_modules_keep_the_test_splits_voices_and_non_free_voices_out():
    from talkingface.corpus import diphone_voices, more_voices
    from talkingface.corpus.speech import FESTIVAL_VOICES
    voices = {v for _, v in more_voices.VOICES}
    assert "alan" not in voices and not voices & {"evgeniy-eng", "lyubov"}  # Scottish (held out by the test split); CC-BY-NC-ND
    assert not set(diphone_voices.VOICES) & set(FESTIVAL_VOICES)  # ked (held out by the test split) and kal stay the corpus's


@pytest.mark.parametrize("module, outside, inside", [("more_voices", "rhvoice:alan", "pico:en-US"),
                                                     ("diphone_voices", "festival:ked", "festival:us1")])
def test_a_voice_module_refuses_a_voice_outside_it_and_names_a_missing_tool(monkeypatch, module, outside, inside):
    import importlib
    from talkingface.corpus.speech import SpeechToolError
    voice_module = importlib.import_module(f"talkingface.corpus.{module}")
    with pytest.raises(ValueError, match="unknown voice"):
        voice_module.synthesize(outside, "a pin", 16000)
    monkeypatch.setattr(voice_module.shutil, "which", lambda tool: None)
    assert voice_module.available() == []
    with pytest.raises(SpeechToolError, match=f"setup --{module.replace('_', '-')}"):
        voice_module.synthesize(inside, "a pin", 16000)


@pytest.mark.skipif(not __import__("shutil").which("RHVoice-test") or not __import__("shutil").which("pico2wave"),
                    reason="RHVoice and Pico missing: scripts/py -m talkingface.corpus setup --more-voices")
def test_every_more_voice_says_a_sentence():
    from talkingface.corpus import more_voices
    for name in more_voices.available():
        audio = more_voices.synthesize(name, "Maybe the bob will pump the map.", 16000)
        assert 1.2 < len(audio) / 16000 < 4.0 and 0.01 < float(abs(audio).max()) <= 1.0, name


@pytest.mark.skipif(not __import__("shutil").which("festival"), reason="festival missing: scripts/py -m talkingface.corpus setup")
def test_every_installed_diphone_voice_says_a_sentence_and_speed_shortens_it():
    from talkingface.corpus import diphone_voices
    voices = diphone_voices.available()
    if not voices:
        pytest.skip("no diphone voice installed: scripts/py -m talkingface.corpus setup --diphone-voices")
    for name in voices:
        slow, fast = (diphone_voices.synthesize(name, "Maybe the bob will pump the map.", 16000, s) for s in (0.85, 1.15))
        assert 1.2 < len(slow) / 16000 < 4.0 and 0.01 < float(abs(slow).max()) <= 1.0, name
        assert len(fast) < 0.9 * len(slow), name
