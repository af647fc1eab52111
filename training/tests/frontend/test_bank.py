"""The front-end's speech bank: crops keep their labels aligned, the warp is features.warp_mel's, masks mask, and a
packed bank comes back as it went in, to 8 bits."""
import numpy as np
import pytest
import torch

from talkingface.features import warp_mel
from talkingface.frontend import bank as fb


def toy_clips(rng, lengths=(400, 120, 900)):
    """Clips whose every Mel frame carries its own label in band 0, so a crop's alignment can be read back."""
    out = []
    for n in lengths:
        lab = rng.integers(0, 40, n)
        mel = rng.standard_normal((n, 80)).astype(np.float32)
        mel[:, 0] = lab
        out.append((mel, lab))
    return out


def test_crops_keep_labels_aligned_and_pad_past_the_end():
    rng = np.random.default_rng(0)
    b = fb.Bank.from_clips(toy_clips(rng))
    fb.WARP, warp = (1.0, 1.0), fb.WARP  # no warp, so band 0 is the label itself
    try:
        mel, lab = b.batch(np.random.default_rng(1), 64, stride=2)
    finally:
        fb.WARP = warp
    assert mel.shape == (64, fb.CROP, 80) and lab.shape == (64, fb.CROP // 2)
    real = lab != fb.PAD_LABEL
    assert real.any() and (~real).any()  # the 120-frame clip is shorter than a crop
    np.testing.assert_array_equal(mel[:, ::2, 0][real].numpy(), lab[real].numpy())
    assert mel[:, ::2][~real].abs().max() == 0  # past a clip's end: zeros


def test_the_batch_warp_is_warp_mel_per_crop():
    rng = np.random.default_rng(2)
    mel = rng.standard_normal((3, 50, 80)).astype(np.float32)
    factor = np.array([0.9, 1.0, 1.07], np.float32)
    got = fb.warp(torch.from_numpy(mel), torch.from_numpy(factor)).numpy()
    for i in range(3):
        np.testing.assert_allclose(got[i], warp_mel(mel[i], float(factor[i])), atol=1e-4)  # float32 against float64 positions


def test_spec_augment_masks_spans_of_frames_and_bands():
    x = torch.ones(200, fb.CROP, 80)
    y = fb.spec_augment(x, np.random.default_rng(3))
    zero = y == 0
    frames, bands = zero.all(2), zero.all(1)  # a masked frame is zero in every band, a masked band in every frame
    assert frames.sum(1).max() <= fb.TIME_MASKS * fb.TIME_MASK_MAX and bands.sum(1).max() <= fb.FREQ_MASKS * fb.FREQ_MASK_MAX
    assert frames.any(1).float().mean() > 0.8 and bands.any(1).float().mean() > 0.8
    assert (zero == (frames[:, :, None] | bands[:, None, :])).all()  # nothing else masked


def test_timbre_changes_the_chosen_crops_smoothly_across_bands(monkeypatch):
    rng = np.random.default_rng(7)
    mel = torch.from_numpy(np.abs(rng.normal(1, 1, (64, 50, 80))).astype(np.float32))
    state = np.random.default_rng(8)
    assert fb.timbre(mel, state, 0.0) is mel
    assert state.random() == np.random.default_rng(8).random()  # off draws nothing: other runs keep their stream
    out = fb.timbre(mel, np.random.default_rng(9), 0.5)
    changed = (out != mel).flatten(1).any(1)
    assert 20 <= int(changed.sum()) <= 44  # about half the crops, the rest untouched
    assert (out >= 0).all() and torch.isfinite(out).all()  # still log(energy + 1)
    # Across bands the changed crops are smoother (the lifter).
    rough = lambda x: (x[..., 1:] - x[..., :-1]).abs().mean((1, 2))
    assert (rough(out[changed]) < rough(mel[changed])).all()
    # The gain: on a spectrum smooth across bands (which the lifter leaves nearly as it is) the band means move, and
    # without the gain (TIMBRE_GAIN 0) they move far less.
    smooth = torch.from_numpy(np.tile(np.linspace(3, 1, 80, dtype=np.float32), (16, 20, 1)))
    moved = lambda x: (x - smooth).mean(1).abs().amax(1)
    with_gain = fb.timbre(smooth, np.random.default_rng(10), 1.0)
    monkeypatch.setattr(fb, "TIMBRE_GAIN", 0.0)
    without = fb.timbre(smooth, np.random.default_rng(10), 1.0)
    assert (moved(with_gain) > 0.1).float().mean() > 0.8 and (moved(without) < 0.05).all()


def test_pack_round_trip(tmp_path):
    rng = np.random.default_rng(4)
    train, val = toy_clips(rng), toy_clips(rng, (30, 40))
    counts = fb.pack(tmp_path / "new" / "b.npz", train, {"val": val, "test": val[:1]})  # its folder made for it
    assert counts == {"train": 3, "val": 2, "test": 1}
    back = fb.unpack(tmp_path / "new" / "b.npz")
    lo, hi = np.percentile(np.concatenate([m for m, _ in train]), 0.01), max(m.max() for m, _ in train)
    for name, clips in (("train", train), ("val", val)):
        assert len(back[name]) == len(clips)
        for (m, l), (m2, l2) in zip(clips, back[name]):
            np.testing.assert_array_equal(l2, l)
            np.testing.assert_allclose(m2, np.clip(m, lo, hi), atol=(hi - lo) / 255 / 2 + 1e-5)


@pytest.mark.skipif(not torch.cuda.is_available(), reason="no CUDA device here")
def test_a_gpu_batch_is_the_cpu_batch():
    clips = toy_clips(np.random.default_rng(5))
    cpu, gpu = (fb.Bank.from_clips(clips, d).batch(np.random.default_rng(6), 8, 2) for d in ("cpu", "cuda"))
    for a, b in zip(cpu, gpu):
        torch.testing.assert_close(b.cpu(), a)
