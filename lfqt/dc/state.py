"""The state of one divide-and-conquer run, as one structure on the Python
side: the sorted keys (until the quad-tree is known from them), the gaps
between them, the mesh the merges write (lfqt.dc.layout.Mesh), the op list
and the merge codes.  Its two methods are the only calls into the
subdivision and merge kernels."""
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
    ops: np.ndarray    # the post-order ops: 2n slots, a range [2 lo, 2 hi) per bin
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

    def subdivide(self, lo, hi, at):
        """Write the ops of positions [lo, hi) from ops[at]; returns the end."""
        return subdivide.subdivide_lfqt(self.gaps, lo, hi, self.ops, at)

    def merge(self, op_lo, op_hi, counts, parts_in, n_in, parts_out, ops=None):
        """Run ops[op_lo:op_hi] (``ops``: another op list, for one top merge)."""
        return merge.run_ops(self.ops if ops is None else ops, op_lo, op_hi, self.mesh,
                             self.codes, counts, parts_in, n_in, parts_out)
