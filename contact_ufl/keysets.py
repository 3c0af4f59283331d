"""Sorted sets of integer keys: the nonzeros of a matrix (``row * columns + column``), the
columns a chain operator gathers, the dofs of a body.

NumPy 2.5's ``np.unique(x)`` (without ``return_*``) goes by a hash table, which is much
slower than a sort on integer keys (see ``docs/developer.md``), also when ``x`` is already
sorted; ``np.union1d`` calls it. These sort-based equivalents give the same arrays.
"""

from __future__ import annotations

import numpy as np

__all__ = ["is_strictly_increasing", "union", "unique"]


def unique(x: np.ndarray) -> np.ndarray:
    """The sorted distinct values of ``x`` (``np.unique(x)`` of a 1-D or flattened array)."""
    y = np.sort(np.ravel(x))
    if len(y) < 2:
        return y
    keep = np.empty(len(y), dtype=bool)
    keep[0] = True
    np.not_equal(y[1:], y[:-1], out=keep[1:])
    return y[keep]


def is_strictly_increasing(x: np.ndarray) -> bool:
    """Whether the 1-D ``x`` is sorted with no repeated value (a set already)."""
    return len(x) < 2 or bool((x[1:] > x[:-1]).all())


def union(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The union of two sorted sets ``a`` and ``b`` (``np.union1d`` of sets): the values of
    ``b`` missing from ``a`` appended to it, and the two sorted runs merged."""
    if len(a) == 0:
        return b.copy()
    at = np.searchsorted(a, b)
    missing = b[(at == len(a)) | (a[np.minimum(at, len(a) - 1)] != b)]
    out = np.concatenate([a, missing.astype(a.dtype, copy=False)])
    out.sort(kind="stable")  # a merge of the two runs
    return out
