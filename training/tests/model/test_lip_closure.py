"""The lip closure (model/lip_closure.py): a model's full closure shuts any face's lips; openings are left alone."""
import numpy as np

from talkingface.corpus.identity import apply_identity, sample_subject
from talkingface.corpus.rig import Rig
from talkingface.corpus.visemes import P, PARAMS
from talkingface.geometry.contours import lip_gap
from talkingface.model.lip_closure import LipClosure, interpolation_matrix


def _offsets(rig: Rig, **params) -> np.ndarray:
    p = np.zeros((1, len(PARAMS)))
    for k, v in params.items():
        p[0, P[k]] = v
    return rig.deform(p, np.zeros(1), np.zeros(1)) - rig.rest[None]


def _reference(template):
    """The template's own face (mm), its lip gap, its rig, and its full closure and jaw opening: a model trained on it."""
    face = template.vertices * template.to_millimetres()
    rig = Rig(template, face)
    return face, float(lip_gap(face[None], template)[0]), rig, _offsets(rig, close=1.0), _offsets(rig, jaw=1.0)


def test_interpolation_matrix_is_np_interp():
    xs = np.array([-2.0, -0.5, 0.0, 1.5])
    x = np.array([-3.0, -2.0, -1.0, 0.7, 1.5, 4.0])
    ys = np.array([1.0, -2.0, 0.5, 3.0])
    assert np.allclose(interpolation_matrix(x, xs) @ ys, np.interp(x, xs, ys))


def test_a_full_closure_shuts_any_face_and_an_opening_is_the_models(template):
    mm = template.to_millimetres()
    # The reference face's own closure and jaw opening stand in for a model trained on it.
    _, ref_gap, _, closing, opening = _reference(template)
    rng = np.random.default_rng(3)
    faces = [apply_identity(template, sample_subject(f"S{i}", rng).identity) * mm for i in range(6)]
    gaps = [float(lip_gap(f[None], template)[0]) for f in faces]
    assert max(gaps) - min(gaps) > 0.8  # the faces part their lips by different amounts
    for face, g in zip(faces, gaps):
        lc = LipClosure(template, face, ref_gap)
        raw = lip_gap(face[None] + closing, template)[0]
        shut = lip_gap(face[None] + lc.apply(closing), template)[0]
        if abs(g - ref_gap) > 0.3:  # as the model closes: pressed through on a smaller gap, apart on a larger one
            assert np.sign(raw) == np.sign(g - ref_gap) and abs(raw) > 0.1
        assert abs(shut) < 0.1
        assert np.allclose(lc.apply(opening), opening)
    # Half a closure closes half of each face's own gap.
    lc = LipClosure(template, faces[int(np.argmax(gaps))], ref_gap)
    half = lip_gap(faces[int(np.argmax(gaps))][None] + lc.apply(0.5 * closing), template)[0]
    assert abs(half - 0.5 * max(gaps)) < 0.15


def test_the_torch_version_is_the_same_and_passes_gradients(template):
    import torch
    from talkingface.model.lip_closure import LipClosureTorch
    mm = template.to_millimetres()
    face = apply_identity(template, sample_subject("T", np.random.default_rng(5)).identity) * mm
    lc = LipClosure(template, face, 5.0)
    closing = _offsets(Rig(template, face), close=0.8)
    o = np.concatenate([closing, np.random.default_rng(0).normal(0, 1.5, (3, template.num_vertices, 3))]).astype(np.float32)
    t = torch.from_numpy(o).requires_grad_(True)
    out = LipClosureTorch(lc).apply(t)
    assert np.abs(out.detach().numpy() - lc.apply(o)).max() < 1e-4
    assert np.abs(out.detach().numpy() - o).max() > 0.1
    out[..., 1].sum().backward()
    assert torch.isfinite(t.grad).all() and t.grad.abs().sum() > 0


def test_the_mouth_gain_scales_the_mouth_alone_and_a_full_closure_still_shuts(template):
    import torch
    from talkingface.model.lip_closure import LipClosureTorch
    face, ref_gap, rig, closing, opening = _reference(template)
    plain, louder = LipClosure(template, face, ref_gap), LipClosure(template, face, 1.3 * ref_gap, mouth_gain=1.3)
    out = louder.apply(opening)
    mouth = np.clip(np.maximum(rig.w_jaw, rig.w_lips), 0, 1)
    # An opening is the model's, 1.3 times on the lips and the jaw, as it was where neither field reaches.
    lips = rig.w_lips > 0.99
    assert np.allclose(out[:, lips], 1.3 * opening[:, lips], atol=1e-9)
    assert np.allclose(out[:, mouth == 0], opening[:, mouth == 0])
    assert lip_gap(face[None] + out, template)[0] > lip_gap(face[None] + plain.apply(opening), template)[0] + 0.5
    # The reference calibrated for the gain (1.3 times the closing motion) shuts the lips as before.
    assert abs(lip_gap(face[None] + louder.apply(closing), template)[0]) < 0.1
    # The torch version scales the same.
    o = np.concatenate([opening, closing]).astype(np.float32)
    assert np.abs(LipClosureTorch(louder).apply(torch.from_numpy(o)).numpy() - louder.apply(o)).max() < 1e-4


def test_a_face_with_its_lips_shut_keeps_them_touching_and_opens_as_the_model_opens(template):
    import torch
    from talkingface.model.lip_closure import LipClosureTorch
    face, ref_gap, rig, closing, opening = _reference(template)
    shut_face = face.copy()
    shut_face[:, 1] += ref_gap * rig.w_lower        # the lower lip's tissue raised until the lips meet
    assert abs(lip_gap(shut_face[None], template)[0]) < 0.05
    lc = LipClosure(template, shut_face, ref_gap)
    assert len(lc.active) == 0 and len(lc.touching) > len(template.regions["lips_inner_upper"])
    raw = lip_gap(shut_face[None] + closing, template)[0]
    assert raw < -0.8 * ref_gap                      # as the model closes: pressed through by its whole closure
    r = template.regions
    inner, lower = np.setdiff1d(r["lips_inner_upper"], r["lips_inner_lower"]), np.asarray(r["lips_inner_lower"])

    def across(v):  # the gap at each x across the mouth (the upper lip's vertices but the corners)
        lo = lower[np.argsort(v[lower, 0])]
        return v[inner, 1] - np.interp(v[inner, 0], v[lo, 0], v[lo, 1])
    rest = across(shut_face)
    assert rest.max() < 0.05 and rest.min() < -1.0   # shut: they meet in the middle, cross towards the corners
    for scale in (1.0, 0.5, 1.4):                    # any closing, full, half or beyond: at each x as at rest
        assert np.abs(across(shut_face + lc.apply(scale * closing)[0]) - rest).max() < 0.05
    assert np.allclose(lc.apply(opening), opening)   # an opening is the model's
    o = np.concatenate([closing, opening, 0.5 * closing]).astype(np.float32)
    assert np.abs(LipClosureTorch(lc).apply(torch.from_numpy(o)).numpy() - lc.apply(o)).max() < 1e-4


def test_the_calibration_finds_the_gap_the_model_closes_by(template):
    # A model that closes the reference face's lips exactly (its rig's full closure) is calibrated to that face's gap.
    from talkingface.model.lip_closure import fit
    face, ref_gap, _, closing, opening = _reference(template)
    segments = [(face, np.concatenate([opening, s * closing])) for s in (0.9, 1.0, 1.1)]
    ref, raw = fit(segments, template)
    assert abs(raw) < 0.1                 # the model's own offsets shut the median segment
    assert abs(ref - ref_gap) < 0.1, (ref, ref_gap)
