"""The state of one divide-and-conquer run, as one structure on the Python
side: the sorted keys (until the quad-tree is known from them), the gaps
between them, the mesh the merges write (lfqt.dc.layout.Mesh), the merge
codes, and for the alternating ablation its op list (the LFQT's ops are
swept piece by piece as the merges run them, State.merge_range).
Its methods are the only calls into the subdivision and merge kernels."""
import time
from dataclasses import dataclass

import numpy as np

from . import merge, subdivide
from .layout import PART, STACK, Mesh

# Ops per piece of merge_range's sweep: each piece costs two calls from
# Python, about 30 us, and a piece this long keeps that under 0.5 ms of a
# 1M call (2M ops), in 1 MB.
OPS_PIECE = 1 << 17


@dataclass
class State:
    khi: np.ndarray    # high 64 bits of the sorted keys (empty for 64-bit keys)
    klo: np.ndarray    # low 64 bits
    wide: bool         # 128-bit keys
    mesh: Mesh
    ops: np.ndarray    # the ablation's post-order ops (the LFQT's are swept as they run)
    gaps: np.ndarray   # uint8, lfqt.dc.subdivide.gap_bits: splits and runs of equal keys
    codes: np.ndarray  # the merges' codes by split position: gaps, or the ablation's
    copies: bool       # a key repeats (gaps has a DUP past position 0)

    @property
    def n(self):
        return self.gaps.shape[0]

    def drop_keys(self):
        """Forget the keys: from here on the gaps stand for them, and the
        merges write T over them (lfqt.dc._memory)."""
        self.khi = self.klo = None

    def bin_ops(self, lo, hi):
        """The LFQT's ops of positions [lo, hi), as a new array."""
        ops = np.empty(2 * max(hi - lo, 0), dtype=np.int64)
        return ops[:subdivide.subdivide_lfqt(self.gaps, lo, hi, ops, 0)]

    def merge_range(self, lo, hi, counts, part):
        """The LFQT's subdivision and merges of positions [lo, hi), its
        partition row to ``part`` (1, PART).  The ops are swept and run a
        piece at a time (subdivide.subdivide_next, merge.run_ops, the
        partition stack handed from piece to piece), so that the call holds
        no list of 2n ops: 8 bytes a point at its peak, the merges' end
        (lfqt.dc._memory).  The loop is here rather than in a kernel that
        calls run_ops: LLVM optimizes a callee again inside its caller, and
        run_ops is most of the first call's compile time (docs/performance.md,
        "peak memory").  Returns the subdivision's share of the time."""
        ops = np.empty(OPS_PIECE, dtype=np.int64)
        stack = np.empty((2, STACK + 1), dtype=np.int64)
        parts = np.empty((STACK, PART), dtype=np.int64)
        i, top, n_parts, sweep = lo, -1, 0, 0.0
        t0 = time.perf_counter()
        while hi > lo:
            t = time.perf_counter()
            nops, i, top = subdivide.subdivide_next(self.gaps, i, hi, ops, stack, top)
            sweep += time.perf_counter() - t
            if nops == 0:
                break
            n_parts = merge.run_ops(ops, 0, nops, self.mesh, self.codes, counts, parts, n_parts,
                                    parts)
        if n_parts:
            part[0] = parts[0]
        return sweep / max(time.perf_counter() - t0, 1e-12)

    def merge(self, op_lo, op_hi, counts, parts_in, n_in, parts_out, ops=None):
        """Run ops[op_lo:op_hi] (``ops``: another op list, for one top merge)."""
        return merge.run_ops(self.ops if ops is None else ops, op_lo, op_hi, self.mesh,
                             self.codes, counts, parts_in, n_in, parts_out)
