"""The CPU's cycle counter (x86: TSC), for phase timings inside kernels and
for the harness's cycle counts (paper 1 reports cycles at 3 GHz)."""
import time

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def cycle_counter(typingctx):
    """The cycle counter via llvm.readcyclecounter, for use inside kernels."""
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(64), []),
                                            "llvm.readcyclecounter")
        return builder.call(fn, [])
    return types.int64(), codegen


@njit(cache=True)
def read_cycles():
    """The cycle counter, from Python."""
    return cycle_counter()


_CYCLES_PER_SECOND = None


def cycles_per_second():
    """Cycle-counter frequency, calibrated once against perf_counter."""
    global _CYCLES_PER_SECOND
    if _CYCLES_PER_SECOND is None:
        c0, t0 = read_cycles(), time.perf_counter()
        time.sleep(0.05)
        c1, t1 = read_cycles(), time.perf_counter()
        _CYCLES_PER_SECOND = (c1 - c0) / (t1 - t0)
    return _CYCLES_PER_SECOND
