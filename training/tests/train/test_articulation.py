"""The articulation measures tell a mouth that times its closures from an average one and from one that flaps."""
import numpy as np

from talkingface.phones import PHONES
from talkingface.train import articulation as art

FPS = 30
# A 6 s utterance: pause, then vowels and consonants with a bilabial every 0.6 s.
PHONES_SEQ = [("SIL", 0.0, 0.3)]
t = 0.3
while t < 5.7:
    PHONES_SEQ += [(p, round(t + a, 4), round(t + b, 4)) for p, a, b in
                   [("AA", 0, 0.2), ("M", 0.2, 0.3), ("IY", 0.3, 0.45), ("T", 0.45, 0.6)]]  # 4 decimals, as alignments
    t = round(t + 0.6, 4)
N = int(6.0 * FPS)


def gap_track(closed_on) -> np.ndarray:
    g = np.full(N, 8.0)
    for p, a, b in PHONES_SEQ:
        if closed_on(p, a, b):
            g[art.segment_frames(a, b, FPS, N)] = 0.0
    return g


def test_timed_closures_score_and_beat_chance():
    c = art.clip_articulation(gap_track(lambda p, a, b: p == "M"), gap_track(lambda p, a, b: p == "M"), PHONES_SEQ, FPS)
    s = art.summarise([c])
    assert s["pred_closure"] == 1.0 and s["pred_false_closure"] == 0.0 and s["pred_open_vowel_opened"] == 1.0
    assert s["chance_closure"] < 0.5 and s["gap_corr"] > 0.99


def test_an_average_mouth_never_closes():
    truth = gap_track(lambda p, a, b: p == "M")
    s = art.summarise([art.clip_articulation(truth, np.full(N, truth.mean()), PHONES_SEQ, FPS)])
    assert s["pred_closure"] == 0.0 and s["gap_corr"] == 0.0 and s["gap_std_ratio"] < 1e-9


def test_a_flapping_mouth_shows_its_false_alarms():
    truth = gap_track(lambda p, a, b: p == "M")
    flap = np.where(np.arange(N) % 4 < 2, 0.0, 8.0)  # closes every 133 ms, whatever is said
    s = art.summarise([art.clip_articulation(truth, flap, PHONES_SEQ, FPS)])
    assert s["pred_closure"] == 1.0
    assert s["pred_false_closure"] > 0.8 and s["chance_closure"] > 0.8  # it scores no better than chance


def test_content_confusion_and_bilabials_heard():
    labels = np.array([PHONES.index(p) for p in ["SIL", "P", "P", "AA", "AA", "M", "M", "T", "B"]])
    called = ["SIL", "T", "P", "AA", "AH", "K", "K", "T", "SIL"]
    logits = np.full((len(labels), len(PHONES) + 1), -5.0)
    logits[np.arange(len(labels)), [PHONES.index(p) for p in called]] = 5.0
    conf = art.content_counts(logits, labels, len(PHONES) + 1)
    s = art.content_summary(conf, art.bilabial_heard(logits, labels))
    assert s["frame_accuracy"] == 4 / 9
    assert s["bilabial_segments"] == 3 and s["bilabial_segments_heard"] == 1 / 3  # P heard once; M and B missed
    assert s["recall"]["M"]["recall"] == 0.0 and s["recall"]["M"]["mistaken_for"] == ["K"]


def test_the_content_encoder_per_voice():
    """espeak-ng's variants count with their accent; each voice's rows add its clips' frames and segments."""
    assert art.voice_family("espeak:en-gb-scotland+m5") == art.voice_family("espeak:en-gb-scotland+klatt3") == "espeak:en-gb-scotland"
    assert art.voice_family("festival:ked") == "festival:ked" and art.voice_family("") == "unknown"
    D = len(PHONES) + 1
    good, bad = np.zeros((D, D), np.int64), np.zeros((D, D), np.int64)
    good[3, 3], good[4, 4] = 8, 2            # 10 frames, all right
    bad[3, 3], bad[3, 5] = 1, 29             # 30 frames, 1 right
    rows = art.voice_rows({"festival:ked": [2, good, 3, 4], "flite:awb": [1, bad, 0, 2]})
    assert [r["voice"] for r in rows] == ["flite:awb", "festival:ked"]  # the most frames first
    assert rows[0]["frames"] == 30 and abs(rows[0]["frame_accuracy"] - 1 / 30) < 1e-12 and rows[1]["frame_accuracy"] == 1.0
    assert rows[1]["clips"] == 2 and (rows[1]["bilabial_segments_heard"], rows[1]["bilabial_segments"]) == (3, 4)
    md = "\n".join(art.voice_markdown(rows))
    assert "| flite:awb | 1 | 30 | 3.3% | 0 of 2 |" in md


def test_each_hit_rate_has_its_false_alarms_and_an_empty_count_is_none():
    # a mouth held open opens every open vowel and every /p b m/; the timed one opens none of them
    held = art.summarise([art.clip_articulation(gap_track(lambda p, a, b: p == "M"), np.full(N, 8.0), PHONES_SEQ, FPS)])
    assert held["pred_open_vowel_opened"] == 1.0 and held["pred_bilabial_opened"] == 1.0 and held["true_bilabial_opened"] == 0.0
    timed = art.summarise([art.clip_articulation(gap_track(lambda p, a, b: p == "M"), gap_track(lambda p, a, b: p == "M"), PHONES_SEQ, FPS)])
    assert timed["pred_bilabial_opened"] == 0.0
    # a clip without /p b m/ or open vowels: rates of nothing are None, not 0%
    none = art.summarise([art.clip_articulation(np.full(N, 8.0), np.full(N, 8.0), [("SIL", 0.0, 1.0), ("T", 1.0, 1.2)], FPS)])
    assert none["pred_closure"] is None and none["chance_closure"] is None and none["pred_open_vowel_opened"] is None
    assert none["pred_false_closure"] == 0.0


def test_a_front_end_calling_p_everywhere_hears_every_bilabial_and_every_other_segment():
    labels = np.array([PHONES.index(p) for p in ["SIL", "AA", "AA", "P", "P", "IY", "M", "T", "T", "SIL"]])
    one_hot = lambda calls: np.eye(len(PHONES))[[PHONES.index(p) for p in calls]]
    everywhere = one_hot(["P"] * len(labels))
    assert art.bilabial_heard(everywhere, labels) == (2, 2)
    assert art.bilabial_heard(everywhere, labels, others=True) == (3, 3)   # AA, IY, T: silence left out
    right = one_hot(["SIL", "AA", "AA", "P", "P", "IY", "M", "T", "T", "SIL"])
    assert art.bilabial_heard(right, labels) == (2, 2) and art.bilabial_heard(right, labels, others=True) == (0, 3)
    tally = art.ContentTally(len(PHONES))
    tally.add(everywhere, labels)
    s = tally.summary()
    assert s["bilabial_segments_heard"] == 1.0 and s["bilabial_false_calls"] == 1.0 and s["other_segments"] == 3


def test_the_chance_level_never_counts_the_true_alignment():
    # two frames: the 0.5 shift moves by one, the 0.25 and 0.75 shifts would land on 0 or 2 = the alignment itself
    phones = [("M", 0.0, 1 / FPS), ("AA", 1 / FPS, 2 / FPS)]
    c = art.chance_counts(np.array([0.0, 8.0]), phones, FPS)
    assert c == {"bilabial_closed": 0, "bilabial": 1}   # only the 0.5 shift: the closure moved off the M
    assert art.chance_counts(np.array([0.0]), [("M", 0.0, 1 / FPS)], FPS) == {"bilabial_closed": 0, "bilabial": 0}
