"""lfqt.workspace: mappings lent as arrays, taken back when the last view
dies, reused best-fit, unmapped when idle; and the views that share one."""
import ctypes
import gc
import mmap
import os
import subprocess
import sys
import time

import numpy as np
import pytest

import lfqt
from conftest import smaps_entry
from lfqt import pages, workspace

MB = 1 << 20


def _address(a):
    return a.__array_interface__["data"][0]


def _resident_kb_over(spans):
    """Resident kB of the pages in the (start, stop) byte ranges ``spans``
    (mincore: page by page, these ranges only, where /proc/self/smaps would
    count a whole memory area, which the kernel may have merged with its
    neighbours); None where mincore is not available."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        mincore = libc.mincore
    except (OSError, AttributeError):
        return None
    mincore.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p]
    page = mmap.PAGESIZE
    total = 0
    for start, stop in spans:
        count = (stop - start + page - 1) // page
        vec = (ctypes.c_ubyte * count)()
        if mincore(ctypes.c_void_p(start), ctypes.c_size_t(stop - start), vec) != 0:
            return None
        total += sum(b & 1 for b in vec) * page // 1024
    return total


def test_a_freed_array_is_reused_by_the_next_request():
    pool = workspace.Pool()
    a = pool.empty(2 * MB, np.uint8)
    where = _address(a)
    del a
    gc.collect()
    assert pool.idle_bytes() == 2 * MB
    b = pool.empty((MB // 8, 2), np.float32)  # another shape and dtype, same bytes
    assert _address(b) == where and pool.idle_bytes() == 0
    assert b.shape == (MB // 8, 2) and b.dtype == np.float32 and b.flags.c_contiguous


def test_a_live_view_keeps_its_mapping_lent():
    pool = workspace.Pool()
    a = pool.empty(2 * MB, np.uint8)
    view = a[10:20]
    view[:] = 7
    del a
    gc.collect()
    assert pool.idle_bytes() == 0
    b = pool.empty(2 * MB, np.uint8)
    b[:] = 1
    assert not np.shares_memory(b, view) and np.all(view == 7)
    del view
    gc.collect()
    assert pool.idle_bytes() == 2 * MB


def test_a_request_takes_the_smallest_idle_mapping_that_fits():
    pool = workspace.Pool()
    arrays = [pool.empty(size * MB, np.uint8) for size in (2, 4, 8)]
    where = {a.shape[0]: _address(a) for a in arrays}
    del arrays
    gc.collect()
    c = pool.empty(3 * MB, np.uint8)
    assert _address(c) == where[4 * MB] and c.shape == (3 * MB,)
    assert pool.idle_bytes() == 10 * MB


def test_a_request_nothing_fits_unmaps_the_smaller_idle_ones():
    pool = workspace.Pool()
    a, b = pool.empty(2 * MB, np.uint8), pool.empty(3 * MB, np.uint8)
    del a, b
    gc.collect()
    assert pool.idle_bytes() == 5 * MB
    c = pool.empty(4 * MB, np.uint8)
    assert pool.idle_bytes() == 0 and c.shape == (4 * MB,)


def test_idle_bytes_past_the_limit_are_unmapped():
    pool = workspace.Pool(limit=3 * MB)
    a, b = pool.empty(2 * MB, np.uint8), pool.empty(2 * MB, np.uint8)
    del a, b
    gc.collect()
    assert pool.idle_bytes() == 2 * MB


def test_idle_mappings_are_unmapped_after_idle_seconds_and_by_release():
    pool = workspace.Pool(idle_seconds=1.0)
    a = pool.empty(2 * MB, np.uint8)
    del a  # back at once (no cycle), long before the timer fires
    assert pool.idle_bytes() == 2 * MB
    deadline = time.monotonic() + 5
    while pool.idle_bytes() and time.monotonic() < deadline:
        time.sleep(0.02)
    assert pool.idle_bytes() == 0
    pool = workspace.Pool()
    a = pool.empty(2 * MB, np.uint8)
    del a
    gc.collect()
    pool.release()
    assert pool.idle_bytes() == 0


def _kept(pool, n=6_000_000, keep=1_000_003):
    """An array of n int32 written whole, and keep_prefix's prefix of it."""
    T = pool.empty(n, np.int32)
    T[:] = np.arange(n, dtype=np.int32)
    return T, pool.keep_prefix(T, keep)


def _resident_kb(a):
    found = smaps_entry(a)
    if found is None:
        pytest.skip("no /proc/self/smaps here")
    return found[0]


def test_a_kept_prefix_gives_back_the_rest_at_release_and_at_the_next_request():
    for give_back in ("release", "fresh mapping", "idle mapping"):
        pool = workspace.Pool()
        if give_back == "idle mapping":  # T takes the larger, the request the smaller
            a, b = pool.empty(2 * MB, np.uint8), pool.empty(30 * MB, np.uint8)
            del a, b
            assert pool.idle_bytes() == 32 * MB
        T, kept = _kept(pool)
        whole = _resident_kb(kept)
        assert whole >= 23_000  # nothing given back yet
        if give_back == "release":
            pool.release()
        else:
            other = pool.empty(2 * MB, np.uint8)
            assert not np.shares_memory(other, kept)
            assert pool.idle_bytes() == 0
        assert _resident_kb(kept) < whole / 2  # 4 MB of 24 MB are still in use
        assert np.array_equal(kept, np.arange(1_000_003, dtype=np.int32))
        assert not T[1_001_024:].any()


def test_a_kept_range_gives_back_the_pages_before_and_after_it():
    pool = workspace.Pool()
    T = pool.empty(6_000_000, np.int32)
    T[:] = np.arange(len(T), dtype=np.int32)
    kept = pool.keep_range(T, 2_000_000, 3_000_003)
    whole = _resident_kb(kept)
    assert whole >= 23_000  # nothing given back yet
    pool.release()
    assert _resident_kb(kept) < whole / 2  # 4 MB of 24 MB are still in use
    assert np.array_equal(kept, np.arange(2_000_000, 3_000_003, dtype=np.int32))
    assert not T[:2_000_000 - 1024].any() and not T[3_001_024:].any()


def test_a_kept_prefix_gives_back_the_rest_after_idle_seconds():
    pool = workspace.Pool(idle_seconds=0.3)
    T, kept = _kept(pool)
    whole = _resident_kb(kept)
    deadline = time.monotonic() + 5
    while _resident_kb(kept) > whole / 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _resident_kb(kept) < whole / 2
    assert np.array_equal(kept, np.arange(1_000_003, dtype=np.int32))


def test_a_result_freed_before_its_pages_go_back_returns_its_mapping_whole():
    pool = workspace.Pool()
    T, kept = _kept(pool)
    where = _address(T)
    del T, kept
    gc.collect()
    again = pool.empty(6_000_000, np.int32)
    assert _address(again) == where
    pool.release()  # nothing to give back any more: the next request's pages stay
    assert np.array_equal(again, np.arange(6_000_000, dtype=np.int32))


def test_small_arrays_come_from_numpy():
    pool = workspace.Pool()
    a = pool.empty((10, 3), np.int64)
    assert a.flags.owndata and a.shape == (10, 3)
    assert pool.empty(0, np.int32).shape == (0,)
    del a
    gc.collect()
    assert pool.idle_bytes() == 0


def test_a_forked_child_still_expires_its_idle_mappings():
    code = ("import gc, os, time, numpy as np\n"
            "from lfqt import workspace\n"
            "workspace.POOL.idle_seconds = 0.05\n"
            "a = workspace.empty(2 << 20, np.uint8); del a; gc.collect()\n"
            "pid = os.fork()\n"
            "if pid == 0:\n"
            "    workspace.POOL.idle_seconds = 0.05\n"
            "    b = workspace.empty(4 << 20, np.uint8); del b; gc.collect()\n"
            "    t = time.monotonic()\n"
            "    while workspace.POOL.idle_bytes() and time.monotonic() - t < 5: time.sleep(0.02)\n"
            "    os._exit(0 if workspace.POOL.idle_bytes() == 0 else 3)\n"
            "_, status = os.waitpid(pid, 0)\n"
            "raise SystemExit(os.waitstatus_to_exitcode(status))\n")
    assert subprocess.run([sys.executable, "-c", code], timeout=120).returncode == 0


def test_views_are_consecutive_aligned_and_bounded():
    buf = np.zeros(workspace.view_bytes((3, np.float64), (5, np.int32), (2, np.uint8)),
                   dtype=np.uint8)
    assert len(buf) == 64 + 64 + 64
    x, y, z = workspace.views(buf, (3, np.float64), (5, np.int32), (2, np.uint8))
    assert (x.shape, y.shape, z.shape) == ((3,), (5,), (2,))
    assert [_address(v) - _address(buf) for v in (x, y, z)] == [0, 64, 128]
    x[:], y[:], z[:] = 1.5, -2, 9
    assert np.all(x == 1.5) and np.all(y == -2) and np.all(z == 9)
    with pytest.raises(ValueError, match="bytes hold no"):
        workspace.views(buf, (3, np.float64), (40, np.int32))


def test_a_kept_result_is_never_lent_to_the_next_call():
    """Results of calls back to back share no memory, and the first stays as
    it was while later calls reuse the pool."""
    rng = np.random.default_rng(5)
    pts = rng.random((300_000, 2))
    first = lfqt.triangulate(pts)
    copies = [a.copy() for a in (first.simplices, first.neighbors, first.duplicate_of)]
    for _ in range(2):
        other = lfqt.triangulate(rng.random((300_000, 2)))
        for a in (first.simplices, first.neighbors, first.duplicate_of):
            for b in (other.simplices, other.neighbors, other.duplicate_of):
                assert not np.shares_memory(a, b)
        del other
        gc.collect()
    for a, b in zip((first.simplices, first.neighbors, first.duplicate_of), copies):
        assert np.array_equal(a, b)
    lfqt.verify(pts, first).raise_if_invalid()


def test_a_kept_result_holds_no_more_resident_memory_than_its_arrays():
    """Once the pool gives back what a result does not use (at release, or
    at the next call's request), the mappings a result lies on hold its
    arrays' pages and nothing of the call's scratch."""
    pts = np.random.default_rng(8).random((300_000, 2))
    tri = lfqt.triangulate(pts)
    workspace.release()
    arrays = (tri.simplices, tri.neighbors, tri.duplicate_of)
    spans = set()
    for a in arrays:
        buf, offset = pages.mapping_of(a)
        start = _address(a) - offset
        spans.add((start, start + len(buf)))
    # simplices and neighbors written over T, on its mapping; duplicate_of on its own
    assert len(spans) == 2
    resident = _resident_kb_over(spans)
    if resident is None:
        pytest.skip("no mincore")
    page_kb = mmap.PAGESIZE / 1024
    assert resident <= sum(a.nbytes for a in arrays) / 1024 + 2 * len(arrays) * page_kb
    lfqt.verify(pts, tri).raise_if_invalid()


def test_a_freed_result_gives_its_memory_to_the_next_call():
    pts = np.random.default_rng(6).random((300_000, 2))
    gc.collect()  # every mapping of earlier tests back in the pool, then none idle
    workspace.release()
    tri = lfqt.triangulate(pts)
    where = _address(tri.simplices)
    assert workspace.SMALLEST <= tri.simplices.nbytes
    del tri
    gc.collect()
    again = lfqt.triangulate(pts)
    assert _address(again.simplices) == where
    lfqt.verify(pts, again).raise_if_invalid()


def _parallel_calls():
    """Python threads triangulating at once (the kernels release the GIL)
    draw on one pool: every result is exact and shares no memory with any
    other still alive."""
    import threading
    sets = [np.random.default_rng(s).random((150_000, 2)) for s in range(4)]
    results, errors = {}, []

    def work(k):
        try:
            for r in range(3):
                results[(k, r)] = lfqt.triangulate(sets[k])
        except BaseException as e:  # noqa: BLE001 - reported by the test
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    arrays = [(key, a) for key, tri in results.items()
              for a in (tri.simplices, tri.neighbors, tri.duplicate_of)]
    for i, (key_a, a) in enumerate(arrays):
        for key_b, b in arrays[i + 1:]:
            assert key_a == key_b or not np.shares_memory(a, b)
    for (k, r), tri in results.items():
        lfqt.verify(sets[k], tri).raise_if_invalid()
        assert np.array_equal(tri.simplices, results[(k, 0)].simplices)


def test_calls_in_parallel_threads_each_get_their_own_memory():
    """_parallel_calls in a child process: a pool that lent one mapping twice
    would crash the kernels."""
    code = (f"import runpy, sys; sys.path.insert(0, {os.path.dirname(__file__)!r}); "
            f"runpy.run_path({__file__!r}, run_name='child')['_parallel_calls']()")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_an_array_lent_a_larger_calls_mapping_holds_only_its_own_pages():
    """A small request that takes the idle mapping of a larger call gets
    the pages past it given back: a result on it keeps no more resident."""
    pool = workspace.Pool()
    big = pool.empty(40 << 20, np.uint8)
    big.fill(1)  # every page resident
    del big
    gc.collect()
    assert pool.idle_bytes() >= 40 << 20
    small = pool.empty(3 << 20, np.uint8)
    small.fill(2)
    buf, offset = pages.mapping_of(small)
    assert len(buf) >= 40 << 20  # the big mapping, lent again
    start = _address(small) - offset
    resident = _resident_kb_over([(start, start + len(buf))])
    if resident is None:
        pytest.skip("no mincore")
    assert resident <= (3 << 20) // 1024 + 4 * mmap.PAGESIZE // 1024
    assert (small == 2).all()
