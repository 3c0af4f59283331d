"""Blocked forms whose blocks are sums of forms compiled apart, and their assembly.

DOLFINx packs every coefficient of a form for every entity of each of its integrals. A block
that added the contact terms (integrals over the slave facets, whose coefficients are the
point data on the slave submesh) to the bulk's cell integrals would pack that point data,
as zeros, for every cell of the mesh: many times the values the bulk needs, and most of the
residual's time in 3D (see ``docs/developer.md``). So each block is a list of *parts*,
compiled one by one (the bulk's cells and loads, then the contact terms) and added into the
block one after the other.

Two savings on the tangent: the parts that depend on no coefficient and no constant (a
linear-elastic bulk's stiffness) can be told apart (:func:`split_constant`) and assembled
once, and a matrix of point data (quadrature functions, which couple only at the same
point) can drop the couplings between points that DOLFINx's cell-wise pattern holds
(:func:`without_cross_point_couplings`).

A block is a list of compiled forms (empty: no block); a blocked linear form is a list of
blocks, a blocked bilinear form a list of rows of blocks. The vectors and matrices are
DOLFINx's blocked ones (``kind="mpi"``: each process's owned entries block after block,
then the ghosts).
"""

from __future__ import annotations

from collections.abc import Sequence

import dolfinx
import dolfinx.cpp
import dolfinx.fem.petsc as fem_petsc
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import keysets

Parts = Sequence[dolfinx.fem.Form]


def assemble_vector(b: PETSc.Vec, blocks: Sequence[Parts]) -> PETSc.Vec:
    """Add the parts of each block into its block of ``b``.

    Parameters
    ----------
    b
        A blocked vector over the blocks' spaces (``dolfinx.fem.petsc.create_vector(spaces,
        kind="mpi")``); not zeroed, ghosts not accumulated.
    blocks
        The parts of each block, in the order of the vector's blocks.
    """
    owned, ghosts = b.getAttr("_blocks")
    with b.localForm() as local:
        for k, parts in enumerate(blocks):
            size = owned[k + 1] - owned[k]
            for form in parts:
                values = dolfinx.fem.assemble_vector(form).array
                local.array_w[owned[k] : owned[k + 1]] += values[:size]
                local.array_w[ghosts[k] : ghosts[k + 1]] += values[size:]
    return b


def create_matrix(blocks: Sequence[Sequence[Parts]]) -> PETSc.Mat:
    """A blocked matrix (``kind="mpi"``) with the sparsity of the first part of each block.

    The other parts must integrate over cells of the first (a block's contact terms over
    slave facets of cells its bulk integrates over): an integral couples the dofs of its
    cells. Else a ``ValueError`` on every rank (DOLFINx's matrices drop the values outside
    their pattern silently).
    """
    for i, row in enumerate(blocks):
        for j, parts in enumerate(row):
            if len(parts) > 1:
                _check_within_first(parts, (i, j))
    return fem_petsc.create_matrix(
        [[parts[0] if parts else None for parts in row] for row in blocks], kind="mpi"
    )


def create_matrix_with_pattern(blocks: Sequence[Sequence[Parts]]) -> PETSc.Mat:
    """A matrix of :func:`create_matrix` holding its pattern: DOLFINx's matrix stores no
    entry until one is set, so the blocks are assembled into it once (any values)."""
    A = create_matrix(blocks)
    assemble_matrix(A, blocks)
    A.assemble()
    return A


def assemble_matrix(
    A: PETSc.Mat,
    blocks: Sequence[Sequence[Parts]],
    layout: Sequence[Sequence[Parts]] | None = None,
) -> PETSc.Mat:
    """Add the parts of each block into its block of ``A`` (a matrix of
    :func:`create_matrix`); not finally assembled (``A.assemble()``).

    ``layout``: the blocked form whose first parts give the spaces of ``A``'s rows and
    columns (by default ``blocks``; needed where a row or column of ``blocks`` is empty).
    """
    layout = blocks if layout is None else layout
    rows = _index_sets(layout, 0)
    columns = _index_sets([list(column) for column in zip(*layout, strict=True)], 1)
    for i, row in enumerate(blocks):
        for j, parts in enumerate(row):
            if not parts:
                continue
            local = A.getLocalSubMatrix(rows[i], columns[j])
            for form in parts:
                dolfinx.cpp.fem.petsc.assemble_matrix(
                    local,
                    form._cpp_object,
                    dolfinx.fem.pack_constants(form),
                    dolfinx.fem.pack_coefficients(form),
                    [],
                    True,
                )
            A.restoreLocalSubMatrix(rows[i], columns[j], local)
    return A


def without_cross_point_couplings(
    A: PETSc.Mat, spaces: Sequence[dolfinx.fem.FunctionSpace]
) -> PETSc.Mat:
    """A zero matrix on the pattern of the blocked matrix ``A`` (of
    :func:`create_matrix_with_pattern` over ``spaces``) less the couplings between two
    different points within each diagonal block of a quadrature space.

    A quadrature function's basis functions are one at their point and zero at the others,
    so a form couples two of them only at the same point, but DOLFINx's pattern couples
    every dof of a cell with every other (the master nodes gathered at the six points of a
    slave facet: a dense 54 x 54 block where six 9 x 9 blocks hold the values). The matrix
    drops the zeros assembled outside its pattern (new nonzero locations are ignored);
    a quadrature space's points are its blocks of ``index_map_bs`` dofs, owned with their
    cell.
    """
    sizes = [V.dofmap.index_map.size_local * V.dofmap.index_map_bs for V in spaces]
    starts = np.concatenate([[0], np.cumsum(sizes)])
    offset = A.getOwnershipRange()[0]
    indptr, columns, _ = A.getValuesCSR()
    rows = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
    keep = np.ones(len(columns), dtype=bool)
    for k, V in enumerate(spaces):
        if not V.ufl_element().is_quadrature:
            continue
        bs, lo, hi = V.dofmap.index_map_bs, starts[k], starts[k + 1]
        inside = (rows >= lo) & (rows < hi)
        inside &= (columns >= offset + lo) & (columns < offset + hi)
        keep[inside] = (rows[inside] - lo) // bs == (columns[inside] - offset - lo) // bs
    kept = np.concatenate([[0], np.cumsum(keep)])[indptr]
    B = PETSc.Mat().createAIJ(
        A.getSizes(),
        csr=(
            kept.astype(PETSc.IntType),
            columns[keep].astype(PETSc.IntType),
            np.zeros(int(keep.sum()), dtype=PETSc.ScalarType),  # the pattern, as zeros
        ),
        comm=A.getComm(),
    )
    B.setLGMap(*A.getLGMap())
    B.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATIONS, False)
    B.assemble()
    return B


def split_constant(
    blocks: Sequence[Sequence[Parts]],
) -> tuple[list[list[Parts]], list[list[Parts]]]:
    """The parts of a blocked bilinear form that depend on no coefficient and no constant
    (their values are fixed by the mesh: a small-strain linear-elastic bulk's stiffness),
    and the others, each in the blocks' layout (empty where none)."""

    def constant(form: dolfinx.fem.Form) -> bool:
        f = form._cpp_object
        return not f.coefficients and not f.constants

    fixed = [[[p for p in parts if constant(p)] for parts in row] for row in blocks]
    varying = [[[p for p in parts if not constant(p)] for parts in row] for row in blocks]
    return fixed, varying


def _check_within_first(parts: Parts, block: tuple[int, int]) -> None:
    """A ``ValueError`` (on every rank) where a part of ``block`` integrates over a cell the
    first part does not, or over another mesh."""
    first = parts[0]
    cells = _cells(first)
    outside = sum(
        len(np.setdiff1d(_cells(p), cells, assume_unique=True)) if p.mesh is first.mesh else 1
        for p in parts[1:]
    )
    if first.mesh.comm.allreduce(outside, MPI.SUM):
        raise ValueError(
            f"block {block}: a part integrates over cells the block's first part does not "
            "(its sparsity is the first part's): put the part whose integrals cover the "
            "others first"
        )


def _cells(form: dolfinx.fem.Form) -> np.ndarray:
    """The local cells of the integration entities of ``form`` (a facet's or vertex's
    cells)."""
    f = form._cpp_object
    cells = [np.zeros(0, dtype=np.int32)]
    for kind in f.integral_types:
        for i in range(f.num_integrals(kind, 0)):
            entities = f.domains(kind, i)
            if kind != dolfinx.fem.IntegralType.cell and entities.size:
                # (cell, local index) pairs, two of them for an interior facet
                entities = entities.reshape(len(entities), -1)[:, 0::2]
            cells.append(entities.ravel())
    return keysets.unique(np.concatenate(cells))


def _index_sets(lines: Sequence[Sequence[Parts]], side: int) -> list[PETSc.IS]:
    """The local index sets of the blocks of the rows (``side`` 0) or columns (1) of a
    blocked matrix, from the space of the first part of each line."""
    spaces = [next(parts[0] for parts in line if parts).function_spaces[side] for line in lines]
    return dolfinx.cpp.la.petsc.create_index_sets(
        [(V.dofmaps[0].index_map, V.dofmaps[0].index_map_bs) for V in spaces]
    )
