"""How much this machine lets threads gain, whatever the code: the ceiling
against which a measured thread speedup is judged (Fig. 6, #18's 2-thread
target).

Each probe gives every thread the same fixed work, so t threads on t free
cores finish in the time one thread takes, and the speedup ``t * time(1) /
time(t)`` is t.  Three kinds of work, as in the divide and conquer:

    compute          a dependent floating-point chain in registers (the
                     predicates of the merges in cache)
    random reads     independent reads at random places of a buffer larger
                     than the caches (the radix scatter, the Morton gather,
                     the output): bound by how many misses the memory system
                     keeps in flight for all cores together
    dependent reads  a pointer chase through the same buffer (the merges'
                     walks on a large mesh): bound by memory latency

A shared or virtualised machine may give two threads much less than 2x on
the memory probes; that is then the ceiling for any memory-bound code.
"""
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit

BUFFER_BYTES = 64 << 20  # beyond the last-level cache of the machines we run on
# steps per thread: each probe takes some 20-60 ms on one thread
WORK = {"compute": 20_000_000, "random reads": 2_000_000, "dependent reads": 300_000}
REPEATS = 5


@njit(cache=True, nogil=True)
def _compute(count, seed):
    """``count`` steps of a dependent multiply-add chain: no memory."""
    x = 1.0 + seed * 1e-9
    for _ in range(count):
        x = x * 0.9999999 + 1e-7
    return x


@njit(cache=True, nogil=True)
def _random_reads(buf, count, seed):
    """``count`` reads at places given by a linear congruential sequence:
    each address is known before the previous read returns."""
    mask = np.uint64(buf.shape[0] - 1)
    x = np.uint64(seed) | np.uint64(1)
    s = 0
    for _ in range(count):
        x = x * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)
        s += buf[(x >> np.uint64(24)) & mask]
    return s


@njit(cache=True, nogil=True)
def _dependent_reads(buf, count, seed):
    """``count`` steps of ``i = buf[i]``: each address is the previous read."""
    i = seed & (buf.shape[0] - 1)
    for _ in range(count):
        i = buf[i]
    return i


def _chase_buffer(nbytes, seed=0):
    """One random cycle through all entries of an int32 array of ``nbytes``
    (a power of two of entries), so that a chase never settles in cache."""
    n = 1 << int(np.log2(nbytes // 4))
    order = np.random.default_rng(seed).permutation(n).astype(np.int32)
    nxt = np.empty(n, dtype=np.int32)
    nxt[order] = np.roll(order, -1)
    return nxt


def _kernels(buffer_bytes):
    buf = _chase_buffer(buffer_bytes)
    return {"compute": lambda count, seed: _compute(count, seed),
            "random reads": lambda count, seed: _random_reads(buf, count, seed),
            "dependent reads": lambda count, seed: _dependent_reads(buf, count, seed)}


def thread_scaling(thread_counts, *, work=None, repeats=REPEATS, buffer_bytes=BUFFER_BYTES):
    """{probe: {t: speedup}} for each t in ``thread_counts`` (t = 1 is 1.0):
    t times the median one-thread time over the median time of t threads
    doing the same work each, one-thread and t-thread calls interleaved.
    ``work`` overrides the steps per thread of each probe (WORK)."""
    work = {**WORK, **(work or {})}
    counts = sorted({int(t) for t in thread_counts} | {1})
    if counts[0] < 1:
        raise ValueError(f"thread counts must be positive, got {thread_counts}")
    kernels = _kernels(buffer_bytes)
    out = {}
    with ThreadPoolExecutor(max(counts)) as pool:
        for name, kernel in kernels.items():
            kernel(1000, 1)  # compiled (or loaded) before timing
            times = {t: [] for t in counts}
            for _ in range(repeats):
                for t in counts:
                    t0 = time.perf_counter()
                    list(pool.map(lambda k: kernel(work[name], k + 1), range(t)))
                    times[t].append(time.perf_counter() - t0)
            one = float(np.median(times[1]))
            out[name] = {t: round(t * one / float(np.median(times[t])), 3) for t in counts}
    return out
