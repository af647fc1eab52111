"""Evaluation of a trained model on the small corpus's test split: the paper's metrics for every clip."""
from talkingface.train import evaluate, train


def test_evaluate_reports_the_paper_metrics(corpus, trained_run):
    model, _ = train.load_checkpoint(trained_run / "final.pt", corpus.template)
    res = evaluate.evaluate(model, corpus, "test")
    for key in ("E_vl", "E_ve", "FDD", "AFDD", "pose_error_deg", "pose_jitter_deg"):
        assert key in res["all"]
    assert res["all"]["clips"] == len(corpus.keys("test"))
