"""Forced alignment (used for espeak-ng and recorded speech) against festival/flite's exact timings."""
import numpy as np

from talkingface.corpus.align import Aligner
from talkingface.corpus.speech import Voice, synthesize
from tests.speech_tools import needs_speech_tools

pytestmark = needs_speech_tools


def test_forced_alignment_matches_synthesiser_timings():
    """The aligner (used for espeak-ng and recorded speech) against festival/flite's exact timings."""
    aligner = Aligner()
    errors = []
    for voice in (Voice("festival", "kal"), Voice("flite", "rms"), Voice("festival", "slt")):
        text = "Did Zoe measure the azure vase near the harbour yesterday?"
        audio, truth = synthesize(voice, text, 16000)
        phones, _ = aligner.align(audio, 16000, text)
        t_ends = [b for p, a, b in truth if p != "SIL"]
        a_ends = [b for p, a, b in phones if p != "SIL"]
        assert len(a_ends) == len(t_ends), voice
        errors += list(np.abs(np.subtract(t_ends, a_ends)))
    assert np.mean(errors) < 0.025
