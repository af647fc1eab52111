"""Loaders for real VOCASET and Multiface, on tiny files written in their processed layouts, and our corpus format."""
import json
import pickle

import numpy as np
import pytest

from talkingface.data.datasets import DatasetError, open_dataset
from talkingface.template import REQUIRED_REGIONS
from talkingface.wav import write_wav

N = 9  # a 3x3 grid stands in for FLAME's 5023 vertices: nothing may depend on the count


def write_mesh_template(root):
    (root / "template").mkdir(parents=True)
    verts = [f"v {0.05 * i} {0.05 * j} 0" for j in range(3) for i in range(3)]  # 100 mm across, in metres
    faces = []
    for j in range(2):
        for i in range(2):
            a = 3 * j + i + 1
            faces += [f"f {a} {a + 1} {a + 4}", f"f {a} {a + 4} {a + 3}"]
    (root / "template" / "face.obj").write_text("\n".join(verts + faces))
    (root / "template" / "masks.json").write_text(json.dumps({"units": "m", "regions": {r: [k % N] for k, r in enumerate(REQUIRED_REGIONS)}}))
    return root / "template" / "face.obj", root / "template" / "masks.json"


def face(mm_per_unit=1000.0, offset_mm=0.0):
    """A neutral face 100 mm across in the layout's units (VOCASET's metres by default; Multiface: 1.0, millimetres)."""
    grid = np.array([[i, j, 0] for j in range(3) for i in range(3)], np.float32)
    return ((50.0 * grid + offset_mm) / mm_per_unit).astype(np.float32)


def write_clip(root, key, frames, sr=16000, seconds=0.5, mm_per_unit=1000.0):
    (root / "wav").mkdir(exist_ok=True)
    (root / "vertices_npy").mkdir(exist_ok=True)
    t = np.arange(int(sr * seconds)) / sr
    write_wav(root / "wav" / f"{key}.wav", 0.3 * np.sin(2 * np.pi * 220 * t), sr)
    # The face, every value a little apart (0.01 mm steps) so that frames can be told apart.
    steps = np.arange(frames * N * 3, dtype=np.float32).reshape(frames, N * 3) * (0.01 / mm_per_unit)
    verts = (face(mm_per_unit).reshape(1, N * 3) + steps).astype(np.float32)
    np.save(root / "vertices_npy" / f"{key}.npy", verts)
    return verts


def test_processed_vocaset(tmp_path):
    """FaceFormer's process_voca_data.py layout: 60 fps, subject_sentenceNN, latin-1 templates.pkl."""
    mesh, masks = write_mesh_template(tmp_path)
    train, test = "FaceTalk_170728_03272_TA", "FaceTalk_170809_00138_TA"
    raw = write_clip(tmp_path, f"{train}_sentence01", 30)  # 0.5 s at 60 fps
    write_clip(tmp_path, f"{train}_sentence40", 30)
    write_clip(tmp_path, f"{test}_sentence05", 30)   # test subjects use sentences 21-40 only
    write_clip(tmp_path, f"{test}_sentence21", 30)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({train: face(), test: face(offset_mm=1.0)}, f, protocol=2)
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    assert ds.layout == "vocaset" and ds.fps == 30 and ds.mm_per_unit == 1000
    assert ds.keys("train") == [f"{train}_sentence01", f"{train}_sentence40"]
    assert ds.keys("test") == [f"{test}_sentence21"]
    clip = ds.load(f"{train}_sentence01")
    assert clip.subject == train and clip.num_frames == 15  # 60 -> 30 fps
    np.testing.assert_array_equal(clip.vertices.reshape(15, -1), raw[::2])
    np.testing.assert_array_equal(ds.load(f"{test}_sentence21").template, face(offset_mm=1.0))
    assert clip.pose is None and clip.phones is None


def test_processed_multiface(tmp_path):
    """FaceDiffuser's Multiface layout: 30 fps, subject_NN, sentences 1-40 / 41-45 / 46-50, millimetres."""
    mesh, masks = write_mesh_template(tmp_path)
    for k in (1, 41, 46, 50):
        write_clip(tmp_path, f"6795937_{k:02d}", 12, mm_per_unit=1.0)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"6795937": face(1.0)}, f)
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    assert ds.layout == "multiface" and ds.fps == 30
    assert ds.keys("train") == ["6795937_01"] and ds.keys("val") == ["6795937_41"]
    assert ds.keys("test") == ["6795937_46", "6795937_50"]
    clip = ds.load("6795937_46")
    assert clip.subject == "6795937" and clip.vertices.shape == (12, N, 3)


def test_wrong_vertex_count_and_missing_pieces_are_reported(tmp_path):
    mesh, masks = write_mesh_template(tmp_path)
    (tmp_path / "wav").mkdir()
    with pytest.raises(DatasetError, match="vertices_npy"):
        open_dataset(tmp_path, template=mesh, masks=masks)
    write_clip(tmp_path, "S1_01", 4, mm_per_unit=1.0)
    with pytest.raises(DatasetError, match="templates.pkl"):
        open_dataset(tmp_path, template=mesh, masks=masks)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"S1": face(1.0)}, f)
    np.save(tmp_path / "vertices_npy" / "S1_01.npy", np.zeros((4, 7 * 3), dtype=np.float32))
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    with pytest.raises(DatasetError, match="expected"):
        ds.load("S1_01")
    with pytest.raises(DatasetError, match="template with region masks"):
        open_dataset(tmp_path)
    with pytest.raises(DatasetError, match="does not exist"):
        open_dataset(tmp_path / "nope")


def test_a_clip_whose_audio_is_not_wav_is_reported_with_its_key(tmp_path):
    mesh, masks = write_mesh_template(tmp_path)
    write_clip(tmp_path, "S1_01", 4, mm_per_unit=1.0)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"S1": face(1.0)}, f)
    (tmp_path / "wav" / "S1_01.wav").write_bytes(b"not a wav at all")
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    with pytest.raises(DatasetError, match="clip S1_01: .* is not a WAV file"):
        ds.load("S1_01")


def own_dataset(root, keys, frames=30):
    """A VOCASET-layout dataset of the user's own subjects (not VOCA's), 0.5 s clips at 60 fps."""
    mesh, masks = write_mesh_template(root)
    for k in keys:
        write_clip(root, k, frames)
    with open(root / "templates.pkl", "wb") as f:
        pickle.dump({k.split("_sentence")[0]: face() for k in keys}, f)
    return mesh, masks


def test_own_subjects_are_split_by_splits_json_and_an_empty_split_says_how(tmp_path):
    keys = ["alice_sentence01", "alice_sentence02", "bob_sentence01"]
    mesh, masks = own_dataset(tmp_path, keys)
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    with pytest.raises(DatasetError, match=r"no clip is in the 'train' split.*VOCA split.*alice, bob.*splits\.json"):
        ds.keys("train")
    (tmp_path / "splits.json").write_text(json.dumps({"train": keys[:2], "val": [], "test": keys[2:]}))
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    assert ds.keys("train") == keys[:2] and ds.keys("test") == ["bob_sentence01"]
    with pytest.raises(DatasetError, match=r"no clip is in the 'val' split. The splits are those of .*splits\.json"):
        ds.keys("val")
    (tmp_path / "splits.json").write_text(json.dumps({"train": ["carol_sentence01"]}))
    with pytest.raises(DatasetError, match="'train' names clips that .* does not have: carol_sentence01"):
        open_dataset(tmp_path, template=mesh, masks=masks)
    (tmp_path / "splits.json").write_text("{train: }")
    with pytest.raises(DatasetError, match="not valid JSON"):
        open_dataset(tmp_path, template=mesh, masks=masks)
    (tmp_path / "splits.json").write_text(json.dumps({"train": keys[:2], "test": keys[1:]}))
    with pytest.raises(DatasetError, match="'alice_sentence02' is in both 'train' and 'test'"):
        open_dataset(tmp_path, template=mesh, masks=masks)


def test_names_without_a_sentence_number_are_refused_with_the_pattern(tmp_path):
    mesh, masks = own_dataset(tmp_path, ["alice_sentenceA1"])
    with pytest.raises(DatasetError, match="SUBJECT_sentenceNN"):
        open_dataset(tmp_path, template=mesh, masks=masks)


@pytest.mark.parametrize("fault, message", [
    ("nan", "NaN or infinite"),
    ("long", r"90 frames at 30 fps are 3.00 s, but its audio is 0.50 s"),
    ("short", r"3 frames at 30 fps are 0.10 s, but its audio is 0.50 s"),
    ("object", "not a plain numeric array"),
])
def test_a_clip_with_bad_vertices_is_refused_naming_it(tmp_path, fault, message):
    mesh, masks = own_dataset(tmp_path, ["alice_sentence01"])
    (tmp_path / "splits.json").write_text(json.dumps({"train": ["alice_sentence01"]}))
    path = tmp_path / "vertices_npy" / "alice_sentence01.npy"
    if fault == "nan":
        v = np.load(path)
        v[4, 4] = np.nan  # an even frame: the 60 fps layout reads every other one
        np.save(path, v)
    elif fault in ("long", "short"):
        np.save(path, np.zeros((180 if fault == "long" else 6, N * 3), np.float32))
    else:
        np.save(path, np.array([{"not": "vertices"}], dtype=object), allow_pickle=True)
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    with pytest.raises(DatasetError, match=f"alice_sentence01.*{message}"):
        ds.load("alice_sentence01")


def test_templates_pkl_faults_are_named(tmp_path):
    mesh, masks = own_dataset(tmp_path, ["alice_sentence01"])
    (tmp_path / "splits.json").write_text(json.dumps({"train": ["alice_sentence01"]}))
    for faces, message in [({"alice": np.zeros((N + 1, 3))}, "subject 'alice' has 10 vertices, the template 9"),
                           ({"alice": np.full((N, 3), np.nan)}, "'alice'.*NaN or infinite")]:
        with open(tmp_path / "templates.pkl", "wb") as f:
            pickle.dump(faces, f)
        with pytest.raises(DatasetError, match=message):
            open_dataset(tmp_path, template=mesh, masks=masks)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"bob": face()}, f)
    with pytest.raises(DatasetError, match="templates.pkl has no neutral face for subject 'alice' \\(it has bob\\)"):
        open_dataset(tmp_path, template=mesh, masks=masks).load("alice_sentence01")


def test_data_in_other_units_than_the_layout_implies_is_refused(tmp_path):
    """VOCASET-named data in millimetres (or a clip in other units than its neutral face) would train on nonsense."""
    mesh, masks = own_dataset(tmp_path, ["alice_sentence01"])
    (tmp_path / "splits.json").write_text(json.dumps({"train": ["alice_sentence01"]}))
    open_dataset(tmp_path, template=mesh, masks=masks).load("alice_sentence01")  # metres, as VOCASET's: fine
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"alice": face(1.0)}, f)  # millimetres
    with pytest.raises(DatasetError, match=r"'alice'.s neutral face is 1e\+05 mm across if its values are in metres, as VOCASET"):
        open_dataset(tmp_path, template=mesh, masks=masks)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"alice": face()}, f)
    np.save(tmp_path / "vertices_npy" / "alice_sentence01.npy", np.tile(face(1.0).reshape(1, -1), (30, 1)))
    with pytest.raises(DatasetError, match=r"clip alice_sentence01: its face is 1e\+03 times the size of subject 'alice'.s neutral face"):
        open_dataset(tmp_path, template=mesh, masks=masks).load("alice_sentence01")


def test_a_template_in_other_units_than_it_says_is_refused(tmp_path):
    """A mesh template in metres whose masks file says nothing of units (so millimetres): the face would be drawn tiny."""
    mesh, masks = own_dataset(tmp_path, ["alice_sentence01"])
    regions = json.loads(masks.read_text())["regions"]
    masks.write_text(json.dumps({"regions": regions}))
    with pytest.raises(DatasetError, match=r"the template face is 0\.1 mm across in the units it gives \(mm; .*\), the subjects' neutral faces 100 mm"):
        open_dataset(tmp_path, template=mesh, masks=masks)
