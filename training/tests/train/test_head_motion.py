"""The head-motion measures tell a still head from one that moves like the truth."""
import numpy as np

from talkingface.train import head_motion as hm


def track(rng, n=150, scale=1.0):
    rot = np.cumsum(rng.standard_normal((n, 3)) * 0.004 * scale, axis=0)
    return np.concatenate([rot, np.zeros((n, 3))], 1)


def test_the_truth_against_itself_and_a_still_head():
    rng = np.random.default_rng(0)
    truth = [track(rng) for _ in range(4)]
    env = [rng.standard_normal(150) for _ in range(4)]
    same = hm.summarise([hm.clip_head_motion(t, t, e) for t, e in zip(truth, env)])
    assert same["spread_ratio"] == 1.0 and same["speed_wasserstein_deg"] == 0.0 and same["follow_pred"] == same["follow_true"]
    still = hm.summarise([hm.clip_head_motion(t, np.zeros_like(t), e) for t, e in zip(truth, env)])
    assert still["spread_ratio"] == 0.0 and still["speed_wasserstein_deg"] > 0.1 and still["follow_pred"] == 0.0
    half = hm.summarise([hm.clip_head_motion(t, 0.5 * t, e) for t, e in zip(truth, env)])
    assert abs(half["spread_ratio"] - 0.5) < 1e-9 and all(abs(v - 0.5) < 1e-9 for v in half["spread_ratio_axes"].values())


def test_draws_average_and_their_range():
    """summarise_draws averages the draws (two draws at half and one and a half times the truth: a ratio of one) and
    says what each draw alone would have reported."""
    rng = np.random.default_rng(1)
    truth = [track(rng) for _ in range(3)]
    env = [rng.standard_normal(150) for _ in range(3)]
    rows = [hm.clip_head_motion(t, s * t, e) | {"draw": k} for k, s in enumerate((0.5, 1.5)) for t, e in zip(truth, env)]
    out = hm.summarise_draws(rows)
    assert abs(out["spread_ratio"] - 1.0) < 1e-9
    assert np.allclose(out["spread_ratio_draws"], [0.5, 1.5])
    assert hm.summarise_draws([]) is None


def test_each_draw_of_each_clip_has_a_seed_of_its_own():
    from talkingface.train.evaluate import draw_seed
    seeds = {draw_seed(0, clip, draw) for clip in range(200) for draw in range(8)}
    assert len(seeds) == 1600 and draw_seed(5, 3, 0) == 8  # the first draw: seed + clip, as before
