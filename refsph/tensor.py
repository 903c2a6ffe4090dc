"""Batched small-matrix helpers for arrays of shape (N, d, d), d = 2 or 3 (closed forms, no LAPACK loop)."""
from __future__ import annotations

import numpy as np

__all__ = ["det", "inv", "identity"]


def identity(n: int, d: int) -> np.ndarray:
    """n copies of the d x d identity, shape (n, d, d)."""
    out = np.zeros((n, d, d))
    idx = np.arange(d)
    out[:, idx, idx] = 1.0
    return out


def det(A: np.ndarray) -> np.ndarray:
    """Determinants of a stack of 2x2 or 3x3 matrices."""
    if A.shape[-1] == 2:
        return A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    return (A[:, 0, 0] * (A[:, 1, 1] * A[:, 2, 2] - A[:, 1, 2] * A[:, 2, 1])
            - A[:, 0, 1] * (A[:, 1, 0] * A[:, 2, 2] - A[:, 1, 2] * A[:, 2, 0])
            + A[:, 0, 2] * (A[:, 1, 0] * A[:, 2, 1] - A[:, 1, 1] * A[:, 2, 0]))


def inv(A: np.ndarray, detA: np.ndarray | None = None) -> np.ndarray:
    """Inverses of a stack of 2x2 or 3x3 matrices by the adjugate (A^-1 = adj(A) / det A)."""
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
