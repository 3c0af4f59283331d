"""Global numbering of blocked (monolithic) PETSc systems, and the chain-rule operator.

DOLFINx numbers a blocked system ``[V_0, V_1, ...]`` by concatenating, on each rank, the
owned dofs of every block; ranks follow one another. :class:`StackedLayout` turns a dof of
one block, known by its global index *within that block*, into its index in the stacked
system, for dofs owned by any rank.

The contact residual is assembled over ``[u, xhat, lambda...]`` where ``xhat`` are master
node positions carried to the slave quadrature points. They are not unknowns: ``xhat =
Xhat + P u``. The operator ``T`` maps the unknowns ``[u, lambda...]`` to ``[u, xhat,
lambda...]`` (identity on ``u`` and the multipliers, ``P`` on ``xhat``), so that the
residual is ``T^T r`` and the Jacobian ``T^T K T`` (chain rule).
"""

from __future__ import annotations

from collections.abc import Sequence

import dolfinx
import numpy as np
import numpy.typing as npt
from petsc4py import PETSc


class StackedLayout:
    """Numbering of a blocked system over function spaces.

    Parameters
    ----------
    spaces
        The function spaces of the blocks, in order.
    """

    def __init__(self, spaces: Sequence[dolfinx.fem.FunctionSpace]):
        comm = spaces[0].mesh.comm
        self.comm = comm
        maps = [(V.dofmap.index_map, V.dofmap.index_map_bs) for V in spaces]
        self.bs = np.array([bs for _, bs in maps])
        sizes = np.array([im.size_local * bs for im, bs in maps], dtype=np.int64)
        starts = np.array([im.local_range[0] * bs for im, bs in maps], dtype=np.int64)
        all_sizes = np.array(comm.allgather(sizes))  # (nranks, nblocks)
        self.block_starts = np.array(comm.allgather(starts)).T  # (nblocks, nranks)
        totals = all_sizes.sum(axis=1)
        self.rank_offsets = np.concatenate([[0], np.cumsum(totals)[:-1]])
        self.block_offsets = np.hstack(
            [np.zeros((len(totals), 1), np.int64), np.cumsum(all_sizes, axis=1)[:, :-1]]
        )  # (nranks, nblocks)
        self.local_sizes = sizes
        self.local_size = int(sizes.sum())
        self.global_size = int(totals.sum())
        self.rank = comm.rank

    def owned(self, block: int, local: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """Stacked index of owned dofs of ``block`` given by their local (unrolled) index."""
        local = np.asarray(local, dtype=np.int64)
        return self.rank_offsets[self.rank] + self.block_offsets[self.rank, block] + local

    def from_block_global(self, block: int, index: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """Stacked index of dofs of ``block`` given by their global (unrolled) block index."""
        index = np.asarray(index, dtype=np.int64)
        starts = self.block_starts[block]
        owner = np.searchsorted(starts, index, side="right") - 1
        return self.rank_offsets[owner] + self.block_offsets[owner, block] + index - starts[owner]


class GlobalValues:
    """The values of a distributed vector at stacked (global) indices, on this rank: a
    PETSc scatter made once (collective), read as often as the vector changes.

    Parameters
    ----------
    vec
        A vector of the layout (its communicator and numbering).
    indices
        Stacked indices to read; ``-1`` reads 0.
    """

    def __init__(self, vec: PETSc.Vec, indices: npt.ArrayLike):
        indices = np.asarray(indices, dtype=np.int64)
        self._size = len(indices)
        self._where = np.flatnonzero(indices >= 0)
        wanted = indices[self._where].astype(PETSc.IntType)
        source = PETSc.IS().createGeneral(wanted, comm=PETSc.COMM_SELF)
        self._values = PETSc.Vec().createSeq(len(wanted), comm=PETSc.COMM_SELF)
        self._scatter = PETSc.Scatter().create(vec, source, self._values, None)
        source.destroy()

    def read(self, vec: PETSc.Vec) -> npt.NDArray[np.float64]:
        """The values of ``vec`` at the indices (collective)."""
        self._scatter.scatter(
            vec, self._values, addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD
        )
        out = np.zeros(self._size)
        out[self._where] = self._values.array_r
        return out


def chain_operator(
    rows: StackedLayout,
    cols: StackedLayout,
    identity_blocks: Sequence[tuple[int, int]],
    gather_blocks: Sequence[int],
    gather_cols: Sequence[npt.NDArray[np.int64]],
) -> PETSc.Mat:
    """The operator ``T`` from the unknowns to the assembled fields.

    Parameters
    ----------
    rows, cols
        Layouts of the assembled system (rows) and of the unknowns (columns).
    identity_blocks
        Pairs ``(row block, column block)`` mapped by the identity.
    gather_blocks
        The row blocks filled by gathering unknowns (the master node positions).
    gather_cols
        For each gather block, for each of its owned dofs (unrolled, in local order), the
        stacked column index of the unknown it copies, or -1 for none (a quadrature point
        without a master facet). A 2D array ``(ndofs, width)`` gives several columns per
        dof (``-1`` padded): an operator whose sparsity pattern holds those of several
        pairings (its values, ones, are not those of a chain rule).

    Returns
    -------
    A parallel AIJ matrix of local size ``(rows.local_size, cols.local_size)``.
    """
    width = max([1, *(c.shape[1] for c in gather_cols if np.ndim(c) == 2)])
    row_index = np.full((rows.local_size, width), -1, dtype=np.int64)
    offset = np.concatenate([[0], np.cumsum(rows.local_sizes)])
    for rb, cb in identity_blocks:
        n = rows.local_sizes[rb]
        row_index[offset[rb] : offset[rb] + n, 0] = cols.owned(cb, np.arange(n))
    for gb, cols_b in zip(gather_blocks, gather_cols, strict=True):
        cols_b = np.asarray(cols_b)
        cols_b = cols_b[:, None] if cols_b.ndim == 1 else cols_b
        row_index[offset[gb] : offset[gb + 1], : cols_b.shape[1]] = cols_b
    row_index.sort(axis=1)  # ascending columns in each row (the -1 first)
    has = row_index >= 0
    indptr = np.concatenate([[0], np.cumsum(has.sum(axis=1))]).astype(PETSc.IntType)
    indices = row_index[has].astype(PETSc.IntType)
    values = np.ones(len(indices), dtype=PETSc.ScalarType)
    T = PETSc.Mat().createAIJ(
        size=((rows.local_size, rows.global_size), (cols.local_size, cols.global_size)),
        csr=(indptr, indices, values),
        comm=rows.comm,
    )
    T.assemble()
    return T


def split_tangent(
    forms: Sequence[Sequence[list]], fields: Sequence, unknowns: Sequence
) -> tuple[list[list] | None, list[list] | None, list[int]]:
    """The blocks of a tangent over the fields split by what the chain rule does to them.

    ``T`` maps an unknown to its own field by the identity, so ``T^T K T`` holds the blocks
    of ``K`` between two unknowns unchanged: they can be assembled straight into a matrix
    over the unknowns. Only the blocks that touch a gathered field (the master node
    positions ``xhat``) need the product, and only over the fields they couple.

    Parameters
    ----------
    forms
        The blocked tangent over ``fields``, each block a list of parts (compiled forms, see
        :mod:`contact_ufl.assembly`; empty: no block), rows and columns in the order of
        ``fields``.
    fields, unknowns
        The assembled fields and the unknowns (a subsequence of the fields, in their order).

    Returns
    -------
    unknown_forms
        The blocks between two unknowns, over ``unknowns`` (the solver matrix's layout);
        ``None`` where an unknown is no field (a control's load factor, gathered onto a field
        of its own) or a row or column of either part would hold no block: then every block
        goes through the product.
    gathered_forms
        The other blocks, over the coupled fields (empty where both are unknowns), or
        ``None`` where no block touches a gathered field.
    coupled
        Indices (in ``fields``) of the fields that those blocks couple, in order.
    """
    n = len(fields)
    whole = [list(row) for row in forms], list(range(n))  # every block through the product
    own = {id(f) for f in unknowns}
    kept = [i for i, f in enumerate(fields) if id(f) in own]
    if [id(fields[i]) for i in kept] != [id(f) for f in unknowns]:
        return None, *whole  # an unknown that is no field
    gathered = [
        [forms[i][j] if i not in kept or j not in kept else [] for j in range(n)] for i in range(n)
    ]
    touches = [any(gathered[i]) or any(row[i] for row in gathered) for i in range(n)]
    coupled = [i for i in range(n) if touches[i]]
    unknown_forms = [[forms[i][j] for j in kept] for i in kept]
    if not coupled:
        return unknown_forms, None, []
    gathered_forms = [[gathered[i][j] for j in coupled] for i in coupled]
    # a blocked matrix needs a form in every row and column
    blocks = [*unknown_forms, *zip(*unknown_forms, strict=True)]
    blocks += [*gathered_forms, *zip(*gathered_forms, strict=True)]
    if not all(any(row) for row in blocks):
        return None, *whole
    return unknown_forms, gathered_forms, coupled
