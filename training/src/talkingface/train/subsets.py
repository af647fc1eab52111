"""The clips each results table reports on, besides all of a split's: the synthetic voices, the recorded human speech,
and the recorded speech whose sentence training never heard.

Why the last: the corpus splits its recordings by a hash of the prompt's name (corpus/plan.py), and the recorded
speaker says a few prompts more than once under other names ("To exit the menu..." and "...to exit the menu."), so 4
of the full corpus's 11 recorded test clips say a sentence that its train split holds in the same voice, and the
speech front-end trained on it. The recorded-speech figures are shown on all 11 and on the others apart.
"""
from __future__ import annotations

import json
import re

# (results key, label) in the order the tables show them.
PARTS = (("all", None), ("synthetic", "synthetic voices"), ("human", "recorded human speech"),
         ("human_unheard", "recorded speech, sentences training never heard"))


def labels(split: str) -> list[tuple[str, str]]:
    """PARTS with the first one's label naming the split."""
    return [(name, label or f"all {split} clips") for name, label in PARTS]


def normalised(text: str) -> str:
    """A sentence as said: lower case, words only ("...to exit the menu." == "To exit the menu...")."""
    return " ".join(re.findall(r"[a-z0-9']+", text.lower()))


def sentences(ds, split: str) -> dict[str, str]:
    """Each clip of `split` -> its normalised sentence, from the corpus's alignments ({} for a dataset without)."""
    folder = ds.root / "alignments"
    if not folder.is_dir():
        return {}
    out = {}
    for key in ds.keys(split):
        path = folder / f"{key}.json"
        text = json.loads(path.read_text()).get("text") if path.is_file() else None
        if text:
            out[key] = normalised(text)
    return out


def member(row: dict, part: str) -> bool:
    """Whether an evaluated clip's row (with "source" and "sentence_heard": None where its sentence is not known)
    belongs to `part`."""
    human = row["source"] == "human"
    return {"all": True, "synthetic": not human, "human": human,
            "human_unheard": human and row.get("sentence_heard") is False}[part]
