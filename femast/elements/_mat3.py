"""3x3 products for the element kernels, without BLAS and without allocating.

numba compiles ``A @ B`` of two small arrays to a call of BLAS (``dgemm``, ``dgemv``) and a new
array: for 3x3 operands the call and the allocation cost 20-50 times the arithmetic (the seated
ball joint's kernel spent 7.7 us per joint on them).  These helpers write into an ``out`` array
(a stack buffer, :mod:`._stack`, or a slice of an output) and compute every entry in the order
and rounding of the BLAS kernels the joints were verified with (OpenBLAS on x86-64: a fused
multiply-add chain over k = 0, 1, 2 for ``dgemm``; for ``dgemv`` on a row-major matrix the chain
starts from the middle term, ``fma(a2, x2, fma(a0, x0, a1 x1))``, and on a transposed one it is
the plain sum ``(a0 x0 + a1 x1) + a2 x2``), so that results are the same to the bit -- and no
longer depend on which BLAS scipy ships.  ``out`` must not alias an operand.
"""

from __future__ import annotations

from llvmlite import ir
from numba import njit
from numba.core import cgutils, types
from numba.extending import intrinsic


@intrinsic
def fma(typingctx, a, b, c):
    """a b + c rounded once (LLVM's ``llvm.fma.f64``: the hardware's instruction where there is one)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(d, [d, d, d]), "llvm.fma.f64")
        return builder.call(fn, [context.cast(builder, v, t, types.float64) for v, t in zip(args, signature.args)])

    return sig, codegen


@njit(cache=True)
def mm(A, B, out):
    """out = A @ B."""
    for i in range(3):
        for j in range(3):
            out[i, j] = fma(A[i, 2], B[2, j], fma(A[i, 1], B[1, j], A[i, 0] * B[0, j]))


@njit(cache=True)
def mm_at(A, B, out):
    """out = A.T @ B."""
    for i in range(3):
        for j in range(3):
            out[i, j] = fma(A[2, i], B[2, j], fma(A[1, i], B[1, j], A[0, i] * B[0, j]))


@njit(cache=True)
def mm_bt(A, B, out):
    """out = A @ B.T."""
    for i in range(3):
        for j in range(3):
            out[i, j] = fma(A[i, 2], B[j, 2], fma(A[i, 1], B[j, 1], A[i, 0] * B[j, 0]))


@njit(cache=True)
def mm_atbt(A, B, out):
    """out = A.T @ B.T."""
    for i in range(3):
        for j in range(3):
            out[i, j] = fma(A[2, i], B[j, 2], fma(A[1, i], B[j, 1], A[0, i] * B[j, 0]))


@njit(cache=True)
def mv(A, x, out):
    """out = A @ x."""
    for i in range(3):
        out[i] = fma(A[i, 2], x[2], fma(A[i, 0], x[0], A[i, 1] * x[1]))


@njit(cache=True)
def mtv(A, x, out):
    """out = A.T @ x."""
    for i in range(3):
        out[i] = (A[0, i] * x[0] + A[1, i] * x[1]) + A[2, i] * x[2]


@njit(cache=True)
def skew_into(v, S):
    """S = [v]x (as :func:`femast.rotations.skew`)."""
    S[0, 0] = 0.0
    S[1, 1] = 0.0
    S[2, 2] = 0.0
    S[0, 1] = -v[2]
    S[0, 2] = v[1]
    S[1, 0] = v[2]
    S[1, 2] = -v[0]
    S[2, 0] = -v[1]
    S[2, 1] = v[0]
