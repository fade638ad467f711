"""Index helpers for the jitted kernels.

numba wraps negative indices around (Python semantics) on every access with a
signed index, and gives signed ``//`` and ``%`` Python's floor semantics.  In
the merge and sort loops those checks cost a quarter to a third of the run
time; an unsigned index skips them.  Only indices known to be non-negative go
through ``u``.
"""
import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic


@njit(cache=True, inline="always")
def u(i):
    """``i`` (non-negative) as an unsigned index."""
    return np.uint64(i)



@intrinsic
def popcount(typingctx, v):
    """Set bits of a uint64 (llvm.ctpop: one popcnt instruction)."""
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.IntType(64), [ir.IntType(64)]), "llvm.ctpop.i64")
        return builder.call(fn, [args[0]])
    return types.int64(types.uint64), codegen
