"""Exact geometric predicates: expansion arithmetic, 2D and 3D predicates,
the LFQT's level-dependent bounds and the counters, one module each.

Precondition: every nonzero |coordinate| inside the exactness window of its
dimension (lfqt._input: MIN_ULP_EXP, MAX_EXP in 2D, the _3D pair in 3D),
where no product of a predicate's degree overflows or leaves the normal
range.  The public functions (triangulate, insert, verify, Delaunay) rescale
their input into it by an exact power of two, which keeps every sign.
Outside it a sign can be wrong: two subnormals multiply to zero with no
error term, so a left turn of raw subnormal points reads as collinear."""
from .counters import (INCIRCLE, INCIRCLE_S1, INCIRCLE_S2, N_PREDICATE, ORIENT, ORIENT_S1,
                       ORIENT_S2, incircle, new_counters, orient2d, tally)
from .levels import CCW_EXACT_DIFF, ICC_EXACT_DIFF, ICC_EXACT_PRODUCTS, binade, level_bounds
from .planar import (CCW_A, CCW_B, ICC_A, ICC_B, incircle_exact, incircle_staged,
                     orient2d_exact, orient2d_staged, static_bounds)
from .spatial import (ISP_A, O3D_A, insphere_exact, insphere_staged, orient3d_exact,
                      orient3d_staged, static_bounds3)
