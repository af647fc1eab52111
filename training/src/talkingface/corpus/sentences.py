"""Our own sentence source: a small seeded grammar over a vocabulary picked for phoneme coverage.

Statements, questions and exclamations of varied length, so the voices produce
varied rhythm and intonation. Every English phoneme occurs (the dataset card
reports the counts, measured with CMUdict); the vocabulary leans on rare ones
(/zh/ in "measure", /oy/ in "boy", /th/ and /dh/, /ng/, /ch/ and /jh/).
"""
from __future__ import annotations

import numpy as np

NAMES = ["Maya", "George", "Joshua", "Zoe", "Arthur", "Yusuf", "Beth", "Victor", "Chloe", "Owen", "Ruth", "Hugo",
         "Nadia", "Theo", "Judith", "Paulo", "Oliver", "Vivian", "Sasha", "Quentin"]
ADJECTIVES = ["quiet", "yellow", "huge", "smooth", "cheap", "brave", "thick", "shiny", "rough", "usual", "gentle",
              "frozen", "noisy", "pleasant", "ancient", "awkward", "wooden", "bright", "foolish", "curious", "vivid",
              "loyal", "thirsty", "muddy", "joyful", "visual", "casual", "bitter", "purple", "narrow"]
NOUNS = ["garage", "treasure", "boy", "voyage", "measure", "judge", "church", "thumb", "feather", "mouth", "window",
         "orange", "bridge", "engine", "kitchen", "jacket", "village", "ocean", "mirror", "pencil", "coin", "toy",
         "path", "cushion", "azure vase", "beige chair", "pleasure boat", "sheep", "wagon", "puzzle", "zebra",
         "leather shoe", "cloud", "moon", "fox", "book", "hook", "cookie", "forest", "thread"]
VERBS_PAST = ["pushed", "moved", "watched", "brought", "chose", "found", "caught", "judged", "measured", "hung",
              "spoiled", "enjoyed", "borrowed", "thanked", "fixed", "washed", "painted", "zipped", "loved", "shook",
              "threw", "bought", "joined", "pulled", "wrapped"]
VERBS_BASE = ["push", "move", "watch", "bring", "choose", "find", "catch", "judge", "measure", "hang", "enjoy",
              "borrow", "fix", "wash", "paint", "join", "pull", "wrap", "carry", "share", "thank"]
PLACES = ["near the harbour", "under the bridge", "behind the church", "in the garage", "through the village",
          "beside the ocean", "at the edge of the forest", "on the narrow path", "in the old kitchen",
          "by the window", "across the muddy yard", "over the frozen lake"]
TIMES = ["this morning", "yesterday", "every Thursday", "at noon", "last winter", "during the voyage",
         "after the show", "before dawn", "on the fourth of June", "each evening"]
ADVERBS = ["quickly", "usually", "gently", "rarely", "happily", "thoroughly", "joyfully", "awkwardly", "easily",
           "visually", "boyishly", "smoothly"]
NUMBERS = ["two", "three", "five", "seven", "nine", "twelve", "thirty", "a hundred", "eighteen", "forty"]

TEMPLATES = [
    "{Name} {verb_past} the {adj} {noun} {place}.",
    "The {adj} {noun} was {verb_past} {time}.",
    "Did {Name} {verb} the {adj} {noun} {time}?",
    "Why would anyone {verb} a {adj} {noun} {place}?",
    "{Name} and {Name2} {adv} {verb_past} {number} {adj} {noun}s.",
    "Please {verb} the {noun} before {Name} gets back.",
    "What a {adj} {noun} that was!",
    "I think the {noun} {place} is {adj}, but the {noun2} is {adj2}.",
    "{Time}, {Name} {verb_past} the {noun} and {verb_past2} the {noun2}.",
    "Nobody {verb_past} the {adj} {noun} {adv}.",
    "Would you {verb} my {noun} while I {verb2} the {noun2}?",
    "There were {number} {noun}s {place} {time}.",
    "Thank you for the {adj} {noun}, {Name}!",
    "{Name} always wants to {verb} the {noun} {adv}, right?",
    "The {noun} smells of {adj} leather and {adj2} smoke.",
    "Show me the {noun} you {verb_past} {time}.",
]


def _fill(template: str, rng: np.random.Generator) -> str:
    pick = lambda words: words[rng.integers(len(words))]
    names = rng.choice(NAMES, 2, replace=False)
    s = template.format(
        Name=names[0], Name2=names[1], adj=pick(ADJECTIVES), adj2=pick(ADJECTIVES), noun=pick(NOUNS), noun2=pick(NOUNS),
        verb_past=pick(VERBS_PAST), verb_past2=pick(VERBS_PAST), verb=pick(VERBS_BASE), verb2=pick(VERBS_BASE),
        place=pick(PLACES), time=pick(TIMES), Time=pick(TIMES).capitalize(), adv=pick(ADVERBS), number=pick(NUMBERS),
    )
    # "a" before a vowel sound reads naturally as "an".
    words = s.split(" ")
    for i in range(len(words) - 1):
        if words[i].lower() == "a" and words[i + 1][0].lower() in "aeio":
            words[i] = words[i][0] + "n" if words[i] == "A" else "an"
    return " ".join(words)


def generate_sentences(count: int, seed: int) -> list[str]:
    """`count` distinct sentences, the same for the same seed."""
    rng = np.random.default_rng(seed)
    out, seen = [], set()
    while len(out) < count:
        s = _fill(TEMPLATES[rng.integers(len(TEMPLATES))], rng)
        if s not in seen:
            seen.add(s)
            out.append(s)
    return out
