"""The looped-sample check of the e2e live-closure bound counts every pass but the first, on the template's face."""
import json

import numpy as np
import pytest

from talkingface.train import looped, train


def test_counts_the_passes_after_the_first(corpus, trained_run):
    model, ck = train.load_checkpoint(trained_run / "final.pt", corpus.template)
    model.eval()
    audio = (0.1 * np.random.default_rng(0).standard_normal(16000)).astype(np.float32)
    phones = [("SIL", 0.0, 0.2), ("M", 0.2, 0.3), ("AA", 0.3, 0.6), ("B", 0.6, 0.7), ("SIL", 0.7, 1.0)]
    for loops, phase in ((2, 0.0), (4, 0.02)):
        c = looped.looped_counts(model, corpus.template, None, 1.0, audio, 16000, phones, loops, phase)
        assert c["bilabial"] == 2 * (loops - 1) and c["other"] == loops - 1
        assert 0 <= c["bilabial_closed"] <= c["bilabial"] and 0 <= c["other_closed"] <= c["other"]


def test_an_unknown_clip_is_named_with_the_ones_there(tmp_path, capsys):
    (tmp_path / "index.json").write_text(json.dumps({"clips": [{"name": "a"}, {"name": "b"}]}))
    with pytest.raises(SystemExit):
        looped.main(["--samples", str(tmp_path), "--clip", "c"])
    assert "it has a, b" in capsys.readouterr().err
