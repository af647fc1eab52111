"""Blinks: their rate, length and share of partial ones follow the speaking style."""
import numpy as np

from talkingface.corpus.coarticulation import SpeakingStyle, blink_track, sample_blinks


def test_blink_rate_matches_the_style():
    style = SpeakingStyle(blink_interval=(2.0, 6.0))
    blinks = sample_blinks(600.0, np.random.default_rng(1), style)
    intervals = np.diff([b.start for b in blinks])
    assert 2.0 <= intervals.min() and intervals.max() <= 6.0
    assert 3.5 < intervals.mean() < 4.5  # uniform on [2, 6]
    assert 0.1 <= min(b.duration for b in blinks) and max(b.duration for b in blinks) <= 0.15
    partial = np.mean([b.amount < 1 for b in blinks])
    assert 0.1 < partial < 0.3
    track = blink_track(blinks[:3], int(30 * blinks[2].start + 30), 30)
    assert np.sum(np.diff((track > 0.5).astype(int)) == 1) == 3
