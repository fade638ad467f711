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
from numba.np.arrayobj import populate_array


@njit(cache=True, inline="always")
def u(i):
    """``i`` (non-negative) as an unsigned index."""
    return np.uint64(i)


@njit(cache=True, inline="always")
def mix64(x):
    """splitmix64's finaliser: a well-spread 64-bit hash of x."""
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


@njit(cache=True, inline="always")
def range_seed(lo, hi):
    """The starting state of ``random_index`` for the range [lo, hi): the
    selections' pseudo-random pivots are a function of their range, so
    every run picks the same ones."""
    return np.uint64(0x9E3779B97F4A7C15) ^ np.uint64(lo * 1000003 + hi)


@njit(cache=True, inline="always")
def random_index(state, lo, hi):
    """(next state, a pseudo-random index in [lo, hi)), hi > lo."""
    state = mix64(state)
    return state, lo + np.int64(state % np.uint64(hi - lo))


@intrinsic
def popcount(typingctx, v):
    """Set bits of a uint64 (llvm.ctpop: one popcnt instruction)."""
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.IntType(64), [ir.IntType(64)]), "llvm.ctpop.i64")
        return builder.call(fn, [args[0]])
    return types.int64(types.uint64), codegen


@intrinsic
def prefetch(typingctx, arr, i):
    """Ask the caches for row i of an array (item i of a 1D one) before it
    is read (llvm.prefetch: a read, kept in every level).  A hint: it never
    faults, whatever i is, and changes no result."""
    def codegen(context, builder, signature, args):
        aty = signature.args[0]
        ary = context.make_array(aty)(context, builder, args[0])
        stride = builder.extract_value(ary.strides, 0)
        base = builder.ptrtoint(ary.data, ir.IntType(64))
        addr = builder.add(base, builder.mul(args[1], stride))
        i8p = ir.IntType(8).as_pointer()
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [i8p, ir.IntType(32), ir.IntType(32),
                                                            ir.IntType(32)]), "llvm.prefetch.p0i8")
        builder.call(fn, [builder.inttoptr(addr, i8p), ir.Constant(ir.IntType(32), 0),
                          ir.Constant(ir.IntType(32), 3), ir.Constant(ir.IntType(32), 1)])
        return context.get_dummy_value()
    return types.none(arr, types.int64), codegen


@intrinsic
def borrow(typingctx, arr):
    """A view of ``arr`` that holds no reference: the same data, shape and
    strides with a null memory-info, on which numba's reference counting is
    a no-op (NRT_incref returns at once on null, and LLVM folds the test
    away).  For passing arrays to an inlined helper that loops, where each
    reference would cost two atomic operations per call.  The view must not
    outlive ``arr``: take it inside the kernel that owns ``arr``, and if
    ``arr`` is that kernel's own, use ``arr`` itself after the view's last
    use (numba frees a local array after its last use, the view's uses not
    counted)."""
    def codegen(context, builder, signature, args):
        aty = signature.args[0]
        src = context.make_array(aty)(context, builder, value=args[0])
        view = context.make_array(aty)(context, builder)
        for field in ("data", "shape", "strides", "nitems", "itemsize"):
            setattr(view, field, getattr(src, field))
        view.meminfo = cgutils.get_null_value(view.meminfo.type)
        view.parent = cgutils.get_null_value(view.parent.type)
        return view._getvalue()
    return arr(arr), codegen


@intrinsic
def stack_array(typingctx, size):
    """A float64 array of ``size`` (a compile-time constant) on the stack of
    the calling function, with a null memory-info like ``borrow``'s views:
    no allocation, and no reference counting where it is passed on.  It
    lives as long as that function's frame: pass it down, never return or
    store it.  For the scratch space of the adaptive predicates, which ran
    a heap allocation per call."""
    if not isinstance(size, types.IntegerLiteral):
        return None  # numba retries with the literal
    n = size.literal_value
    aty = types.Array(types.float64, 1, "C")

    def codegen(context, builder, signature, args):
        data = cgutils.alloca_once(builder, context.get_value_type(types.float64), size=n)
        ary = context.make_array(aty)(context, builder)
        intp = context.get_value_type(types.intp)
        populate_array(ary, data=data, shape=[ir.Constant(intp, n)],
                       strides=[ir.Constant(intp, 8)], itemsize=ir.Constant(intp, 8),
                       meminfo=cgutils.get_null_value(ary.meminfo.type))
        return ary._getvalue()
    return aty(size), codegen


@njit(cache=True, nogil=True)
def iota(out, lo, hi):
    """out[i] = i for i in [lo, hi): the identity permutation by ranges, so
    that threads can share it."""
    for i in range(lo, hi):
        out[u(i)] = i


@njit(cache=True, inline="always")
def bit(bits, t):
    """Bit t of a bitmap of uint64 words (64 bits each, lowest first)."""
    return (bits[u(t >> 6)] >> np.uint64(t & 63)) & np.uint64(1)


@njit(cache=True, inline="always")
def rank(bits, first, t):
    """The set bits of ``bits`` before bit t, given ``first[w]``, the set bits
    before word w: a compact id for each set bit, found with one popcount in
    two small arrays (a bit and 8 bytes per 64 items) that stay in cache."""
    below = bits[u(t >> 6)] & ((np.uint64(1) << np.uint64(t & 63)) - np.uint64(1))
    return first[u(t >> 6)] + popcount(below)
