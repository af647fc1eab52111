"""The head's own motion (model/head_motion.py): the speech read-out finds what the speech carries, the process
the rest, the gain the truth's spread; a seed draws the same motion; an earlier checkpoint's dict still loads."""
import pytest
import numpy as np

from talkingface.model import head_motion as hmod


def clips(rng, n=40, frames=120, d=6):
    """Features f (a smooth random signal), and a truth of 2 deg x f[:, 0] on pitch plus slow AR noise on every axis."""
    feats, truth = [], []
    for _ in range(n):
        f = np.cumsum(rng.standard_normal((frames, d)), 0) * 0.2
        f -= f.mean(0)
        noise = np.zeros((frames, 3))
        for t in range(2, frames):
            noise[t] = 1.7 * noise[t - 1] - 0.72 * noise[t - 2] + 0.05 * rng.standard_normal(3)
        speech = np.zeros((frames, 3))
        speech[:, 0] = 2.0 * f[:, 0]
        feats.append(f)
        truth.append(speech + noise)
    return feats, truth


def test_the_read_out_recovers_what_the_speech_carries_and_the_spread_is_the_truths():
    rng = np.random.default_rng(0)
    feats, truth = clips(rng)
    head = hmod.fit(truth, feats, np.zeros(3), ridge=1e-6)
    assert abs(head.speech_w[0, 0] - 2.0) < 0.1                                  # pitch follows f[:, 0]
    assert np.abs(head.speech_w[0, 1:]).max() < 0.1 and np.abs(head.speech_w[1:]).max() < 0.1
    want = np.mean([r.std(0) for r in truth], 0)
    got = np.mean([head.sample(f, 500 + i).std(0) for i, f in enumerate(feats)], 0)
    assert np.all(np.abs(got / want - 1) < 0.1), (got, want)
    # The read-out's part of the motion is the speech's: its correlation with the truth's pitch is high.
    part = np.concatenate([head.speech(f)[:, 0] for f in feats])
    assert np.corrcoef(part, np.concatenate([r[:, 0] for r in truth]))[0, 1] > 0.8


def test_without_the_read_out_the_process_carries_all_of_it():
    rng = np.random.default_rng(1)
    feats, truth = clips(rng, n=20)
    head = hmod.fit(truth, feats, np.zeros(3), ridge=None)
    assert not head.speech_w.any() and not head.speech_b.any()
    assert np.array_equal(head.sample(feats[0], 3), head.process(feats[0], 3))


def test_a_seed_draws_the_same_motion_and_an_earlier_dict_loads():
    rng = np.random.default_rng(2)
    feats, truth = clips(rng, n=10)
    head = hmod.fit(truth, feats, np.zeros(3))
    assert np.array_equal(head.sample(feats[0], 4), head.sample(feats[0], 4))
    assert np.abs(head.sample(feats[0], 4) - head.sample(feats[0], 5)).max() > 1e-3
    again = hmod.HeadMotion.from_dict(head.to_dict())
    assert np.allclose(again.sample(feats[1], 4), head.sample(feats[1], 4), atol=1e-4)
    earlier = {k: v for k, v in head.to_dict().items() if not k.startswith("speech_")}
    old = hmod.HeadMotion.from_dict(earlier)
    assert not old.speech_w.any() and np.array_equal(old.sample(feats[0], 4), old.process(feats[0], 4))


def test_the_gain_makes_the_typical_speaker_in_ratio_terms():
    """Two speakers, one moving four times as much as the other: calibrated per speaker, the model moves like their
    geometric mean (twice the calm one, half the lively one); over all clips, like their arithmetic mean."""
    rng = np.random.default_rng(3)
    feats, truth = clips(rng, n=30)
    truth = [r * (4.0 if i % 2 else 1.0) for i, r in enumerate(truth)]
    speakers = ["lively" if i % 2 else "calm" for i in range(len(truth))]
    head = hmod.fit(truth, feats, np.zeros(3), ridge=None, speakers=speakers)
    pred = [head.sample(f, 900 + i) for i, f in enumerate(feats)]
    calm = [np.linalg.norm(x.std(0)) for x, s in zip(pred, speakers) if s == "calm"]
    calm_true = [np.linalg.norm(x.std(0)) for x, s in zip(truth, speakers) if s == "calm"]
    assert abs(np.mean(calm) / np.mean(calm_true) - 2.0) < 0.3
    pooled = hmod.fit(truth, feats, np.zeros(3), ridge=None)
    calm_pooled = [np.linalg.norm(pooled.sample(f, 900 + i).std(0)) for i, (f, s) in enumerate(zip(feats, speakers)) if s == "calm"]
    assert abs(np.mean(calm_pooled) / np.mean(calm_true) - 2.5) < 0.35


def test_motion_stats_measures_spread_speed_and_jitter():
    # A sine of amplitude 1 deg on one axis: spread 1/sqrt(2), speed the mean |derivative| per frame, jitter the
    # mean |second difference|; scaling the track scales every measure.
    t = np.arange(2000)
    w = 2 * np.pi / 100
    x = np.zeros((len(t), 3))
    x[:, 0] = np.sin(w * t)
    st = hmod.motion_stats([x])
    assert abs(st["spread"] - 1 / np.sqrt(2)) < 1e-3
    assert abs(st["speed"] - 2 / np.pi * w) < 1e-3
    assert abs(st["jitter"] - 2 / np.pi * w * w) < 1e-4
    st2 = hmod.motion_stats([3 * x])
    assert all(abs(st2[k] - 3 * st[k]) < 1e-9 for k in st)


def test_a_fit_that_would_not_settle_is_refused():
    from talkingface.model.head_motion import fit_ar2
    rng = np.random.default_rng(0)
    growing = np.cumprod(np.full((200, 3), 1.02), 0) + rng.normal(0, 0.01, (200, 3))  # grows 2% a frame
    with pytest.raises(ValueError, match="does not settle"):
        fit_ar2([growing])
    ar, _ = fit_ar2([rng.normal(0, 1, (200, 3))])  # noise settles
    assert np.abs(ar).max() < 0.5
