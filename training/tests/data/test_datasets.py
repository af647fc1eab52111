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
    verts = [f"v {i} {j} 0" for j in range(3) for i in range(3)]
    faces = []
    for j in range(2):
        for i in range(2):
            a = 3 * j + i + 1
            faces += [f"f {a} {a + 1} {a + 4}", f"f {a} {a + 4} {a + 3}"]
    (root / "template" / "face.obj").write_text("\n".join(verts + faces))
    (root / "template" / "masks.json").write_text(json.dumps({"units": "m", "regions": {r: [k % N] for k, r in enumerate(REQUIRED_REGIONS)}}))
    return root / "template" / "face.obj", root / "template" / "masks.json"


def write_clip(root, key, frames, sr=16000, seconds=0.5):
    (root / "wav").mkdir(exist_ok=True)
    (root / "vertices_npy").mkdir(exist_ok=True)
    t = np.arange(int(sr * seconds)) / sr
    write_wav(root / "wav" / f"{key}.wav", 0.3 * np.sin(2 * np.pi * 220 * t), sr)
    verts = np.arange(frames * N * 3, dtype=np.float32).reshape(frames, N * 3)
    np.save(root / "vertices_npy" / f"{key}.npy", verts)
    return verts


def test_processed_vocaset(tmp_path):
    """FaceFormer's process_voca_data.py layout: 60 fps, subject_sentenceNN, latin-1 templates.pkl."""
    mesh, masks = write_mesh_template(tmp_path)
    train, test = "FaceTalk_170728_03272_TA", "FaceTalk_170809_00138_TA"
    raw = write_clip(tmp_path, f"{train}_sentence01", 10)
    write_clip(tmp_path, f"{train}_sentence40", 10)
    write_clip(tmp_path, f"{test}_sentence05", 10)   # test subjects use sentences 21-40 only
    write_clip(tmp_path, f"{test}_sentence21", 10)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({train: np.zeros((N, 3)), test: np.ones((N, 3))}, f, protocol=2)
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    assert ds.layout == "vocaset" and ds.fps == 30 and ds.mm_per_unit == 1000
    assert ds.keys("train") == [f"{train}_sentence01", f"{train}_sentence40"]
    assert ds.keys("test") == [f"{test}_sentence21"]
    clip = ds.load(f"{train}_sentence01")
    assert clip.subject == train and clip.num_frames == 5  # 60 -> 30 fps
    np.testing.assert_array_equal(clip.vertices.reshape(5, -1), raw[::2])
    np.testing.assert_array_equal(ds.load(f"{test}_sentence21").template, np.ones((N, 3)))
    assert clip.pose is None and clip.phones is None


def test_processed_multiface(tmp_path):
    """FaceDiffuser's Multiface layout: 30 fps, subject_NN, sentences 1-40 / 41-45 / 46-50, millimetres."""
    mesh, masks = write_mesh_template(tmp_path)
    for k in (1, 41, 46, 50):
        write_clip(tmp_path, f"6795937_{k:02d}", 12)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"6795937": np.zeros((N, 3), dtype=np.float32)}, f)
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
    write_clip(tmp_path, "S1_01", 4)
    with pytest.raises(DatasetError, match="templates.pkl"):
        open_dataset(tmp_path, template=mesh, masks=masks)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"S1": np.zeros((N, 3))}, f)
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
    write_clip(tmp_path, "S1_01", 4)
    with open(tmp_path / "templates.pkl", "wb") as f:
        pickle.dump({"S1": np.zeros((N, 3))}, f)
    (tmp_path / "wav" / "S1_01.wav").write_bytes(b"not a wav at all")
    ds = open_dataset(tmp_path, template=mesh, masks=masks)
    with pytest.raises(DatasetError, match="clip S1_01: .* is not a WAV file"):
        ds.load("S1_01")
