"""Front-ends measured by themselves give the face evaluation's content-encoder figures, per voice too."""
import json

from talkingface.frontend import measure
from talkingface.train import evaluate, train


def test_measure_matches_the_evaluation_and_counts_every_voice(corpus, trained_run, tmp_path, capsys):
    ck = trained_run / "final.pt"
    out = tmp_path / "fe.json"
    assert measure.main([str(ck), "--corpus", str(corpus.root), "--split", "test", "--out", str(out)]) == 0
    r = json.loads(out.read_text())[str(ck)]["test"]
    model, _ = train.load_checkpoint(ck, corpus.template)
    ce = evaluate.evaluate(model, corpus, "test")["content_encoder"]
    assert abs(r["frame_accuracy"] - ce["all"]["frame_accuracy"]) < 1e-9
    assert r["bilabial_segments"] == ce["all"]["bilabial_segments"]
    assert r["by_voice"] == ce["by_voice"]
    assert sum(v["clips"] for v in r["by_voice"]) == len(corpus.keys("test"))
    assert "per voice" in capsys.readouterr().out


def test_warps_average_the_log_posteriors_of_warped_mels(trained_run):
    import numpy as np
    import pytest
    import torch
    from talkingface.features import warp_mel
    enc, _ = measure.load_encoder(str(trained_run / "final.pt"))
    mel = np.random.default_rng(0).standard_normal((90, 80)).astype(np.float32) + 4
    with torch.no_grad():
        assert torch.equal(measure.heard(enc, mel), enc(torch.from_numpy(mel)[None])[0])
        lp = [enc(torch.from_numpy(warp_mel(mel, w).astype(np.float32))[None])[0].log_softmax(-1) for w in (0.9, 1.1)]
        torch.testing.assert_close(measure.heard(enc, mel, (0.9, 1.1)), (lp[0] + lp[1]) / 2)
    with pytest.raises(SystemExit):
        measure.main([str(trained_run / "final.pt"), "--corpus", "x", "--warps", "1,three"])


def test_a_chosen_warp_is_the_most_certain_or_the_best_scoring_one(trained_run):
    import numpy as np
    import pytest
    import torch
    from talkingface.features import warp_mel
    enc, _ = measure.load_encoder(str(trained_run / "final.pt"))
    mel = np.random.default_rng(1).standard_normal((90, 80)).astype(np.float32) + 4
    warps = (0.9, 1.0, 1.1)
    with torch.no_grad():
        lps = [enc(torch.from_numpy(warp_mel(mel, w).astype(np.float32))[None])[0].log_softmax(-1) for w in warps]
    certainty = [float((lp.exp() * lp).sum(-1).mean()) for lp in lps]
    lp, w = measure.heard_at_chosen_warp(enc, mel, warps, "entropy", np.zeros(len(lps[0]), np.int64))
    assert w == warps[int(np.argmax(certainty))] and torch.equal(lp, lps[warps.index(w)])
    # oracle: labels that are what the 1.1 warp hears make it the best
    labels = lps[2].argmax(-1).numpy()
    assert measure.heard_at_chosen_warp(enc, mel, warps, "oracle", labels)[1] == 1.1
    with pytest.raises(ValueError, match="entropy"):
        measure.heard_at_chosen_warp(enc, mel, warps, "loudest", labels)
    with pytest.raises(SystemExit):
        measure.main([str(trained_run / "final.pt"), "--corpus", "x", "--choose-warp", "entropy"])  # one warp only


def test_accuracy_by_kind_reads_the_confusion():
    import numpy as np
    from talkingface.phones import PHONE_INDEX, PHONES
    from talkingface.train.articulation import accuracy_by_kind
    conf = np.zeros((len(PHONES) + 1, len(PHONES) + 1), np.int64)
    P, B, T, AA, AE, IY, SIL = (PHONE_INDEX[p] for p in ("P", "B", "T", "AA", "AE", "IY", "SIL"))
    conf[P, P] = 3   # right
    conf[P, B] = 1   # wrong phone, same lip group (closed)
    conf[T, P] = 2   # wrong group
    conf[T, T] = 2
    conf[AA, AE] = 4  # wrong vowel, same group (open)
    conf[IY, IY] = 4
    conf[AA, len(PHONES)] = 2  # the blank: no group
    conf[SIL, SIL] = 100  # silence counts in neither
    r = accuracy_by_kind(conf)
    assert r["consonant_frame_accuracy"] == 5 / 8
    assert r["vowel_frame_accuracy"] == 4 / 10
    assert r["lip_group_accuracy"] == (3 + 1 + 2 + 4 + 4) / 18


def test_an_ensemble_averages_its_members_log_posteriors(trained_run, tmp_path):
    import numpy as np
    import torch
    ck = trained_run / "final.pt"
    ens, cfg = measure.load_encoder(f"{ck}+{ck}")
    assert isinstance(ens, measure.Ensemble) and len(ens.members) == 2
    enc, _ = measure.load_encoder(str(ck))
    # the second member perturbed, so the mean is not either member's
    with torch.no_grad():
        for p in ens.members[1].parameters():
            p.add_(0.01 * torch.randn_like(p))
    mel = np.random.default_rng(2).standard_normal((90, 80)).astype(np.float32) + 4
    with torch.no_grad():
        lp = [m(torch.from_numpy(mel)[None])[0].log_softmax(-1) for m in ens.members]
        torch.testing.assert_close(measure.heard(ens, mel), (lp[0] + lp[1]) / 2)
        torch.testing.assert_close(lp[0], enc(torch.from_numpy(mel)[None])[0].log_softmax(-1))
    assert cfg.content_classes == lp[0].shape[-1]
