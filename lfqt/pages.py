"""Fresh memory for the kernels' large arrays (lent out by lfqt.workspace):
anonymous private mappings, with or without transparent huge pages, and
their pages around a kept range given back.

A huge page (2 MiB) costs one fault where small pages (4 KiB) cost 512, and
fewer TLB misses afterwards: the divide and conquer runs 7% faster on them
(1M points, calls back to back).  But on a virtual machine whose
balloon hands free memory back to its host (virtio free page reporting, in
blocks of 2 MiB), a freed huge page goes back to the host about 2 s later,
and a fresh one then faults on the host too::

    216 MB written once, fresh     huge pages     small pages
    reused within 2 s              0.04 s        0.08 s
    after the host took it back    0.4-0.6 s     0.08 s

(our Firecracker VMs).  So huge pages pay for calls whose memory is soon
reused, and cost most where calls run long: a 3D insertion of 1M points
runs 4 s, and its cell records and output came back host-faulted on every
call, 0.7 s of 4.6 (``host_takes_free_pages``).  An array's size stands for
the length of the call that writes it, hence for how soon its pages come
back (``huge_pays``)::

    divide and conquer, T on        huge pages     small pages
    1M points (T 48 MB), a call     0.230 s        0.240-0.258 s
    4M (192 MB), a call             0.98-1.07 s    1.00-1.05 s
    4M, a process's first call      1.02-1.52 s    1.00-1.16 s
    6M (288 MB), a call             1.76-1.79 s    1.54-1.57 s
    10M (480 MB), a call            2.85-2.98 s    2.58-2.62 s
    10M, 2 threads, a call          1.33-2.58 s    1.49-1.77 s
"""
import mmap
import os

import numpy as np

SOON_REUSED = 128 << 20  # bytes: a larger array's call outlasts the host's ~2 s
VIRTIO_DEVICES = "/sys/bus/virtio/devices"
_BALLOON = 0x0005  # virtio device id of the memory balloon
_REPORTING = 5  # its feature bit VIRTIO_BALLOON_F_REPORTING
_reporting = None


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


def huge_pays(nbytes):
    """Whether an array of ``nbytes`` goes on huge pages: unless the host
    takes free pages back and the array is larger than SOON_REUSED, whose
    call then runs long enough for the host to have taken back the pages
    the last call freed (the table above)."""
    return nbytes <= SOON_REUSED or not host_takes_free_pages()


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
