"""Where the points come from: an in-memory array, a dask.array, or a path or
glob of ``.npy`` or Parquet chunks, each turned into a list of chunks that a
worker reads on its own (``read``), so that no process holds the whole set.

A chunk is (kind, what, rows): ("array", ndarray, n), ("npy", path, n),
("parquet", path, n) or ("dask", delayed block, n).  Global point ids are
positions in the concatenation of the chunks, in order.
"""
import glob as globmod
from pathlib import Path

import numpy as np

from .._input import as_exact_float

ARRAY_CHUNK_ROWS = 1 << 19  # 8 MiB of float64 pairs per task argument


def chunks(points, chunk_rows=None):
    """The chunk list of ``points`` (see the module docstring)."""
    if isinstance(points, (str, Path)):
        return _files(str(points))
    if isinstance(points, (list, tuple)) and points and all(isinstance(p, (str, Path))
                                                            for p in points):
        return [c for p in points for c in _files(str(p))]
    if type(points).__module__.startswith("dask"):
        return _dask(points, chunk_rows)
    arr = as_exact_float(points, (2,))
    rows = chunk_rows or ARRAY_CHUNK_ROWS
    return [("array", np.ascontiguousarray(arr[i:i + rows]), len(arr[i:i + rows]))
            for i in range(0, max(len(arr), 1), rows)]


def _files(pattern):
    paths = sorted(globmod.glob(pattern)) if any(ch in pattern for ch in "*?[") else [pattern]
    if not paths:
        raise FileNotFoundError(f"no files match {pattern!r}")
    out = []
    for p in paths:
        if p.endswith(".npy"):
            arr = np.load(p, mmap_mode="r")
            if arr.ndim != 2 or arr.shape[1] != 2:
                raise ValueError(f"{p}: points must have shape (n, 2), got {arr.shape}")
            out.append(("npy", p, int(arr.shape[0])))
        elif p.endswith(".parquet") or p.endswith(".pq"):
            import pyarrow.parquet as pq
            meta = pq.ParquetFile(p).metadata
            out.append(("parquet", p, int(meta.num_rows)))
        else:
            raise ValueError(f"{p}: expected .npy or .parquet chunks")
    return out


def _dask(arr, chunk_rows):
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"points must have shape (n, 2), got {arr.shape}")
    if any(np.isnan(c) for c in arr.chunks[0]):
        raise ValueError("the dask array has unknown chunk sizes; call "
                         "arr.compute_chunk_sizes() first")
    if chunk_rows:
        arr = arr.rechunk((chunk_rows, 2))
    elif len(arr.chunks[1]) > 1:
        arr = arr.rechunk({1: 2})
    blocks = arr.to_delayed().ravel()
    return [("dask", b, int(n)) for b, n in zip(blocks, arr.chunks[0])]


def parquet_xy(table):
    """The two coordinate columns of a Parquet table: "x" and "y" when
    present, else its first two columns."""
    names = table.column_names
    cols = ["x", "y"] if {"x", "y"} <= set(names) else names[:2]
    if len(cols) < 2:
        raise ValueError(f"a Parquet chunk needs two coordinate columns, got {names}")
    return np.column_stack([table.column(c).to_numpy() for c in cols])


def read(kind, what):
    """The chunk's points, validated (lfqt._input.as_exact_float) and finite;
    ``what`` is already the block itself for a dask chunk."""
    if kind == "npy":
        data = np.load(what)
    elif kind == "parquet":
        import pyarrow.parquet as pq
        data = parquet_xy(pq.read_table(what))
    else:
        data = what
    arr = as_exact_float(data, (2,))
    finite = np.isfinite(arr).all(axis=1)
    if not finite.all():
        raise ValueError(f"points contain NaN or inf in {np.count_nonzero(~finite)} rows of "
                         f"a {kind} chunk")
    return arr
