"""Each phone's articulation (its viseme): what the rig's parameters do while it is spoken.

Every phone of talkingface.phones has a target for each articulatory parameter of the rig and a
dominance (how strongly it holds that parameter against its neighbours, after
Cohen & Massaro 1993, "Modeling coarticulation in synthetic visual speech").
Bilabials and labiodentals dominate the lips; alveolars and velars barely
constrain them, so they take the shape of the surrounding vowels.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..phones import PHONES, SILENCE

# Articulatory parameters, all in [0, 1] (the rig maps them to millimetres and degrees).
PARAMS = ("jaw", "lip_open", "round", "protrude", "spread", "close", "labiodental")
P = {name: i for i, name in enumerate(PARAMS)}


@dataclass(frozen=True)
class Articulation:
    target: tuple[float, ...]     # one value per PARAMS entry
    dominance: tuple[float, ...]  # Cohen-Massaro magnitude per parameter


def _a(jaw=0.0, lip_open=0.0, round=0.0, protrude=0.0, spread=0.0, close=0.0, labiodental=0.0, dom=1.0, lip_dom=None):
    target = (jaw, lip_open, round, protrude, spread, close, labiodental)
    lip = dom if lip_dom is None else lip_dom
    dominance = (dom, lip, lip, lip, lip, lip, lip)
    return Articulation(target, dominance)


# Targets from phonetic descriptions of English visemes (jaw height, lip aperture,
# rounding/protrusion, spreading); dominances follow Cohen-Massaro's ordering.
ARTICULATION: dict[str, Articulation] = {
    "AA": _a(jaw=0.95, lip_open=0.65, spread=0.1),
    "AE": _a(jaw=0.75, lip_open=0.55, spread=0.45),
    "AH": _a(jaw=0.6, lip_open=0.45, spread=0.1),
    "AO": _a(jaw=0.75, lip_open=0.5, round=0.5, protrude=0.35),
    "AW": _a(jaw=0.8, lip_open=0.55, round=0.3, protrude=0.2),
    "AY": _a(jaw=0.8, lip_open=0.55, spread=0.3),
    "EH": _a(jaw=0.55, lip_open=0.4, spread=0.35),
    "ER": _a(jaw=0.35, lip_open=0.25, round=0.4, protrude=0.35),
    "EY": _a(jaw=0.45, lip_open=0.35, spread=0.5),
    "IH": _a(jaw=0.35, lip_open=0.3, spread=0.45),
    "IY": _a(jaw=0.2, lip_open=0.2, spread=0.75),
    "OW": _a(jaw=0.55, lip_open=0.35, round=0.8, protrude=0.55),
    "OY": _a(jaw=0.6, lip_open=0.4, round=0.65, protrude=0.45),
    "UH": _a(jaw=0.3, lip_open=0.2, round=0.65, protrude=0.5),
    "UW": _a(jaw=0.2, lip_open=0.15, round=1.0, protrude=0.85),
    # Bilabials: lips pressed together (the rig closes the contour exactly).
    "P": _a(jaw=0.1, close=1.0, dom=1.0, lip_dom=8.0),
    "B": _a(jaw=0.1, close=1.0, dom=1.0, lip_dom=8.0),
    "M": _a(jaw=0.1, close=1.0, dom=1.0, lip_dom=8.0),
    # Labiodentals: lower lip up to the upper teeth.
    "F": _a(jaw=0.15, labiodental=1.0, dom=1.0, lip_dom=6.0),
    "V": _a(jaw=0.15, labiodental=1.0, dom=1.0, lip_dom=6.0),
    "TH": _a(jaw=0.25, lip_open=0.25, dom=1.5, lip_dom=0.6),
    "DH": _a(jaw=0.25, lip_open=0.25, dom=1.5, lip_dom=0.6),
    "T": _a(jaw=0.25, lip_open=0.15, dom=0.8, lip_dom=0.2),
    "D": _a(jaw=0.25, lip_open=0.15, dom=0.8, lip_dom=0.2),
    "N": _a(jaw=0.25, lip_open=0.15, dom=0.8, lip_dom=0.2),
    "L": _a(jaw=0.3, lip_open=0.2, dom=0.6, lip_dom=0.2),
    "S": _a(jaw=0.1, lip_open=0.12, spread=0.4, dom=3.0, lip_dom=0.8),
    "Z": _a(jaw=0.1, lip_open=0.12, spread=0.4, dom=3.0, lip_dom=0.8),
    "SH": _a(jaw=0.15, lip_open=0.2, round=0.6, protrude=0.75, dom=2.0, lip_dom=3.0),
    "ZH": _a(jaw=0.15, lip_open=0.2, round=0.6, protrude=0.75, dom=2.0, lip_dom=3.0),
    "CH": _a(jaw=0.15, lip_open=0.2, round=0.55, protrude=0.7, dom=2.0, lip_dom=3.0),
    "JH": _a(jaw=0.15, lip_open=0.2, round=0.55, protrude=0.7, dom=2.0, lip_dom=3.0),
    "K": _a(jaw=0.3, lip_open=0.2, dom=0.5, lip_dom=0.15),
    "G": _a(jaw=0.3, lip_open=0.2, dom=0.5, lip_dom=0.15),
    "NG": _a(jaw=0.3, lip_open=0.2, dom=0.5, lip_dom=0.15),
    "HH": _a(jaw=0.4, lip_open=0.3, dom=0.2, lip_dom=0.1),
    "R": _a(jaw=0.2, lip_open=0.15, round=0.5, protrude=0.4, dom=1.0, lip_dom=1.5),
    "W": _a(jaw=0.1, lip_open=0.1, round=1.0, protrude=0.8, dom=1.0, lip_dom=5.0),
    "Y": _a(jaw=0.15, lip_open=0.15, spread=0.5, dom=1.0, lip_dom=1.0),
    # Silence relaxes to a closed, neutral mouth: lips lightly together, jaw at rest.
    SILENCE: _a(close=1.0, dom=0.6, lip_dom=0.6),
}
assert set(ARTICULATION) == set(PHONES)

TARGETS = np.array([ARTICULATION[p].target for p in PHONES], dtype=np.float64)        # (num_phones, num_params)
DOMINANCE = np.array([ARTICULATION[p].dominance for p in PHONES], dtype=np.float64)   # (num_phones, num_params)
