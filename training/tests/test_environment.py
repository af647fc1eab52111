"""The venv is exactly what training/uv.lock says (scripts/setup.sh installs it with `uv sync --locked`)."""
import importlib.metadata
import re
import sys
import tomllib
from pathlib import Path

import pytest

LOCK = Path(__file__).resolve().parents[1] / "uv.lock"


def canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


# Someone who installs the toolkit into an environment of their own (pyproject.toml's ranges) is not checked.
@pytest.mark.skipif(not (Path(sys.prefix) / ".lock-sha256").exists(), reason="not the project's venv (scripts/setup.sh)")
def test_every_installed_package_is_the_locked_version():
    locked: dict[str, set[str]] = {}
    for p in tomllib.loads(LOCK.read_text())["package"]:
        locked.setdefault(canonical(p["name"]), set()).add(p["version"])  # a package may be locked per Python version
    installed = {canonical(d.metadata["Name"]): d.version for d in importlib.metadata.distributions()}
    unlocked = {n: v for n, v in installed.items() if n not in locked}
    wrong = {n: (v, sorted(locked[n])) for n, v in installed.items() if n in locked and v not in locked[n]}
    assert not unlocked, f"installed but not in uv.lock: {unlocked} (run scripts/setup.sh's ensure_venv, or relock)"
    assert not wrong, f"installed version differs from uv.lock (installed, locked): {wrong}"
    for must in ("torch", "numpy", "onnxruntime", "pocketsphinx"):
        assert must in installed
