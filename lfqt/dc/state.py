"""The state of one divide-and-conquer run, as one structure on the Python
side: the sorted keys (until the quad-tree is known from them), the gaps
between them, the mesh the merges write (lfqt.dc.layout.Mesh), the merge
codes, and for the alternating ablation its op list (the LFQT's ops are
swept piece by piece as the merges run them, lfqt.dc.merge.merge_lfqt).
Its methods are the only calls into the subdivision and merge kernels."""
from dataclasses import dataclass

import numpy as np

from . import merge, subdivide
from .layout import Mesh


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
        partition row to ``part`` (1, PART); returns the fraction of the
        time spent in the subdivision (merge.merge_lfqt)."""
        sweep, whole = merge.merge_lfqt(self.gaps, lo, hi, self.mesh, counts, part)
        return sweep / whole if whole > 0 else 0.0

    def merge(self, op_lo, op_hi, counts, parts_in, n_in, parts_out, ops=None):
        """Run ops[op_lo:op_hi] (``ops``: another op list, for one top merge)."""
        return merge.run_ops(self.ops if ops is None else ops, op_lo, op_hi, self.mesh,
                             self.codes, counts, parts_in, n_in, parts_out)
