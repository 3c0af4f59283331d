"""The sort-based sets of integer keys give NumPy's sets."""

from __future__ import annotations

import numpy as np
import pytest

from contact_ufl import keysets


@pytest.mark.parametrize("n", [0, 1, 2, 1000])
def test_unique_and_union_are_numpys(n):
    rng = np.random.default_rng(n)
    x = rng.integers(-50, 50 if n < 100 else 10**12, size=(n, 3))
    np.testing.assert_array_equal(keysets.unique(x), np.unique(x))
    a, b = np.unique(x[:, 0]), np.unique(x[:, 1:])
    for left, right in ((a, b), (b, a), (a, a), (a[:0], b), (a, b[:0])):
        got = keysets.union(left, right)
        np.testing.assert_array_equal(got, np.union1d(left, right))
        assert got.dtype == np.union1d(left, right).dtype


def test_strictly_increasing():
    assert keysets.is_strictly_increasing(np.array([], dtype=np.int64))
    assert keysets.is_strictly_increasing(np.array([3]))
    assert keysets.is_strictly_increasing(np.array([-2, 0, 7]))
    assert not keysets.is_strictly_increasing(np.array([0, 0, 1]))  # a repeat
    assert not keysets.is_strictly_increasing(np.array([1, 0]))
