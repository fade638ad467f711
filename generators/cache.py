"""On-disk cache of large point sets.

Files live in ``$LFQT_CACHE_DIR`` (default ``~/.cache/lfqt``), named by every
parameter of the set, written atomically (temporary file, then rename) and
loaded memory-mapped read-only.  A file that cannot be loaded is regenerated.
"""
import os
import tempfile
from pathlib import Path

import numpy as np


def cache_dir():
    return Path(os.environ.get("LFQT_CACHE_DIR", Path.home() / ".cache" / "lfqt"))


def cached(key, build):
    """The array stored under ``key``, built by ``build()`` on a miss."""
    path = cache_dir() / f"{key}.npy"
    if path.exists():
        try:
            return np.load(path, mmap_mode="r")
        except (ValueError, OSError, EOFError):
            path.unlink(missing_ok=True)  # corrupted or truncated: rebuild
    arr = build()
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            np.save(f, arr)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return np.load(path, mmap_mode="r")
