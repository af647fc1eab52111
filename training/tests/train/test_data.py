"""Training batches: silence crops target each subject's closed rest face, and leave normal batches alone."""
import numpy as np
import pytest
import torch

from talkingface.geometry.contours import contour_gap
from talkingface.model.config import ModelConfig
from talkingface.phones import PHONE_INDEX, SILENCE
from talkingface.train.data import attach_rest_faces, prepare, sample_batch


def test_silence_crops_target_each_subjects_closed_rest_face(corpus):
    clips = [prepare(corpus, k) for k in corpus.keys("train")]
    r = corpus.template.regions
    gaps = attach_rest_faces(clips, corpus.template)
    # One rest face per subject; it is one of that subject's own frames, and the most closed one among
    # its silence frames (so no more open than any silence-labelled frame with open eyes).
    assert len(gaps) == len({c.template.tobytes() for c in clips})
    for c in clips:
        assert any(np.array_equal(c.rest, v) for d in clips if d.template.tobytes() == c.template.tobytes() for v in d.vertices)
    all_gaps = np.concatenate([contour_gap(c.vertices, r["lips_inner_upper"], r["lips_inner_lower"]) for c in clips])
    assert max(gaps.values()) < np.median(all_gaps)
    cfg = ModelConfig()
    rng = np.random.default_rng(0)
    b = sample_batch(clips, rng, 8, 4, cfg, silence=1.0)
    assert torch.all(b.pose == 0)
    assert torch.all(b.vertices == b.vertices[:, :1])           # a still face ...
    quiet = b.mel.abs().max().item()
    assert quiet < 0.05                                          # ... for silence or faint noise
    assert set(b.content_labels.unique().tolist()) <= {-100, PHONE_INDEX[SILENCE]}  # labelled silence
    # And a normal batch is untouched by the option at 0.
    b0 = sample_batch(clips, np.random.default_rng(0), 8, 4, cfg, silence=0.0)
    assert b0.mel.abs().max().item() > 1.0
    with pytest.raises(ValueError, match="attach_rest_faces"):
        for c in clips:
            c.rest = None
        sample_batch(clips, rng, 8, 4, cfg, silence=1.0)
