"""Fresh memory for the kernels' large arrays (lent out by lfqt.workspace):
anonymous private mappings, with or without transparent huge pages, and
their pages around a kept range given back.

A huge page (2 MiB) costs one fault where small pages (4 KiB) cost 512, and
fewer TLB misses afterwards.  But on a virtual machine whose balloon hands
free memory back to its host (virtio free page reporting, in blocks of
2 MiB), the memory a fresh mapping gets has mostly been taken back by the
host, and a fresh huge page then faults on the host too, at several times
the cost of the same bytes in small pages.  Fresh memory is what a program
that keeps its results meets on every call, and every process on its first
call; only a warm loop that drops each result reuses its mappings (and
there huge pages gain a few per cent at most).  So on such a host every
mapping uses small pages (``huge_pays``); elsewhere, huge pages.  The
numbers are in docs/performance.md ("huge pages and fresh memory").
"""
import ctypes
import mmap
import os

import numpy as np

VIRTIO_DEVICES = "/sys/bus/virtio/devices"
_BALLOON = 0x0005  # virtio device id of the memory balloon
_REPORTING = 5  # its feature bit VIRTIO_BALLOON_F_REPORTING
_reporting = None
MADV_POPULATE_WRITE = 23  # Linux 5.14+: fault a range in, writable, in one call
_libc = None


def mapping(nbytes, huge=True):
    """A fresh anonymous mapping of ``nbytes`` (an mmap object), advised to
    use transparent huge pages or not to (``huge``), for lfqt.workspace to
    lend out as arrays, so that the pages around what a result keeps can
    be given back (``give_back``).  The mapping is private: a shared one (mmap's
    default) is shmem, which gets no transparent huge pages."""
    buf = mmap.mmap(-1, nbytes, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
    advice = getattr(mmap, "MADV_HUGEPAGE" if huge else "MADV_NOHUGEPAGE", None)
    if advice is not None:
        buf.madvise(advice)
    return buf


def huge_pays():
    """Whether fresh mappings go on transparent huge pages: unless the host
    takes free pages back (the module's docstring)."""
    return not host_takes_free_pages()


def mapping_of(a):
    """(the mmap that array ``a`` lies on, the byte offset of a's first
    element in it) for a view of lfqt.workspace's frombuffer array, whose
    data starts the mapping; None for memory from elsewhere."""
    root = a
    while isinstance(root.base, np.ndarray):
        root = root.base
    buf = root.base.obj if isinstance(root.base, memoryview) else root.base
    if not isinstance(buf, mmap.mmap):
        return None
    return buf, a.__array_interface__["data"][0] - root.__array_interface__["data"][0]


def give_back(buf, start, stop=None):
    """Hand the whole pages of mapping ``buf`` between bytes ``start`` and
    ``stop`` (default: its end) back to the system (MADV_DONTNEED: they
    cost no memory again until written, and read as zeros)."""
    start = -(-start // mmap.PAGESIZE) * mmap.PAGESIZE
    stop = len(buf) if stop is None else stop // mmap.PAGESIZE * mmap.PAGESIZE
    if hasattr(mmap, "MADV_DONTNEED") and start < stop:
        buf.madvise(mmap.MADV_DONTNEED, start, stop - start)


def populate(buf, start, stop):
    """Fault in the pages of mapping ``buf`` between bytes ``start`` and
    ``stop`` (page multiples) in one system call, writable, rather than one
    fault per page at its first write: the kernel fills the page tables in a
    loop, without a trap per page.  The call releases the GIL, so threads
    can populate parts of one mapping at once.  Returns False where the
    kernel cannot (before Linux 5.14), and nothing is done then."""
    global _libc
    if _libc is None:
        _libc = ctypes.CDLL(None, use_errno=True)
        _libc.madvise.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
    if stop <= start:
        return True
    address = np.frombuffer(buf, dtype=np.uint8).ctypes.data + start
    return _libc.madvise(address, stop - start, MADV_POPULATE_WRITE) == 0


def host_takes_free_pages(devices=VIRTIO_DEVICES):
    """Whether a virtio memory balloon of this machine reports free pages
    to its host (its features, bit _REPORTING; read once per process for
    VIRTIO_DEVICES)."""
    global _reporting
    default = devices == VIRTIO_DEVICES
    if default and _reporting is not None:
        return _reporting
    found = False
    try:
        names = sorted(os.listdir(devices))
    except OSError:
        names = []
    for name in names:
        try:
            with open(os.path.join(devices, name, "device")) as f:
                device = int(f.read().strip(), 16)
            with open(os.path.join(devices, name, "features")) as f:
                features = f.read().strip()  # one character per bit, bit 0 first
        except (OSError, ValueError):
            continue
        if device == _BALLOON and len(features) > _REPORTING and features[_REPORTING] == "1":
            found = True
    if default:
        _reporting = found
    return found
