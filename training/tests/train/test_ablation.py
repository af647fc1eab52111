"""The ablation driver (Table IV) trains, evaluates and tabulates its rows, one job or several side by side."""
import json

import pytest

from talkingface.train import ablation


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_ablation_driver_writes_the_table(corpus, tmp_path, jobs):
    out = tmp_path / "results"
    ablation.main(["--corpus", str(corpus.root), "--steps", "1", "--rows", "G+MLP", "LG+GAVA", "--runs", str(tmp_path / "runs"),
                   "--out", str(out), "--batch-clips", "2", "--frames", "4", "--jobs", jobs])
    table = json.loads((out / "ablation.json").read_text())
    for row in ("G+MLP", "LG+GAVA"):
        assert set(("E_vl", "E_ve", "FDD", "AFDD")) <= set(table[row])
        assert all(isinstance(table[row][k], float) for k in ("E_vl", "E_ve", "FDD", "AFDD"))
    assert "cannot be judged yet" in (out / "ablation.md").read_text()
