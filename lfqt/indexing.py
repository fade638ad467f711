"""Index helpers for the jitted kernels.

numba wraps negative indices around (Python semantics) on every access with a
signed index, and gives signed ``//`` and ``%`` Python's floor semantics.  In
the merge and sort loops those checks cost a quarter to a third of the run
time; an unsigned index skips them.  Only indices known to be non-negative go
through ``u``.
"""
import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def u(i):
    """``i`` (non-negative) as an unsigned index."""
    return np.uint64(i)

