"""The sparsity plan of the solver matrix: which pattern the factorisation is analysed on.

The tangent ``T^T K T`` changes its pattern whenever the pairing does; a factorisation's
symbolic analysis costs as much as a numeric one. :class:`SolverPattern` keeps the solver
matrix's pattern, not the current pairing's, but that of a *superset* operator (each point
coupled with the master nodes of its facet and of the facets beside it: the couplings'
``pattern_gathers``), so that a pairing that moves points onto neighbouring facets keeps
the pattern and its analysis. It decides, from sorted keys ``row * columns + column`` of the
couplings (:mod:`contact_ufl.keysets`), when a pairing leaves the pattern, when the pattern
grows (a union) and when it is rebuilt on the current superset.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import keysets


def nonzero_keys(M: PETSc.Mat | None) -> np.ndarray:
    """Sorted keys ``row * columns + column`` (global indices) of the nonzeros of this
    rank's rows of ``M``, explicit zeros included (none for no matrix)."""
    if M is None:
        return np.zeros(0, np.int64)
    offsets, columns, _ = M.getValuesCSR()
    start = M.getOwnershipRange()[0]
    rows = np.repeat(np.arange(start, start + len(offsets) - 1, dtype=np.int64), np.diff(offsets))
    keys = rows * M.getSize()[1] + columns
    # an AIJ row holds its columns sorted: the keys are a set already
    return keys if keysets.is_strictly_increasing(keys) else keysets.unique(keys)


class SolverPattern:
    """The couplings the solver matrix's pattern holds, and when it must change.

    Parameters
    ----------
    comm
        The communicator of the unknowns (every decision is collective).
    superset
        Whether the pattern holds the facets beside each point's facet (default of the
        operator: in 2D). Without it (the 3D default) the pattern is the union of the
        pairings met: an analysis for every pairing that leaves it. In 3D the superset's
        extra fill (larger still with the smoothed normal's wide gathers) costs more than
        the analyses it saves.
    slack
        A union that would hold more than ``1 + slack`` times the couplings of the current
        superset is rebuilt on the current one instead (at that growth, or at the start of a
        step): in 3D, where every new pairing grows the pattern, an unbounded union ends with
        several times the nonzeros and the factorisation's flops of the rebuilt pattern.
    """

    def __init__(self, comm: MPI.Comm, superset: bool, slack: float = 0.5):
        self.comm = comm
        self.superset = superset
        self.slack = slack
        self.union_keys: np.ndarray | None = None  # the couplings of the pattern (a union)
        self.current_keys: np.ndarray | None = None  # those of the last superset operator
        self.product_keys: np.ndarray | None = None  # the products' nonzeros in the matrix
        self.must_grow = True  # the pattern must grow before the next factorisation

    def holds(self, keys: np.ndarray) -> bool:
        """Whether the couplings ``keys`` of the current pairing lie within the *last*
        superset operator, on every rank (collective). Not the union of those met: ``T^T K
        T`` is within the pattern of one operator that holds ``T``, while a ``T`` whose
        rows gather from two different earlier operators couples columns that no single one
        of them couples (a new nonzero outside the pattern)."""
        if self.current_keys is None:
            return False
        wide = self.current_keys
        inside = len(keys) == 0 or (
            len(wide) > 0 and bool(np.all(np.isin(keys, wide, assume_unique=True)))
        )
        return bool(self.comm.allreduce(inside, MPI.LAND))

    def widen(self, keys: np.ndarray) -> None:
        """A new superset operator of couplings ``keys``: the pattern must grow by it."""
        self.current_keys = keys
        self.union_keys = keys if self.union_keys is None else keysets.union(self.union_keys, keys)
        self.must_grow = True

    def forget(self) -> None:
        """Drop the couplings met: the next superset is the pattern's only one."""
        self.union_keys = self.current_keys = None

    def overgrown(self) -> bool:
        """Whether the union of the couplings met holds more than ``1 + slack`` times those
        of the current superset (collective)."""
        union, now = self.comm.allreduce(np.array([len(self.union_keys), len(self.current_keys)]))
        return bool(union > (1.0 + self.slack) * now)

    def rebuilt(self, product_keys: np.ndarray) -> None:
        """The matrix was made anew on the current superset, with the products' nonzeros
        ``product_keys``."""
        self.union_keys = self.current_keys
        self.product_keys = product_keys
        self.must_grow = False

    def grown(self, product_keys: np.ndarray) -> None:
        """The matrix's pattern grew by the products' nonzeros ``product_keys``."""
        self.product_keys = keysets.union(self.product_keys, product_keys)
        self.must_grow = False

    def within_matrix(self, product_keys: np.ndarray) -> bool:
        """Whether the nonzeros ``product_keys`` (:func:`nonzero_keys`) of a product over
        the superset are all among those added to the matrix since it was made, on every
        rank (collective)."""
        inside = bool(np.isin(product_keys, self.product_keys, assume_unique=True).all())
        return bool(self.comm.allreduce(inside, MPI.LAND))
