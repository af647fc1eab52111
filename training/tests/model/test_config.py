"""The model config: a checkpoint written before a field existed keeps the behaviour it was trained with."""
from talkingface.model.config import LEGACY, ModelConfig
from talkingface.phones import CONTENT_CLASSES


def test_old_checkpoints_keep_their_encoder():
    assert ModelConfig.from_dict({k: v for k, v in ModelConfig().to_dict().items() if k != "content_arch"}).content_arch == LEGACY["content_arch"]


def test_the_content_classes_are_the_phones_and_the_blank():
    assert ModelConfig().content_classes == len(CONTENT_CLASSES) == 41
