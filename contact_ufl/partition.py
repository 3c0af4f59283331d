"""A cell partition that splits every body of a mesh over all the ranks.

The bodies of a multi-body mesh share no facet, so they are separate connected components of
the mesh's dual graph (cells joined by a shared facet). A graph partitioner minimises the cut
edges: it puts whole bodies on ranks (the cut between two bodies is free), and then one rank
holds all of a contact pair's slave points, its gathered rows of the chain operator ``T`` and
most of the tangent. :func:`body_partitioner` partitions each connected component on its own
into ``nparts`` parts with the graph partitioner (SCOTCH by default), so every body is split
over all the ranks and its share of the contact surfaces with it.

The dual graph is gathered on one rank (a mesh read from gmsh is there already), partitioned
there one component at a time, and each rank gets back the destinations of its cells: the
owner first, then (with ghosting) the ranks of the cells that share a facet with it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import dolfinx
import dolfinx.cpp
import dolfinx.graph
import numpy as np
import numpy.typing as npt
import scipy.sparse
import scipy.sparse.csgraph
from mpi4py import MPI

__all__ = ["PARTITIONS", "body_partitioner", "cell_partitioner"]

#: The partitions :func:`cell_partitioner` knows: each body over all ranks, or DOLFINx's.
PARTITIONS = ("bodies", "graph")

GraphPartitioner = Callable[[Any, int, Any, bool], Any]


def _default_graph_partitioner() -> GraphPartitioner:
    """SCOTCH, else KaHIP, else ParMETIS (whichever this DOLFINx build has)."""
    for name in ("partitioner_scotch", "partitioner_kahip", "partitioner_parmetis"):
        if hasattr(dolfinx.graph, name):
            return getattr(dolfinx.graph, name)()
    raise RuntimeError("this DOLFINx build has no graph partitioner")


def body_partitioner(graph_partitioner: GraphPartitioner | None = None) -> GraphPartitioner:
    """A graph partitioner that splits each connected component over all the parts.

    Parameters
    ----------
    graph_partitioner
        Partitions one component (called on ``MPI.COMM_SELF``); default SCOTCH.

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
        gathered = comm.gather((offsets, edges), root=0)
        pieces = None
        if comm.rank == 0:
            sizes = [len(o) - 1 for o, _ in gathered]
            degrees = np.concatenate([np.diff(o) for o, _ in gathered])
            adjacency = _csr(np.concatenate([e for _, e in gathered]), degrees)
            owner = _split_components(adjacency, nparts, split)
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
    adjacency: scipy.sparse.csr_array, nparts: int, split: GraphPartitioner
) -> npt.NDArray[np.int32]:
    """The part of each node: every connected component split into ``nparts`` parts."""
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
        local = dolfinx.cpp.graph.AdjacencyList_int64(
            np.asarray(sub.indices, dtype=np.int64), np.asarray(sub.indptr, dtype=np.int32)
        )
        parts = np.asarray(split(MPI.COMM_SELF, nparts, local, False).array, dtype=np.int32)
        owner[nodes] = (parts + shift) % nparts  # rotate: the bodies' remainders spread
        shift += 1
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
    keys = np.unique(rows[other] * nparts + ranks[other])
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


def cell_partitioner(partition: str, ghost_mode: dolfinx.mesh.GhostMode) -> Callable[..., Any]:
    """The cell partitioner of ``partition`` (one of :data:`PARTITIONS`)."""
    if partition == "graph":
        return dolfinx.mesh.create_cell_partitioner(ghost_mode, 2)
    return dolfinx.mesh.create_cell_partitioner(body_partitioner(), ghost_mode, 2)
