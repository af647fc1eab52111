"""Forced alignment: phone timings for speech whose words are known (espeak-ng voices, recorded speech).

pocketsphinx 5 with its bundled en-us acoustic model and CMUdict. Two passes
(word alignment, then phone/state alignment), as the pocketsphinx docs describe;
if the second pass fails ("Alignment failed in frame N", about one utterance in
ten), each phone becomes a one-phone pseudo-word and a single pass aligns those.
Words missing from CMUdict get flite's letter-to-sound pronunciation. Against
festival/flite ground truth the boundaries are off by 11-16 ms on average.
"""
from __future__ import annotations

import logging
import re
import subprocess

import numpy as np

from ..phones import PHONES, SILENCE, normalise_phone
from .speech import merge_silences

log = logging.getLogger(__name__)

ALIGN_RATE = 16000  # the en-us acoustic model's sample rate
_FRAME = 0.01       # pocketsphinx frame shift, s
_PAD = 0.25         # silence added on both sides before aligning, s


class AlignmentError(RuntimeError):
    """pocketsphinx could not align the words to the audio; the message says which words and why."""


def spoken_words(text: str) -> list[str]:
    """The words a reader says for `text`: flite's normaliser spells out numbers and symbols; keep [a-z']."""
    out = subprocess.run(["flite", "-pw", "-t", text, "none"], capture_output=True, text=True, check=True).stdout
    return [w for w in (re.sub(r"[^a-z']", "", t.lower()) for t in out.split()) if w]


def flite_pronunciation(word: str) -> str:
    out = subprocess.run(["flite", "-ps", "-t", word, "none"], capture_output=True, text=True, check=True).stdout
    phones = [normalise_phone(p) for p in out.split()]
    return " ".join(p for p in phones if p != SILENCE)


class Aligner:
    """One pocketsphinx decoder (about 0.2 s to load). Its state carries over between utterances, so
    where reproducibility matters, use a new Aligner per utterance."""

    def __init__(self):
        from pocketsphinx import Decoder  # imported here so the rest of the toolkit works without it

        # Batch cepstral mean normalisation: each utterance is normalised on its own. The default ("live")
        # carries an estimate from one utterance to the next, so a clip's alignment would depend on which
        # clips the same worker aligned before it, and the corpus on how clips fell to workers.
        self.decoder = Decoder(samprate=ALIGN_RATE, lm=None, loglevel="FATAL", cmn="batch")
        arpa = [p for p in PHONES if p != SILENCE]
        for k, p in enumerate(arpa):  # one-phone pseudo-words for the fallback pass
            self.decoder.add_word(f"p_{p.lower()}", p, k == len(arpa) - 1)

    def _decode(self, pcm: bytes) -> None:
        d = self.decoder
        d.start_utt()
        d.process_raw(pcm, full_utt=True)
        d.end_utt()

    def align(self, audio: np.ndarray, sample_rate: int, text: str) -> tuple[list[tuple[str, float, float]], str]:
        """Mono audio at ALIGN_RATE and its transcript -> (ARPAbet phones with start/end s, method used)."""
        if sample_rate != ALIGN_RATE:
            raise AlignmentError(f"alignment needs {ALIGN_RATE} Hz audio, got {sample_rate}")
        d = self.decoder
        words = spoken_words(text)
        if not words:
            raise AlignmentError(f"no words to align in {text!r}")
        for w in words:
            if d.lookup_word(w) is None:
                pron = flite_pronunciation(w)
                if pron:
                    d.add_word(w, pron, True)
        words = [w for w in words if d.lookup_word(w) is not None]
        # The acoustic model expects silence around an utterance; synthesisers like espeak-ng start
        # speaking on the first sample, which makes the phone pass fail. Pad, align, shift back.
        pad = np.zeros(int(_PAD * sample_rate), dtype=np.float32)
        pcm = (np.clip(np.concatenate([pad, audio, pad]), -1, 1) * 32767).astype("<i2").tobytes()
        duration = len(audio) / sample_rate
        try:
            d.set_align_text(" ".join(words))
            self._decode(pcm)
            d.set_alignment()
            self._decode(pcm)
            phones = [(e.name, e.start * _FRAME, (e.start + e.duration) * _FRAME) for e in d.get_alignment().phones()]
            method = "two-pass"
        except RuntimeError as first:  # pocketsphinx's "Alignment failed in frame N": the one-pass fallback below
            log.debug("two-pass alignment of %r failed (%s); aligning its phones in one pass", text, first)
            tokens = [f"p_{p.lower()}" for w in words for p in d.lookup_word(w).split()]
            try:
                d.set_align_text(" ".join(tokens))
                self._decode(pcm)
                segs = list(d.seg() or [])
            except RuntimeError as e:
                raise AlignmentError(f"pocketsphinx could not align {text!r}: two passes: {first}; one pass: {e}") from e
            # seg() start frames come out one frame early (measured against TTS ground truth).
            phones = [("SIL" if s.word == "<sil>" else s.word[2:], s.start_frame * _FRAME + _FRAME, (s.end_frame + 1) * _FRAME + _FRAME)
                      for s in segs if s.word not in ("<s>", "</s>")]
            method = "one-pass-phones"
        phones = _tidy([(p, a - _PAD, b - _PAD) for p, a, b in phones], duration)
        if sum(p != SILENCE for p, _, _ in phones) < max(1, len(words) // 2):
            raise AlignmentError(f"pocketsphinx found too few phones for {text!r} ({method})")
        return phones, method


def _tidy(phones, duration: float) -> list[tuple[str, float, float]]:
    """Fillers to silence, gaps filled with silence, times clipped to the audio, neighbours merged.
    The end is left where the aligner put it (clip.py records how far that is from the audio's end)."""
    out: list[tuple[str, float, float]] = []
    t = 0.0
    for name, a, b in phones:
        a = max(a, 0.0)
        p = SILENCE if name.startswith("+") or name in ("SIL", "<sil>") else normalise_phone(name)
        a, b = max(a, t), min(b, duration)
        if b <= a:
            continue
        if a > t + 1e-6:
            out.append((SILENCE, t, a))
        out.append((p, a, b))
        t = b
    return merge_silences(out)
