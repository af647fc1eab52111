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
