"""Batched small-matrix helpers for arrays of shape (N, d, d), d = 2 or 3 (closed forms, no LAPACK loop).

Memory layout. A stack of N small matrices is an (N, d, d) array everywhere in refsph. The rate
evaluations store such stacks *component-major*: each component A[:, a, b] is one contiguous array of N
numbers (the memory of an (d, d, N) array, viewed as (N, d, d)). Then every operation below is a handful of
whole-array ufunc calls on contiguous data -- a 2x2 product is 8 multiplies and 4 adds over N numbers,
about 8x faster than ``np.matmul`` on a C-ordered (N, 2, 2) stack, which runs a tiny matrix product
per particle. :func:`empty` and :func:`component_major` make such arrays; NumPy keeps the layout through
elementwise arithmetic (``empty_like``, ``a * b``, ``a + b`` of component-major operands), so it only has to
be set where an array is created. Mixing a C-ordered and a component-major operand in one expression works,
but is slow; the rate functions convert their (N, d, d) inputs once on entry.
"""
from __future__ import annotations

import numpy as np

__all__ = ["det", "inv", "identity", "empty", "component_major", "matmul", "transpose", "rowdot"]


def empty(n: int, d: int) -> np.ndarray:
    """An uninitialised (n, d, d) stack stored component-major (A[:, a, b] contiguous)."""
    return np.empty((d, d, n)).transpose(2, 0, 1)


def component_major(A: np.ndarray, copy: bool = False) -> np.ndarray:
    """A as a component-major (N, d, d) stack: A itself if it already is one (and not ``copy``)."""
    A = np.asarray(A, dtype=float)
    if not copy and A.strides[0] == A.itemsize:
        return A
    out = empty(A.shape[0], A.shape[1])
    out[...] = A
    return out


def identity(n: int, d: int) -> np.ndarray:
    """n copies of the d x d identity, shape (n, d, d)."""
    out = np.zeros((n, d, d))
    idx = np.arange(d)
    out[:, idx, idx] = 1.0
    return out


def transpose(A: np.ndarray) -> np.ndarray:
    """A_ba for every matrix of the stack (a view)."""
    return np.swapaxes(A, 1, 2)


def matmul(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """C = A B for stacks of shape (N, d, d): C_ab = sum_k A_ak B_kb, as d whole-stack products."""
    d = A.shape[-1]
    C = A[:, :, 0, None] * B[:, None, 0, :]
    for k in range(1, d):
        C += A[:, :, k, None] * B[:, None, k, :]
    return C


def rowdot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """sum_k a[:, k] b[:, k] for two (M, d) arrays: the dot product of each row pair (M numbers)."""
    out = a[:, 0] * b[:, 0]
    for k in range(1, a.shape[1]):
        out += a[:, k] * b[:, k]
    return out


def det(A: np.ndarray) -> np.ndarray:
    """Determinants of a stack of 2x2 or 3x3 matrices."""
    if A.shape[-1] == 2:
        return A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    return (A[:, 0, 0] * (A[:, 1, 1] * A[:, 2, 2] - A[:, 1, 2] * A[:, 2, 1])
            - A[:, 0, 1] * (A[:, 1, 0] * A[:, 2, 2] - A[:, 1, 2] * A[:, 2, 0])
            + A[:, 0, 2] * (A[:, 1, 0] * A[:, 2, 1] - A[:, 1, 1] * A[:, 2, 0]))


def inv(A: np.ndarray, detA: np.ndarray | None = None) -> np.ndarray:
    """Inverses of a stack of 2x2 or 3x3 matrices by the adjugate (A^-1 = adj(A) / det A).

    The result has the memory layout of A (component-major in, component-major out)."""
    if detA is None:
        detA = det(A)
    out = np.empty_like(A)
    if A.shape[-1] == 2:
        out[:, 0, 0] = A[:, 1, 1]
        out[:, 0, 1] = -A[:, 0, 1]
        out[:, 1, 0] = -A[:, 1, 0]
        out[:, 1, 1] = A[:, 0, 0]
    else:
        out[:, 0, 0] = A[:, 1, 1] * A[:, 2, 2] - A[:, 1, 2] * A[:, 2, 1]
        out[:, 0, 1] = A[:, 0, 2] * A[:, 2, 1] - A[:, 0, 1] * A[:, 2, 2]
        out[:, 0, 2] = A[:, 0, 1] * A[:, 1, 2] - A[:, 0, 2] * A[:, 1, 1]
        out[:, 1, 0] = A[:, 1, 2] * A[:, 2, 0] - A[:, 1, 0] * A[:, 2, 2]
        out[:, 1, 1] = A[:, 0, 0] * A[:, 2, 2] - A[:, 0, 2] * A[:, 2, 0]
        out[:, 1, 2] = A[:, 0, 2] * A[:, 1, 0] - A[:, 0, 0] * A[:, 1, 2]
        out[:, 2, 0] = A[:, 1, 0] * A[:, 2, 1] - A[:, 1, 1] * A[:, 2, 0]
        out[:, 2, 1] = A[:, 0, 1] * A[:, 2, 0] - A[:, 0, 0] * A[:, 2, 1]
        out[:, 2, 2] = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    out /= detA[:, None, None]
    return out
