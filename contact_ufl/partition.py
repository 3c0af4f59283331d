"""A cell partition that splits every body of a mesh over all the ranks.

The bodies of a multi-body mesh share no facet, so they are separate connected components of
the mesh's dual graph (cells joined by a shared facet). A graph partitioner minimises the cut
edges: it puts whole bodies on ranks (the cut between two bodies is free), and then one rank
holds all of a contact pair's slave points, its gathered rows of the chain operator ``T`` and
most of the tangent. :func:`body_partitioner` partitions each connected component on its own
into ``nparts`` parts with the graph partitioner (SCOTCH by default), so every body is split
over all the ranks and its share of the contact surfaces with it.

A body's cells split evenly need not split its contact surface evenly (the graph partitioner
knows nothing of it, and can give one rank twice the slave facets of another), and
the contact work (search, contact assembly, the gathered rows of ``T``, PtAP) goes with the
surface. Given the cells that touch each contact surface (:func:`surface_cells`, from the
contact facets of the mesh being read), each component is split in two stages: the cells of
each of its surfaces first, each surface into equal parts (the graph partitioner on the graph
joining that surface's cells within two facet steps of each other), then the rest grown from
them breadth first, one layer per round, every part up to an equal share of the component's
cells (:func:`_grow`). Every rank then holds an equal share of each body and of each of its
contact surfaces (a body with two, split as one, could get one on each rank). (DOLFINx's
graph partitioners take no vertex weights, so a two-constraint split cannot be asked of them
directly.)

The dual graph is gathered on one rank (a mesh read from gmsh is there already), partitioned
there one component at a time, and each rank gets back the destinations of its cells: the
owner first, then (with ghosting) the ranks of the cells that share a facet with it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import basix
import dolfinx
import dolfinx.cpp
import dolfinx.graph
import numpy as np
import numpy.typing as npt
import scipy.sparse
import scipy.sparse.csgraph
from mpi4py import MPI

from contact_ufl import keysets
from contact_ufl.errors import collective_check

__all__ = ["PARTITIONS", "body_partitioner", "cell_partitioner", "surface_cells"]

#: The partitions :func:`cell_partitioner` knows: each body over all ranks, or DOLFINx's.
PARTITIONS = ("bodies", "graph")

GraphPartitioner = Callable[[Any, int, Any, bool], Any]


def _default_graph_partitioner() -> GraphPartitioner:
    """SCOTCH, else KaHIP, else ParMETIS (whichever this DOLFINx build has)."""
    for name in ("partitioner_scotch", "partitioner_kahip", "partitioner_parmetis"):
        if hasattr(dolfinx.graph, name):
            return getattr(dolfinx.graph, name)()
    raise RuntimeError("this DOLFINx build has no graph partitioner")


def body_partitioner(
    graph_partitioner: GraphPartitioner | None = None,
    on_surface: npt.NDArray[np.integer] | npt.NDArray[np.bool_] | None = None,
) -> GraphPartitioner:
    """A graph partitioner that splits each connected component over all the parts.

    Parameters
    ----------
    graph_partitioner
        Partitions one component (called on ``MPI.COMM_SELF``); default SCOTCH.
    on_surface
        The contact surface that this rank's nodes (cells, in the order of the graph's nodes)
        touch: 0 none, ``k > 0`` the k-th (``True``: one surface); each component's share of
        each surface is split evenly too. Default: none.

    Returns
    -------
    Callable
        ``(comm, nparts, graph, ghosting) -> destinations``, for
        :func:`dolfinx.mesh.create_cell_partitioner`.
    """
    split = graph_partitioner or _default_graph_partitioner()

    def partition(comm: MPI.Comm, nparts: int, graph: Any, ghosting: bool) -> Any:
        offsets = np.asarray(graph.offsets, dtype=np.int64)
        edges = np.asarray(graph.array, dtype=np.int64)
        n = len(offsets) - 1
        marks = np.zeros(n, np.int32) if on_surface is None else np.asarray(on_surface, np.int32)
        collective_check(
            comm,
            len(marks) == n,
            f"on_surface has {len(marks)} entries for {n} cells",
            ValueError,
        )
        gathered = comm.gather((offsets, edges, marks), root=0)
        pieces = None
        if comm.rank == 0:
            sizes = [len(o) - 1 for o, _, _ in gathered]
            degrees = np.concatenate([np.diff(o) for o, _, _ in gathered])
            adjacency = _csr(np.concatenate([e for _, e, _ in gathered]), degrees)
            surface = np.concatenate([m for _, _, m in gathered])
            owner = _split_components(adjacency, nparts, split, surface)
            data, offs = _destinations(adjacency, owner, nparts, ghosting)
            bounds = np.concatenate([[0], np.cumsum(sizes)])
            pieces = [
                (data[offs[a] : offs[b]], offs[a : b + 1] - offs[a])
                for a, b in zip(bounds[:-1], bounds[1:], strict=True)
            ]
        data, offs = comm.scatter(pieces, root=0)
        return dolfinx.cpp.graph.AdjacencyList_int32(
            np.ascontiguousarray(data, dtype=np.int32), np.ascontiguousarray(offs, np.int32)
        )

    return partition


def _csr(edges: npt.NDArray[np.int64], degrees: npt.NDArray[np.int64]) -> scipy.sparse.csr_array:
    """The (global) dual graph as a sparse adjacency matrix."""
    n = len(degrees)
    indptr = np.concatenate([[0], np.cumsum(degrees)])
    return scipy.sparse.csr_array((np.ones(len(edges), dtype=np.int8), edges, indptr), (n, n))


def _split_components(
    adjacency: scipy.sparse.csr_array,
    nparts: int,
    split: GraphPartitioner,
    on_surface: npt.NDArray[np.int32],
) -> npt.NDArray[np.int32]:
    """The part of each node: every connected component split into ``nparts`` parts (and its
    nodes on each surface, ``on_surface == k > 0``, evenly too)."""
    count, label = scipy.sparse.csgraph.connected_components(adjacency, directed=False)
    owner = np.zeros(adjacency.shape[0], dtype=np.int32)
    order = np.argsort(label, kind="stable")
    starts = np.searchsorted(label[order], np.arange(count + 1))
    shift = 0
    for c in range(count):  # one graph partition per body (a handful)
        nodes = order[starts[c] : starts[c + 1]]
        if len(nodes) < 2 * nparts:  # too small to split: keep it whole, on the next rank
            owner[nodes] = shift % nparts
            shift += 1
            continue
        sub = adjacency[nodes][:, nodes].tocsr()
        labels = on_surface[nodes]
        surfaces = [np.flatnonzero(labels == k) for k in np.unique(labels[labels > 0])]
        surfaces = [nodes_k for nodes_k in surfaces if len(nodes_k) >= 2 * nparts]
        if surfaces:
            parts = _split_surfaces_first(sub, surfaces, nparts, split)
        else:
            parts = _split(sub, nparts, split)
        owner[nodes] = (parts + shift) % nparts  # rotate: the bodies' remainders spread
        shift += 1
    return owner


def _split(
    graph: scipy.sparse.csr_array, nparts: int, split: GraphPartitioner
) -> npt.NDArray[np.int32]:
    """The graph partitioner's parts of a (serial) graph."""
    local = dolfinx.cpp.graph.AdjacencyList_int64(
        np.asarray(graph.indices, dtype=np.int64), np.asarray(graph.indptr, dtype=np.int32)
    )
    return np.asarray(split(MPI.COMM_SELF, nparts, local, False).array, dtype=np.int32)


def _split_surfaces_first(
    graph: scipy.sparse.csr_array,
    surfaces: list[npt.NDArray[np.int64]],
    nparts: int,
    split: GraphPartitioner,
) -> npt.NDArray[np.int32]:
    """Parts of one component: the nodes of each of its ``surfaces`` (disjoint) split evenly
    first, one surface at a time (the graph partitioner on the graph joining that surface's
    nodes within two steps of each other: the cells along a surface often share only an
    edge), the other nodes grown from them."""
    owner = np.full(graph.shape[0], -1, dtype=np.int32)
    adjacency = graph.astype(np.int32)
    for surface in surfaces:
        touching = adjacency[surface]
        near = (touching @ adjacency + touching)[:, surface].tocsr()
        near.setdiag(0)
        near.eliminate_zeros()
        owner[surface] = _split(near, nparts, split)
    return _grow(graph, owner, nparts)


def _grow(
    graph: scipy.sparse.csr_array, owner: npt.NDArray[np.int32], nparts: int
) -> npt.NDArray[np.int32]:
    """Assign the unassigned nodes (``owner < 0``) breadth first from the assigned ones, one
    layer per round, every part up to an equal share of the nodes.

    A node claimed by several parts in a round goes to the smallest of them. Nodes that no
    part below its share reaches (cut off by full parts) fill those parts last.
    """
    owner = owner.copy()
    share = -(-len(owner) // nparts)
    sizes = np.bincount(owner[owner >= 0], minlength=nparts)
    frontier = np.flatnonzero(owner >= 0)
    while len(frontier) > 0:
        step = graph[frontier].tocoo()
        nodes, parts = step.col.astype(np.int64), owner[frontier[step.row]]
        free = owner[nodes] < 0
        nodes, parts = nodes[free], parts[free]
        order = np.lexsort((parts, sizes[parts], nodes))  # by node, then the smaller part
        nodes, parts = nodes[order], parts[order]
        first = np.ones(len(nodes), dtype=bool)
        first[1:] = nodes[1:] != nodes[:-1]
        nodes, parts = nodes[first], parts[first]
        order = np.argsort(parts, kind="stable")
        nodes, parts = nodes[order], parts[order]
        room = np.maximum(share - sizes, 0)
        keep = _rank_within(parts.astype(np.int64)) < room[parts]
        nodes, parts = nodes[keep], parts[keep]
        owner[nodes] = parts
        sizes += np.bincount(parts, minlength=nparts)
        frontier = nodes
    rest = np.flatnonzero(owner < 0)
    room = np.maximum(share - sizes, 0)
    owner[rest] = np.repeat(np.arange(nparts, dtype=np.int32), room)[: len(rest)]
    return owner


def _destinations(
    adjacency: scipy.sparse.csr_array, owner: npt.NDArray[np.int32], nparts: int, ghosting: bool
) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.int64]]:
    """Each node's destinations as an adjacency list: its owner, then (with ``ghosting``) the
    other owners of its neighbours, ascending."""
    n = len(owner)
    if not ghosting:
        return owner.copy(), np.arange(n + 1, dtype=np.int64)
    coo = adjacency.tocoo()
    rows, ranks = coo.row.astype(np.int64), owner[coo.col].astype(np.int64)
    other = ranks != owner[rows]
    keys = keysets.unique(rows[other] * nparts + ranks[other])
    ghost_rows, ghost_ranks = keys // nparts, keys % nparts
    counts = 1 + np.bincount(ghost_rows, minlength=n)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    data = np.empty(offsets[-1], dtype=np.int32)
    data[offsets[:-1]] = owner
    first_ghost = offsets[ghost_rows] + 1 + _rank_within(ghost_rows)
    data[first_ghost] = ghost_ranks
    return data, offsets


def _rank_within(sorted_keys: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """Position of each entry within its run of equal (sorted) keys."""
    if len(sorted_keys) == 0:
        return np.empty(0, dtype=np.int64)
    starts = np.flatnonzero(np.concatenate([[True], sorted_keys[1:] != sorted_keys[:-1]]))
    run = np.repeat(starts, np.diff(np.concatenate([starts, [len(sorted_keys)]])))
    return np.arange(len(sorted_keys)) - run


def surface_cells(
    cell_types: list[Any],
    cells: list[npt.NDArray[np.int64]],
    surfaces: list[list[npt.NDArray[np.int64]]],
) -> npt.NDArray[np.int32]:
    """The contact surface each cell has a facet on.

    Parameters
    ----------
    cell_types
        DOLFINx cell type of each block of ``cells``.
    cells
        The cells' vertices (input numbering, DOLFINx's local vertex order), one flat array
        per cell type: what a cell partitioner is given.
    surfaces
        The facets of each contact surface by their vertices (the same numbering), one
        ``(n, k)`` array per facet shape.

    Returns
    -------
    numpy.ndarray
        One label per cell, the blocks in order: 0 none, ``k + 1`` for ``surfaces[k]`` (the
        first, for a cell on several).
    """
    tables = [[np.sort(t, axis=1) for t in surface if len(t) > 0] for surface in surfaces]
    labels = []
    for cell_type, block in zip(cell_types, cells, strict=True):
        nv = dolfinx.cpp.mesh.cell_num_vertices(cell_type)
        vertices = np.asarray(block, dtype=np.int64).reshape(-1, nv)
        tdim = dolfinx.cpp.mesh.cell_dim(cell_type)
        label = np.zeros(len(vertices), dtype=np.int32)
        for local in basix.topology(basix.CellType[cell_type.name])[tdim - 1]:
            keys = np.sort(vertices[:, local], axis=1)
            for k, surface in enumerate(tables):
                for table in surface:
                    if table.shape[1] == len(local):
                        label[_rows_in(keys, table) & (label == 0)] = k + 1
        labels.append(label)
    return np.concatenate(labels) if labels else np.zeros(0, dtype=np.int32)


def _rows_in(rows: npt.NDArray[np.int64], table: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
    """Which rows of ``rows`` are rows of ``table``."""
    _, label = np.unique(np.concatenate([table, rows]), axis=0, return_inverse=True)
    label = label.reshape(-1)
    return np.isin(label[len(table) :], label[: len(table)])


def cell_partitioner(
    partition: str,
    ghost_mode: dolfinx.mesh.GhostMode,
    contact_facets: list[list[npt.NDArray[np.int64]]] | None = None,
) -> Callable[..., Any]:
    """The cell partitioner of ``partition`` (one of :data:`PARTITIONS`).

    Parameters
    ----------
    partition
        ``"bodies"`` (:func:`body_partitioner`) or ``"graph"`` (DOLFINx's).
    ghost_mode
        Ghost mode of the mesh.
    contact_facets
        ``"bodies"``: the facets of each contact surface by their vertices (input numbering,
        one ``(n, k)`` array per facet shape) on the rank that holds the cells; the cells
        touching each surface are split evenly too. Default: none.

    Returns
    -------
    Callable
        ``(comm, nparts, cell_types, cells) -> destinations``, for
        :func:`dolfinx.mesh.create_mesh`.
    """
    if partition == "graph":
        return dolfinx.mesh.create_cell_partitioner(ghost_mode, 2)
    facets = contact_facets or []

    def partition_cells(comm: MPI.Comm, nparts: int, cell_types: list, cells: list) -> Any:
        split = body_partitioner(on_surface=surface_cells(cell_types, cells, facets))
        by_graph = dolfinx.cpp.mesh.create_cell_partitioner(split, ghost_mode, 2)
        return by_graph(comm, nparts, cell_types, cells)

    return partition_cells
