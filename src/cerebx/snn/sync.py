"""What a compiled loop needs to trade work with a Python thread without the interpreter lock: loads and stores
that order the memory around them (acquire / release, on an int64 array shared with the other thread), a sleep
and the thread's CPU clock. Each is an external C call or an LLVM instruction, named, not a pointer: the kernels
that use them stay in numba's cache. Used by the spiking controller's chunk server
(:class:`~cerebx.controllers.snn.controller.ChunkServer`).

A plain ``a[i]`` in a compiled loop that waits for another thread may be read once and kept in a register; an
acquire load is read every time, and whatever the other thread wrote before its release store of that element
is visible after it.
"""

from __future__ import annotations

import time

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

_THREAD_CPU = time.CLOCK_THREAD_CPUTIME_ID


@intrinsic
def _load_acquire(typingctx, arr, i):
    """``arr[i]`` of a 1-D int64 array, an atomic acquire load."""
    if not (isinstance(arr, types.Array) and arr.dtype == types.int64 and arr.ndim == 1):
        return None

    def codegen(context, builder, sig, args):
        ary = context.make_array(sig.args[0])(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, sig.args[0], ary, [args[1]])
        return builder.load_atomic(ptr, "acquire", 8)

    return types.int64(arr, i), codegen


@intrinsic
def _store_release(typingctx, arr, i, value):
    """``arr[i] = value`` of a 1-D int64 array, an atomic release store."""
    if not (isinstance(arr, types.Array) and arr.dtype == types.int64 and arr.ndim == 1):
        return None

    def codegen(context, builder, sig, args):
        ary = context.make_array(sig.args[0])(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, sig.args[0], ary, [args[1]])
        v = context.cast(builder, args[2], sig.args[2], types.int64)
        builder.store_atomic(v, ptr, "release", 8)
        return context.get_dummy_value()

    return types.void(arr, i, value), codegen


@intrinsic
def _sleep_us(typingctx, us):
    """``usleep(us)``: the thread sleeps, the core is free (Linux rounds up to its timer slack, ~50 us)."""

    def codegen(context, builder, sig, args):
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(32), [ir.IntType(32)]),
                                            "usleep")
        builder.call(fn, [builder.trunc(context.cast(builder, args[0], sig.args[0], types.int64), ir.IntType(32))])
        return context.get_dummy_value()

    return types.void(us), codegen


def clock_ns_intrinsic(clock_id: int, doc: str):
    """An intrinsic without arguments that returns ``clock_gettime(clock_id)`` in ns (a vDSO call, a few tens of
    ns for the monotonic clock): the kernels' profile clock and the chunk server's CPU clock."""

    def clock(typingctx):
        def codegen(context, builder, sig, args):
            i64 = ir.IntType(64)
            ts = cgutils.alloca_once(builder, ir.LiteralStructType([i64, i64]))  # struct timespec (LP64)
            fnty = ir.FunctionType(ir.IntType(32), [ir.IntType(32), ts.type])
            fn = cgutils.get_or_insert_function(builder.module, fnty, "clock_gettime")
            builder.call(fn, [ir.Constant(ir.IntType(32), clock_id), ts])
            sec = builder.load(cgutils.gep_inbounds(builder, ts, 0, 0))
            nsec = builder.load(cgutils.gep_inbounds(builder, ts, 0, 1))
            return builder.add(builder.mul(sec, ir.Constant(i64, 1_000_000_000)), nsec)

        return types.int64(), codegen

    clock.__doc__ = doc
    return intrinsic(clock)


_thread_cpu_ns = clock_ns_intrinsic(_THREAD_CPU, "The calling thread's CPU time in ns.")


@njit(cache=True, nogil=True)
def load_acquire(arr, i):  # pragma: no cover - numba
    """``arr[i]`` (int64, 1-D) read with acquire order: from Python, once, after a plain read saw the value
    the other thread released, so that what it wrote before is seen too."""
    return _load_acquire(arr, i)


@njit(cache=True, nogil=True)
def store_release(arr, i, value):  # pragma: no cover - numba
    """``arr[i] = value`` (int64, 1-D) with release order: what this thread wrote before is seen by a thread
    that reads the value with acquire order."""
    _store_release(arr, i, value)
