"""The mark for tests that run the Debian speech tools (festival, flite, espeak-ng, sox, pocketsphinx's aligner),
and an aligner that always fails, for the corpus's fallbacks."""
import os
import shutil

import pytest

from talkingface.corpus.align import AlignmentError

# Outside CI, a machine without the Debian speech tools skips these (and says how to get them); CI never skips.
needs_speech_tools = pytest.mark.skipif(
    not os.environ.get("CI") and (shutil.which("festival") is None or shutil.which("flite") is None),
    reason="speech tools missing: scripts/py -m talkingface.corpus setup")


class NoAlignment:
    """Stands in for corpus.align.Aligner: every alignment fails, with a reason that names the words."""

    def align(self, audio, sample_rate, text):
        raise AlignmentError(f"test: {text!r} will not align")
