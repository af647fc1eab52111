"""The phone set every stage shares: ARPAbet as in CMUdict and pocketsphinx, plus silence.

The corpus labels its clips with these phones, the content encoder's classes are these plus a blank
(model/config.py), the measures group them (bilabials, open vowels), and the exporter writes the class
names into the manifest for the browser.
"""
from __future__ import annotations

import numpy as np

SILENCE = "SIL"
BLANK = "<blank>"  # the CTC-style blank class after the phones (as DeepSpeech's alphabet + blank)
# The 39 ARPAbet phones of CMUdict plus silence.
PHONES = (
    "AA", "AE", "AH", "AO", "AW", "AY", "B", "CH", "D", "DH", "EH", "ER", "EY", "F", "G", "HH", "IH", "IY",
    "JH", "K", "L", "M", "N", "NG", "OW", "OY", "P", "R", "S", "SH", "T", "TH", "UH", "UW", "V", "W", "Y",
    "Z", "ZH", SILENCE,
)
PHONE_INDEX = {p: i for i, p in enumerate(PHONES)}
# The content encoder's classes in logit order.
CONTENT_CLASSES = (*PHONES, BLANK)


def frame_labels(phones, n_frames: int, rate: float, dtype=np.int64) -> np.ndarray:
    """(n_frames,) phone classes at `rate` frames per second from (phone, start s, end s) segments, silence elsewhere."""
    labels = np.full(n_frames, PHONE_INDEX[SILENCE], dtype)
    for p, a, b in phones:
        labels[int(round(a * rate)) : int(round(b * rate))] = PHONE_INDEX[p]
    return labels

VOWELS = frozenset("AA AE AH AO AW AY EH ER EY IH IY OW OY UH UW".split())
OPEN_VOWELS = frozenset(("AA", "AE", "AH", "AO", "AW", "AY"))
BILABIALS = frozenset(("P", "B", "M"))
LABIODENTALS = frozenset(("F", "V"))
# What a viewer sees of each phone at the lips (the groups of viseme sets such as Oculus's): a front-end that takes
# one phone for another of its group costs the face little, one that takes it for another group shows.
LIP_GROUPS = {
    "closed": ("P", "B", "M"),
    "lip on teeth": ("F", "V"),
    "tongue between teeth": ("TH", "DH"),
    "rounded": ("W", "UW", "UH", "OW", "OY", "AO", "R", "ER", "SH", "ZH", "CH", "JH"),  # AO: open (OPEN_VOWELS), lips rounded
    "open": ("AA", "AE", "AH", "AW", "AY"),
    "spread": ("IY", "IH", "EY", "EH", "Y"),
    "lips at rest": ("T", "D", "N", "L", "S", "Z", "K", "G", "NG", "HH"),
    "silence": (SILENCE,),
}
LIP_GROUP_OF = {p: g for g, phones in LIP_GROUPS.items() for p in phones}

# Phone names used by festival (radio phoneset) and flite (cmu_us) that differ from ARPAbet.
_ALIASES = {
    "PAU": SILENCE, "H#": SILENCE, "SIL": SILENCE, "SP": SILENCE, "BRTH": SILENCE, "#": SILENCE, "_": SILENCE,
    "AX": "AH", "AXR": "ER", "IX": "IH", "UX": "UW", "DX": "D", "NX": "N", "EL": "L", "EM": "M", "EN": "N",
    "HV": "HH", "Q": SILENCE,
}


def normalise_phone(name: str) -> str:
    """Map a synthesiser's or aligner's phone name (any case, stress digits allowed) to the ARPAbet set."""
    p = name.strip().upper().rstrip("012")
    p = _ALIASES.get(p, p)
    if p not in PHONE_INDEX:
        raise ValueError(f"unknown phone {name!r}: add it to the alias table in talkingface/phones.py")
    return p
