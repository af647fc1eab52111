"""What the corpus holds before any of it is made: subjects, and per clip its split, seed, words and voice.

plan() draws everything from the corpus seed in a fixed order, so the same config gives the same plan
whatever the machine, and a clip's own generator is seeded by (corpus seed, clip key).
"""
from __future__ import annotations

import hashlib
from dataclasses import asdict, dataclass, field

import numpy as np

from .. import constants
from . import recorded
from .identity import Subject, sample_subject
from .sentences import generate_sentences
from .speech import SpeechToolError, Voice, all_voices


@dataclass(frozen=True)
class CorpusConfig:
    preset: str
    subjects: tuple[int, int, int]   # train, val, test
    sentences_per_subject: int
    sentence_pool: tuple[int, int, int]  # distinct sentences per split
    human_fraction: float = 0.15     # share of clips spoken by the recorded human voice
    clean_fraction: float = 0.25     # share of clips left without augmentation
    seed: int = 0
    sample_rate: int = constants.SAMPLE_RATE
    fps: int = constants.FPS


PRESETS = {
    "full": CorpusConfig("full", (12, 2, 2), 40, (200, 30, 30)),
    "small": CorpusConfig("small", (2, 1, 1), 3, (6, 3, 3), human_fraction=0.25),
}


def is_test_voice(v: Voice) -> bool:
    """Voices that training never hears: a festival voice, a flite voice, a whole espeak accent and two variants."""
    if v.id in ("festival:ked", "flite:awb"):
        return True
    if v.engine == "espeak":
        accent, variant = v.name.split("+")
        return accent == "en-gb-scotland" or variant in ("klatt3", "f5")
    return False


def split_of_recording(name: str) -> str:
    """Recorded prompts split by a stable hash of their name: 15% test, 10% val."""
    h = int(hashlib.sha1(name.encode()).hexdigest()[:8], 16) % 100
    return "test" if h < 15 else "val" if h < 25 else "train"


@dataclass
class ClipSpec:
    key: str
    subject: int
    split: str
    seed: int
    text: str = ""
    voice: dict | None = None        # Voice fields for TTS clips
    recording: str | None = None     # asterisk prompt name for human clips
    fallback_voices: list = field(default_factory=list)
    augment: bool = True


def plan(cfg: CorpusConfig) -> tuple[list[Subject], list[ClipSpec]]:
    rng = np.random.default_rng(cfg.seed)
    n_train, n_val, n_test = cfg.subjects
    subjects = [sample_subject(f"Synth{i + 1:02d}", rng) for i in range(n_train + n_val + n_test)]
    split_of_subject = ["train"] * n_train + ["val"] * n_val + ["test"] * n_test
    pools = generate_sentences(sum(cfg.sentence_pool), cfg.seed + 1)
    a, b, _ = cfg.sentence_pool
    sentences = {"train": pools[:a], "val": pools[a : a + b], "test": pools[a + b :]}
    voices = all_voices()
    voice_pool = {"train": [v for v in voices if not is_test_voice(v)], "test": [v for v in voices if is_test_voice(v)]}
    voice_pool["val"] = voice_pool["train"]
    human = {"train": [], "val": [], "test": []}
    if cfg.human_fraction > 0:
        # A corpus that silently lacked its recorded speech would be another corpus (issue 12: a fresh machine
        # missed the transcripts package, and every later clip drew other voices and tempos).
        if not recorded.available():
            raise SpeechToolError(f"recorded speech missing: {recorded.MISSING_HINT}")
        for r in recorded.recordings():
            human[split_of_recording(r.name)].append(r)
    cursors = {k: 0 for k in sentences}
    specs = []
    for s_idx, subject in enumerate(subjects):
        split = split_of_subject[s_idx]
        order = rng.permutation(len(sentences[split]))
        for k in range(cfg.sentences_per_subject):
            key = f"{subject.name}_sentence{k + 1:02d}"
            seed = int.from_bytes(hashlib.sha256(f"{cfg.seed}:{key}".encode()).digest()[:4], "little")
            spec = ClipSpec(key, s_idx, split, seed, augment=rng.random() >= cfg.clean_fraction)
            pool = voice_pool[split]
            # Voice-engine balance: each engine family gets its share, whatever the pool sizes.
            engines = sorted({v.engine for v in pool})
            engine = engines[rng.integers(len(engines))]
            family = [v for v in pool if v.engine == engine]
            chosen = family[rng.integers(len(family))]
            spec.voice = asdict(chosen)
            # If alignment fails (espeak voices, now and then): three other pool voices, then one whose
            # synthesiser gives the timings itself, so every clip ends up with speech.
            others = [pool[i] for i in rng.permutation(len(pool))[:3]]
            timed = [v for v in pool if v.timing == "synthesiser"]
            spec.fallback_voices = [asdict(v) for v in others + [timed[rng.integers(len(timed))]]]
            # Drawn for every clip, so the draws of later clips never depend on which recordings exist.
            wants_human = rng.random() < cfg.human_fraction
            if human[split] and wants_human:
                spec.recording = human[split][cursors.setdefault("h" + split, 0) % len(human[split])].name
                cursors["h" + split] += 1
            else:
                spec.text = sentences[split][order[k % len(order)]]
            cursors[split] += 1
            specs.append(spec)
    return subjects, specs
