"""The dataset card's account of recordings a TTS voice had to speak."""
from talkingface.corpus.card import recorded_fallback


def test_the_card_counts_recordings_spoken_by_tts():
    failed = {"Synth01_sentence02": {"recording": "vm-goodbye", "reason": "pocketsphinx found too few phones"}}
    line = recorded_fallback({"recordings_failed_alignment": failed})
    assert line.startswith("1 clip(s) planned as recorded speech") and "Synth01_sentence02 (vm-goodbye: pocketsphinx found too few phones)" in line
    assert recorded_fallback({"recordings_failed_alignment": {}}) == "Every recording planned for a clip was aligned."
    assert "predates" in recorded_fallback({})
