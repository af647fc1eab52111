"""One way to read talking-face data, wherever it came from.

Three on-disk layouts open to the same `FaceDataset`:

- our synthetic corpus (corpus/build.py): the community's VOCASET layout
  (wav/, vertices_npy/, templates.pkl) plus meta.json, poses_npy/,
  alignments/, splits.json and the template with its regions;
- processed VOCASET as FaceFormer / CodeTalker write it (process_voca_data.py):
  wav/SUBJECT_sentenceNN.wav, vertices_npy/SUBJECT_sentenceNN.npy (T at 60 fps,
  5023*3, metres), templates.pkl (latin-1 pickle: subject -> (5023, 3));
- processed Multiface as FaceDiffuser writes it: wav/SUBJECT_NN.wav,
  vertices_npy/SUBJECT_NN.npy (T at 30 fps, 6172*3, millimetres), templates.pkl.

The training code sees only `Clip`s: audio, per-frame vertices I + O, the
subject's neutral face, an optional head pose and optional phone labels.
Real datasets need a template file with the region masks (docs/templates.md)
for their topology; pass it as `template=` or put it at ROOT/template/template.json.
"""
from __future__ import annotations

import json
import pickle
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..template import MM_PER_UNIT, Template, load_template
from ..wav import WavError, read_wav

CORPUS_FORMAT = "talking-face-corpus"

# The VOCA split (FaceFormer vocaset/main.py, CodeTalker config/vocaset): subjects, then sentence ranges.
VOCASET_SPLITS = {
    "train": ("FaceTalk_170728_03272_TA FaceTalk_170904_00128_TA FaceTalk_170725_00137_TA FaceTalk_170915_00223_TA "
              "FaceTalk_170811_03274_TA FaceTalk_170913_03279_TA FaceTalk_170904_03276_TA FaceTalk_170912_03278_TA", range(1, 41)),
    "val": ("FaceTalk_170811_03275_TA FaceTalk_170908_03277_TA", range(21, 41)),
    "test": ("FaceTalk_170809_00138_TA FaceTalk_170731_00024_TA", range(21, 41)),
}
# FaceDiffuser's Multiface split: sentence ranges over all subjects.
MULTIFACE_SPLITS = {"train": range(1, 41), "val": range(41, 46), "test": range(46, 51)}


class DatasetError(ValueError):
    """The folder is not a dataset this toolkit reads, or is incomplete; the message says what is missing."""


@dataclass
class Clip:
    key: str
    subject: str
    audio: np.ndarray                 # (S,) float32 mono in [-1, 1]
    sample_rate: int
    fps: float
    vertices: np.ndarray              # (F, N, 3) float32, unposed I + O, dataset units
    template: np.ndarray              # (N, 3) float32, this subject's neutral face
    pose: np.ndarray | None = None    # (F, 6) [axis-angle (rad), translation (units)]; y = R x + t
    phones: list[tuple[str, float, float]] | None = None  # (ARPAbet phone, start s, end s)
    meta: dict = field(default_factory=dict)

    @property
    def num_frames(self) -> int:
        return self.vertices.shape[0]


@dataclass
class FaceDataset:
    root: Path
    layout: str                      # "corpus", "vocaset" or "multiface"
    template: Template               # topology and regions (vertices: a reference neutral face)
    fps: float
    mm_per_unit: float
    splits: dict[str, list[str]]
    subject_templates: dict[str, np.ndarray]
    meta: dict = field(default_factory=dict)
    _frame_step: int = 1

    def keys(self, split: str) -> list[str]:
        if split not in self.splits:
            raise DatasetError(f"{self.root}: no split {split!r} (have {', '.join(self.splits)})")
        if not self.splits[split]:
            raise DatasetError(f"{self.root}: no clip is in the {split!r} split. {self._split_rule()}")
        return self.splits[split]

    def _split_rule(self) -> str:
        """How this dataset's clips are split, for a message about an empty split."""
        own = f"To split your own clips, list their names in {self.root / 'splits.json'}: " \
              f'{{"train": ["alice_sentence01", ...], "val": [...], "test": [...]}}.'
        if self.layout == "corpus" or (self.root / "splits.json").is_file():
            return f"The splits are those of {self.root / 'splits.json'}."
        subjects = sorted({self.subject_of(p.stem) for p in (self.root / "vertices_npy").glob("*.npy")})
        if self.layout == "vocaset":
            rule = "; ".join(f"{name}: {subjects_.split()[0]} and {len(subjects_.split()) - 1} more VOCA subjects, "
                             f"sentences {r.start}-{r.stop - 1}" for name, (subjects_, r) in VOCASET_SPLITS.items())
            return f"Without splits.json the VOCA split applies, by subject and sentence ({rule}); this dataset's " \
                   f"subjects are {', '.join(subjects) or 'none'}. {own}"
        return f"Without splits.json FaceDiffuser's Multiface split applies, by sentence number " \
               f"(train 1-40, val 41-45, test 46-50). {own}"

    def subject_of(self, key: str) -> str:
        if self.layout == "vocaset":
            return key.split("_sentence")[0]
        return key.rsplit("_", 1)[0]

    def load(self, key: str) -> Clip:
        subject = self.subject_of(key)
        try:
            audio, sr = read_wav(self.root / "wav" / f"{key}.wav")
        except WavError as e:  # the dataset's error, naming the clip; the WAV reader's reason kept
            raise DatasetError(f"clip {key}: {e}") from e
        try:
            verts = np.load(self._file("vertices_npy", key, ".npy"))[:: self._frame_step]
        except ValueError as e:  # a pickled object array, a truncated file
            raise DatasetError(f"clip {key}: vertices_npy/{key}.npy is not a plain numeric array: {e}") from e
        n = self.template.num_vertices
        if verts.ndim != 2 or verts.shape[1] != n * 3:
            raise DatasetError(f"{key}: vertices have shape {verts.shape}, expected (frames, {n * 3}) for template {self.template.id}")
        if not np.isfinite(verts).all():
            raise DatasetError(f"clip {key}: vertices_npy/{key}.npy holds NaN or infinite values")
        seconds, frames_seconds = len(audio) / sr, len(verts) / self.fps
        if abs(seconds - frames_seconds) > max(0.25, 0.1 * seconds):  # alignment tools leave a few frames either way
            raise DatasetError(
                f"clip {key}: {len(verts)} frames at {self.fps:g} fps are {frames_seconds:.2f} s, but its audio is "
                f"{seconds:.2f} s (the {self.layout} layout reads vertices at {self.fps * self._frame_step:g} fps)")
        if subject not in self.subject_templates:
            raise DatasetError(f"clip {key}: templates.pkl has no neutral face for subject {subject!r} "
                               f"(it has {', '.join(sorted(self.subject_templates)) or 'none'})")
        ratio = _size_across(verts[:1], 1.0) / max(_size_across(self.subject_templates[subject], 1.0), 1e-12)
        if not 0.5 <= ratio <= 2.0:  # data in another unit than its neutral face would train on nonsense
            raise DatasetError(f"clip {key}: its face is {ratio:.3g} times the size of subject {subject!r}'s neutral face "
                               f"in templates.pkl: both must be in {_units(self.mm_per_unit)}")
        clip = Clip(key, subject, audio, sr, self.fps, verts.reshape(-1, n, 3).astype(np.float32),
                    self.subject_templates[subject].reshape(n, 3).astype(np.float32))
        # Poses and alignments are optional for a dataset (VOCASET has neither), not for a clip of one that has them:
        # a clip without would be measured as a still head and silence, silently.
        if (self.root / "poses_npy").is_dir():
            clip.pose = np.load(self._file("poses_npy", key, ".npy")).astype(np.float32)
        if (self.root / "alignments").is_dir():
            a = json.loads(self._file("alignments", key, ".json").read_text())
            clip.phones = [tuple(p) for p in a["phones"]]
            clip.meta = {k: v for k, v in a.items() if k != "phones"}
        return clip

    def _file(self, folder: str, key: str, suffix: str) -> Path:
        path = self.root / folder / f"{key}{suffix}"
        if not path.is_file():
            raise DatasetError(f"clip {key}: missing {folder}/{path.name} in {self.root}")
        return path


def open_dataset(root: str | Path, template: str | Path | None = None, masks: str | Path | None = None) -> FaceDataset:
    """Open a dataset folder, recognising its layout. For real data, `template` is a template.json, or a
    mesh (.obj/.ply, e.g. VOCASET's FLAME_sample.ply) with its `masks` file."""
    root = Path(root)
    if not root.is_dir():
        raise DatasetError(f"dataset folder {root} does not exist")
    for sub in ("wav", "vertices_npy"):
        if not (root / sub).is_dir():
            raise DatasetError(f"{root} has no {sub}/ folder: not a VOCASET-style dataset (wav/, vertices_npy/, templates.pkl)")
    if (root / "meta.json").exists():
        return _open_corpus(root)
    keys = sorted(p.stem for p in (root / "vertices_npy").glob("*.npy"))
    if not keys:
        raise DatasetError(f"{root}/vertices_npy has no .npy files")
    tpl = _real_template(root, template, masks)
    subject_templates = _read_templates_pkl(root, tpl.num_vertices)
    vocaset = any("_sentence" in k for k in keys)
    for k in keys:  # the subject and the sentence number come from the name
        if not re.fullmatch(r".+_sentence\d+" if vocaset else r".+_\d+", k):
            raise DatasetError(f"{root}/vertices_npy/{k}.npy: names are SUBJECT_sentenceNN (VOCASET) or SUBJECT_NN "
                               f"(Multiface), NN the sentence's number" + ("" if vocaset else "; VOCASET's names contain '_sentence'"))
    if (root / "splits.json").is_file():
        splits = _own_splits(root, keys)
    elif vocaset:
        splits = {}
        for split, (subjects, sentences) in VOCASET_SPLITS.items():
            subs = set(subjects.split())
            splits[split] = [k for k in keys if k.split("_sentence")[0] in subs and int(k.split("_sentence")[1]) in sentences]
    else:
        splits = {split: [k for k in keys if int(k.rsplit("_", 1)[1]) in r] for split, r in MULTIFACE_SPLITS.items()}
    _check_sizes(root / "templates.pkl", subject_templates, 1000.0 if vocaset else 1.0, "VOCASET" if vocaset else "Multiface")
    _check_template_units(tpl, subject_templates, 1000.0 if vocaset else 1.0)
    if vocaset:  # VOCASET is 60 fps; the community subsamples to 30 (FaceFormer data_loader: [::2]).
        return FaceDataset(root, "vocaset", tpl, 30.0, 1000.0, splits, subject_templates, _frame_step=2)
    return FaceDataset(root, "multiface", tpl, 30.0, 1.0, splits, subject_templates)


def _own_splits(root: Path, keys: list[str]) -> dict[str, list[str]]:
    """ROOT/splits.json, {"train": [clip names], "val": [...], "test": [...]}, checked against the clips there."""
    path = root / "splits.json"
    try:
        splits = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise DatasetError(f"{path} is not valid JSON: {e}") from e
    if not isinstance(splits, dict) or not all(isinstance(v, list) for v in splits.values()):
        raise DatasetError(f'{path}: expected {{"train": [clip names], "val": [...], "test": [...]}}')
    have = set(keys)
    for split, names in splits.items():
        missing = [n for n in names if n not in have]
        if missing:
            raise DatasetError(f"{path}: {split!r} names clips that {root}/vertices_npy does not have: {', '.join(missing[:5])}"
                               + (f" and {len(missing) - 5} more" if len(missing) > 5 else ""))
    check_disjoint(path, splits)
    return splits


def check_disjoint(path: Path, splits: dict[str, list[str]]) -> None:
    """A clip in two splits would be tested on what the model trained on: refused, naming the clips."""
    seen: dict[str, str] = {}
    for split, names in splits.items():
        for n in names:
            if seen.setdefault(n, split) != split:
                raise DatasetError(f"{path}: clip {n!r} is in both {seen[n]!r} and {split!r}: a clip belongs to one split")


def _open_corpus(root: Path) -> FaceDataset:
    meta = json.loads((root / "meta.json").read_text())
    if meta.get("format") != CORPUS_FORMAT:
        raise DatasetError(f"{root}/meta.json is not a {CORPUS_FORMAT} file")
    tpl = load_template(root / "template" / "template.json")
    splits = json.loads((root / "splits.json").read_text())
    check_disjoint(root / "splits.json", splits)
    mm = MM_PER_UNIT[meta["units"]]
    return FaceDataset(root, "corpus", tpl, float(meta["fps"]), mm, splits, _read_templates_pkl(root), meta)


#: A neutral face's largest extent (mm) that the units are taken to be right for: a face alone is about 150 mm, a
#: whole head with its neck under 600 (data in millimetres read as metres is a thousand times that).
FACE_SIZE_MM = (50.0, 600.0)


def _size_across(face: np.ndarray, mm_per_unit: float) -> float:
    return float(np.ptp(np.asarray(face, dtype=np.float64).reshape(-1, 3), axis=0).max()) * mm_per_unit


def _units(mm_per_unit: float) -> str:
    return "metres" if mm_per_unit == 1000.0 else "millimetres"


def _check_sizes(path: Path, faces: dict[str, np.ndarray], mm_per_unit: float, layout: str) -> None:
    """Each subject's neutral face must be a face's size in the units its layout's names imply."""
    for subject, face in faces.items():
        size = _size_across(face, mm_per_unit)
        if not FACE_SIZE_MM[0] <= size <= FACE_SIZE_MM[1]:
            raise DatasetError(
                f"{path}: subject {subject!r}'s neutral face is {size:.3g} mm across if its values are in "
                f"{_units(mm_per_unit)}, as {layout}'s clip names imply (a face is about 150 mm): give templates.pkl "
                f"and vertices_npy/ in {_units(mm_per_unit)}")


def _check_template_units(tpl: Template, faces: dict[str, np.ndarray], mm_per_unit: float) -> None:
    """The template must be in the units it says (a mesh's masks file gives them): the browser draws it in them."""
    sizes = sorted(_size_across(face, mm_per_unit) for face in faces.values())
    if not sizes:
        return
    data, own = sizes[len(sizes) // 2], _size_across(tpl.vertices, tpl.to_millimetres())
    if not 0.5 <= own / data <= 2.0:
        raise DatasetError(
            f"the template {tpl.id} is {own:.3g} mm across in the units it gives ({tpl.units}; a mesh's masks file says "
            f"them as \"units\", mm when it does not), the subjects' neutral faces {data:.3g} mm: give the template's units")


def _real_template(root: Path, template: str | Path | None, masks: str | Path | None) -> Template:
    path = Path(template) if template else root / "template" / "template.json"
    if template and not path.exists():
        raise DatasetError(f"the template {path} (--template) does not exist")
    if not path.exists():
        raise DatasetError(
            f"{root}: a real dataset needs its template with region masks: pass --template (and --masks) "
            f"or put it at {path} (docs/templates.md)")
    return load_template(path, masks)


def _read_templates_pkl(root: Path, vertices: int | None = None) -> dict[str, np.ndarray]:
    """templates.pkl, subject -> neutral face; with `vertices`, each checked to have that many, and finite."""
    path = root / "templates.pkl"
    if not path.exists():
        raise DatasetError(f"{root} has no templates.pkl (subject -> neutral vertices)")
    with open(path, "rb") as f:
        # VOCASET's templates.pkl is a Python 2 pickle of numpy arrays (FaceFormer: encoding='latin1').
        data = pickle.load(f, encoding="latin1")
    faces = {k: np.asarray(v, dtype=np.float32) for k, v in data.items()}
    for subject, face in faces.items():
        if vertices is not None and face.size != vertices * 3:
            raise DatasetError(f"{path}: subject {subject!r} has {face.size // 3} vertices, the template {vertices}")
        if not np.isfinite(face).all():
            raise DatasetError(f"{path}: subject {subject!r}'s neutral face holds NaN or infinite values")
    return faces
