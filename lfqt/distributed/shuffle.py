"""A shuffle through files: each writer sorts its rows by destination and
writes one file, with the offsets of every destination's rows at its head;
each reader reads its own range of every file.  The graph holds one task
per writer and one per reader (not one per pair), and the data waits on
disk rather than in the workers' memory.

A file is ``.npy`` arrays one after another: the offsets (int64, parts + 1),
a summary (float64, one row per part, maybe no columns), then the arrays,
each with one row per item.  A reader seeks to its rows;
no file is read whole.  Files are written under a temporary name and
renamed, so that a task run again (after a worker is lost) never leaves a
half-written file under the final name.

The directory must be visible to every worker (a local disk for a
LocalCluster, a shared file system for a cluster of machines).
"""
import contextlib
import errno
import os
import shutil

import numpy as np
from numpy.lib import format as npformat


class DiskFullError(OSError):
    """The scratch or output directory ran out of space."""


def write(path, starts, *arrays, summary=None):
    """Write ``starts`` (the offsets of each part's rows), ``summary`` (a
    row of floats per part, or nothing) and ``arrays`` (rows grouped by
    part) to ``path``; returns ``path`` as a str."""
    path = str(path)
    if summary is None:
        summary = np.empty((len(starts) - 1, 0))
    tmp = f"{path}.{os.getpid()}.part"
    try:
        with writing(path), open(tmp, "wb") as f:
            for a in (np.asarray(starts, dtype=np.int64),
                      np.asarray(summary, dtype=np.float64), *arrays):
                npformat.write_array(f, np.ascontiguousarray(a), allow_pickle=False)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path


@contextlib.contextmanager
def writing(path):
    """A full disk while writing ``path`` raises DiskFullError (ENOSPC,
    EDQUOT, or Arrow's words for them), naming the file."""
    try:
        yield
    except OSError as e:
        if e.errno in (errno.ENOSPC, errno.EDQUOT) or "No space left" in str(e):
            raise DiskFullError(errno.ENOSPC, f"no space left to write {str(path)!r}: free "
                                f"some disk, or give a directory with room (scratch= or "
                                f"out=)") from e
        raise


def written(*paths):
    """The writers' files, once all are written: one task between the
    writers and the readers, so that the graph has writers + readers
    edges, not their product."""
    return list(paths)


def read(path, part):
    """The rows of part ``part`` of every array in the file, as a list."""
    with open(path, "rb") as f:
        starts = _next(f)
        _rows(f, 0, 0, 1)  # the summary
        lo, hi = int(starts[part]), int(starts[part + 1])
        return _rows(f, lo, hi)


def summary(path, part):
    """(rows of part ``part``, its summary row), reading the head only."""
    with open(path, "rb") as f:
        starts = _next(f)
        return int(starts[part + 1] - starts[part]), _rows(f, part, part + 1, 1)[0][0]


def _rows(f, lo, hi, arrays=None):
    """Rows lo:hi of the next ``arrays`` arrays (default: all the rest)."""
    out = []
    while arrays is None or len(out) < arrays:
        try:
            shape, dtype = _header(f)
        except EOFError:
            return out
        row = int(np.prod(shape[1:], dtype=np.int64)) * dtype.itemsize
        begin = f.tell()
        f.seek(begin + lo * row)
        data = np.fromfile(f, dtype=dtype, count=(hi - lo) * (row // dtype.itemsize))
        out.append(data.reshape((hi - lo,) + tuple(shape[1:])))
        f.seek(begin + shape[0] * row)
    return out


def _header(f):
    if not f.read(1):
        raise EOFError
    f.seek(-1, os.SEEK_CUR)
    version = npformat.read_magic(f)
    reader = npformat.read_array_header_1_0 if version == (1, 0) else npformat.read_array_header_2_0
    shape, fortran, dtype = reader(f)
    if fortran:
        raise ValueError("shuffle files hold C-ordered arrays")
    return shape, dtype


def _next(f):
    shape, dtype = _header(f)
    return np.fromfile(f, dtype=dtype, count=int(np.prod(shape, dtype=np.int64)))


def remove(directory):
    """Remove a scratch directory and everything in it."""
    shutil.rmtree(directory, ignore_errors=True)
