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
