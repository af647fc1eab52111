"""head_motion's --cache: the train split's residuals and features, kept in an .npz with what they were made from, and
reused only when that matches (the fit itself takes seconds; collecting them, up to 25 minutes)."""
from __future__ import annotations

import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np


def cached(path: Path | None, source: str, against_mean: bool, compute: Callable[[], tuple]) -> tuple[list, list, list[str], list[str]]:
    """(residuals, feats, speakers, sources) from `path` where it was made from `source` with the same `against_mean`,
    else from compute(), then kept in `path` (None: no cache). A file that is not such a cache, or another's, stops."""
    if path is None:
        return compute()
    if path.exists():
        try:
            data = np.load(path, allow_pickle=False)
            fresh = "made_from" in data and str(data["made_from"]) == source and bool(data["against_mean"]) == against_mean
        except (ValueError, OSError, EOFError, zipfile.BadZipFile) as e:
            raise SystemExit(f"--cache {path} is not a cache this command wrote ({e}): delete it or give another --cache") from e
        if not fresh:
            raise SystemExit(f"{path} was made from another corpus or checkpoint, with the other --against-mean, or by "
                             "an earlier version: delete it or give another --cache")
        n = int(data["clips"])
        return [data[f"r{i}"] for i in range(n)], [data[f"f{i}"] for i in range(n)], data["speakers"].tolist(), data["sources"].tolist()
    residuals, feats, speakers, sources = compute()
    np.savez(path, clips=len(residuals), speakers=np.array(speakers), sources=np.array(sources), against_mean=against_mean,
             made_from=source, **{f"r{i}": r for i, r in enumerate(residuals)}, **{f"f{i}": f for i, f in enumerate(feats)})
    return residuals, feats, speakers, sources
