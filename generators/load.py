"""A user's own point cloud as an (n, 2) or (n, 3) float64 array.

``load(path)`` reads, by the file's suffix:

* ``.npy``: an (n, 2) or (n, 3+) numeric array (x, y[, z] are its first
  columns), or a structured array with fields x and y (and z);
* ``.csv``: a header naming x and y (and z) columns, any case, or no header
  and at least two numeric columns (x, y[, z] first);
* ``.parquet``/``.pq``: columns x and y (and z), any case (pyarrow, in the
  ``distributed`` extra);
* ``.las``/``.laz``: the scaled x, y, z of every point (laspy; ``.laz``
  through its lazrs backend; both in the ``lidar`` extra).

Errors say what is wrong: a missing file, an unknown suffix, no x/y
columns, a NaN or infinite coordinate, an empty cloud."""
from pathlib import Path

import numpy as np

SUFFIXES = (".npy", ".csv", ".parquet", ".pq", ".las", ".laz")
LIDAR_EXTRA = "pip install 'lfqt[lidar]' (laspy with the lazrs backend)"


class LoadError(ValueError):
    """The file is no point cloud we can read; the message says why."""


def load(path, dim=None):
    """The points of the file at ``path``: (n, 3) when it has z, else (n, 2);
    ``dim=2`` keeps x and y, ``dim=3`` requires z."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such point cloud: {path}")
    suffix = path.suffix.lower()
    readers = {".npy": _npy, ".csv": _csv, ".parquet": _parquet, ".pq": _parquet,
               ".las": _las, ".laz": _las}
    if suffix not in readers:
        raise LoadError(f"{path}: unknown format {suffix or '(no suffix)'!r}; lfqt reads "
                        f"{', '.join(SUFFIXES)}")
    pts = np.asarray(readers[suffix](path), dtype=np.float64)
    return _checked(path, pts, dim)


def _checked(path, pts, dim):
    if len(pts) == 0:
        raise LoadError(f"{path}: the point cloud is empty")
    bad = ~np.isfinite(pts).all(axis=1)
    if bad.any():
        raise LoadError(f"{path}: {int(bad.sum()):,} points have a NaN or infinite coordinate "
                        f"(the first is row {int(np.flatnonzero(bad)[0])})")
    if dim == 3 and pts.shape[1] < 3:
        raise LoadError(f"{path}: no z column, and a 3D experiment needs one")
    return np.ascontiguousarray(pts[:, :dim] if dim else pts)


def _columns(path, names, get):
    """x, y (and z when present) by name, any case; LoadError without x/y."""
    lower = {str(c).lower(): c for c in names}
    if "x" not in lower or "y" not in lower:
        raise LoadError(f"{path}: no x/y columns (it has {', '.join(map(str, names)) or 'none'})")
    cols = [get(lower[c]) for c in ("x", "y", "z") if c in lower]
    return np.column_stack([np.asarray(c, dtype=np.float64) for c in cols])


def _numeric(path, arr):
    if arr.ndim != 2 or arr.shape[1] < 2:
        raise LoadError(f"{path}: no x/y columns (an array of shape {arr.shape}; lfqt needs "
                        "(n, 2) or (n, 3))")
    return arr[:, :3]


def _npy(path):
    arr = np.load(path, allow_pickle=False)
    if arr.dtype.names:
        return _columns(path, arr.dtype.names, lambda c: arr[c])
    if not np.issubdtype(arr.dtype, np.number):
        raise LoadError(f"{path}: not numbers (dtype {arr.dtype})")
    return _numeric(path, arr)


def _csv(path):
    with open(path) as f:
        first = f.readline()
    cells = [c.strip() for c in first.split(",")]
    try:
        [float(c) for c in cells]
        header = False
    except ValueError:
        header = True
    if not header:
        arr = np.loadtxt(path, delimiter=",", ndmin=2)
        return _numeric(path, arr)
    arr = np.genfromtxt(path, delimiter=",", names=True, dtype=np.float64, ndmin=1)
    names = arr.dtype.names or ()
    if arr.size == 0:
        return np.empty((0, 2))
    return _columns(path, names, lambda c: np.atleast_1d(arr[c]))


def _parquet(path):
    try:
        import pyarrow.parquet as pq
    except ImportError as e:
        raise LoadError(f"{path}: reading Parquet needs pyarrow: pip install 'lfqt[distributed]'"
                        ) from e
    table = pq.read_table(path)
    return _columns(path, table.column_names, lambda c: table.column(c).to_numpy())


def _las(path):
    try:
        import laspy
    except ImportError as e:
        raise LoadError(f"{path}: reading LAS/LAZ needs laspy: {LIDAR_EXTRA}") from e
    try:
        las = laspy.read(path)
    except laspy.errors.LaspyException as e:
        raise LoadError(f"{path}: laspy cannot read it ({e}); for .laz: {LIDAR_EXTRA}") from e
    return np.column_stack((np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)))


def register(path):
    """Load the cloud at ``path`` once and register it in generators.REGISTRY
    as a set of its own: ``input:<file name>`` (x, y) and, when it has z,
    ``input:<file name>:xyz``.  Drawing n points gives its first n rows
    (all of them at n = its size), unchanged.  Returns {dimension: name} and
    the number of points.  The file's size and modification time key the
    set's definition, so that results of another file never resume."""
    import hashlib

    from . import REGISTRY, Distribution
    path = Path(path)
    pts = load(path)
    stat = path.stat()
    digest = hashlib.sha256(f"{path.resolve()}:{stat.st_size}:{stat.st_mtime_ns}".encode())
    names = {}
    for dim in (2, 3):
        if pts.shape[1] < dim:
            continue
        name = f"input:{path.name}" + (":xyz" if dim == 3 else "")
        cols = np.ascontiguousarray(pts[:, :dim])
        REGISTRY[name] = Distribution(name, dim, _prefix(cols), f"{path} ({digest.hexdigest()[:12]})",
                                      duplicates="by-design", default_n=len(pts), tags=("input",))
        names[dim] = name
    return names, len(pts)


def _prefix(pts):
    def draw(rng, n):
        """The first n points of the user's file."""
        if n > len(pts):
            raise ValueError(f"the file has {len(pts):,} points, not {n:,}")
        return pts[:n].copy()
    return draw
