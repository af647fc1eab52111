import pytest
import torch

from talkingface.model.config import ModelConfig
from talkingface.model.gava import TalkingFace


@pytest.fixture
def make(template):
    """A model on the shipped template, seeded, in eval mode: make(decoder="SA") and the like."""
    def build(**kw) -> TalkingFace:
        torch.manual_seed(0)
        return TalkingFace(ModelConfig(**kw), template).eval()
    return build
