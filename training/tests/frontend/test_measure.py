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
