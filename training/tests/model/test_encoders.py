"""The content encoder: the dilated one reads half a second back and no further ahead than the first one."""
import torch

from talkingface.model.config import ModelConfig
from talkingface.model.encoders import ContentEncoder


def test_the_dilated_encoder_looks_back_not_ahead():
    enc = ContentEncoder(ModelConfig(), 80).eval()
    mel = torch.randn(1, 300, 80)
    with torch.no_grad():
        base = enc(mel)
        moved = mel.clone()
        moved[0, 150] += 1.0
        changed = torch.nonzero((enc(moved) - base).abs().amax(-1)[0] > 0).flatten()
    assert 150 - int(changed[0]) * 2 <= 7          # 70 ms look-ahead, as the first encoder
    assert int(changed[-1]) * 2 - 150 >= 50         # and half a second of context behind
