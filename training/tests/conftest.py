import pytest

from talkingface import export
from talkingface.corpus.build import build_corpus
from talkingface.corpus.plan import PRESETS
from talkingface.data.datasets import open_dataset
from talkingface.paths import MODELS_DIR, TEMPLATE_DIR
from talkingface.template import load_template
from talkingface.train import train


@pytest.fixture(scope="session")
def corpus(tmp_path_factory):
    """The small preset corpus, built once per test session (a few seconds)."""
    out = tmp_path_factory.mktemp("corpus") / "small"
    build_corpus(out, PRESETS["small"], workers=2)
    return open_dataset(out)


@pytest.fixture(scope="session")
def template():
    """The shipped face template."""
    return load_template(TEMPLATE_DIR / "template.json")


@pytest.fixture(scope="session")
def trained_run(corpus, tmp_path_factory):
    """A run folder whose final.pt is the default model trained two steps on the small corpus."""
    run = tmp_path_factory.mktemp("run")
    train.main(["--corpus", str(corpus.root), "--out", str(run), "--steps", "2", "--batch-clips", "2", "--frames", "4"])
    return run


@pytest.fixture(scope="session")
def reexported(tmp_path_factory):
    """The shipped checkpoint exported afresh by this machine's exporter."""
    out = tmp_path_factory.mktemp("reexport")
    export.export(MODELS_DIR / "checkpoint.pt", out)
    return out
