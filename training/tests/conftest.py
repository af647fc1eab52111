import pytest

from talkingface.corpus.build import PRESETS, build_corpus
from talkingface.data.datasets import open_dataset


@pytest.fixture(scope="session")
def corpus(tmp_path_factory):
    """The small preset corpus, built once per test session (a few seconds)."""
    out = tmp_path_factory.mktemp("corpus") / "small"
    build_corpus(out, PRESETS["small"], workers=2)
    return open_dataset(out)
