"""Two models on the same segments: the paired test that says whether their closures differ by more than chance."""
import json

import numpy as np
import pytest
import torch

from talkingface.train import paired


def test_mcnemar_counts_the_segments_only_one_model_closes_and_gives_the_exact_p():
    a = np.array([1, 1, 1, 0, 0], dtype=bool)
    b = np.array([0, 0, 1, 0, 1], dtype=bool)
    r = paired.mcnemar(a, b)
    assert (r["only_first"], r["only_second"], r["n"]) == (2, 1, 5)
    assert r["p"] == pytest.approx(1.0)                      # 2 against 1 of 3: 2 * P(X <= 1) = 2 * 4/8, capped at 1
    r = paired.mcnemar(np.ones(10, bool), np.zeros(10, bool))
    assert r["p"] == pytest.approx(2 / 2 ** 10)              # all ten discordant one way
    assert paired.mcnemar(a, a)["p"] == 1.0 and paired.mcnemar(a, a)["only_first"] == 0
    with pytest.raises(ValueError, match="different segments"):
        paired.mcnemar(a, b[:4])


def test_d_prime_is_zero_at_chance_and_grows_with_discrimination():
    assert paired.d_prime(0.3, 0.3, 100, 1000) == pytest.approx(0.0)
    assert paired.d_prime(0.858, 0.095, 190, 2427) == pytest.approx(2.38, abs=0.01)
    assert np.isfinite(paired.d_prime(1.0, 0.0, 10, 10))       # kept half a trial from the ends


def test_the_command_compares_a_model_with_itself_and_another(trained_run, corpus, tmp_path):
    first = trained_run / "final.pt"
    out = tmp_path / "same.json"
    assert paired.main(["--corpus", str(corpus.root), str(first), str(first), "--split", "test", "--out", str(out)]) == 0
    same = json.loads(out.read_text())
    for key in ("bilabial_closed", "closed_in_other_speech"):
        assert same[key]["only_first"] == same[key]["only_second"] == 0 and same[key]["p"] == 1.0
        assert same[key]["n"] > 0
    assert same["d_prime"]["first"] == same["d_prime"]["second"]


def test_compare_reads_both_kinds_of_segment():
    first = {"bilabial": np.array([1, 1, 0, 0], bool), "other": np.array([0, 0, 0, 1, 0, 0], bool)}
    second = {"bilabial": np.array([1, 1, 1, 1], bool), "other": np.array([1, 1, 0, 1, 0, 0], bool)}
    r = paired.compare(first, second)
    assert (r["bilabial_closed"]["only_first"], r["bilabial_closed"]["only_second"]) == (0, 2)
    assert (r["closed_in_other_speech"]["only_first"], r["closed_in_other_speech"]["only_second"]) == (0, 2)
    assert r["d_prime"]["second"] > r["d_prime"]["first"]


def test_a_split_without_clips_is_refused(trained_run, corpus):
    first = trained_run / "final.pt"
    with pytest.raises(SystemExit):
        paired.main(["--corpus", str(corpus.root), str(first), str(first), "--split", "nosuch"])
