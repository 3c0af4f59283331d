"""The candidate master facets of a search: what a rank sends of its master facets
(:class:`MasterCandidates`: their current nodes and a table of their fixed data), what a rank
makes of the rows it received (:class:`Candidates`, in a rank-independent order) and the fans
of facets beside each (:func:`fan_columns`: the neighbourhood of the solver's pattern).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse

from contact_ufl.contact.search.kinds import FACET_EDGES


@dataclass
class MasterCandidates:
    """The master facets of one rank, as the search exchanges them: their current nodes and
    a table of their fixed data.

    Attributes
    ----------
    nodes
        Current positions of the gathered nodes of each facet, ``(nf, gathered, gdim)``: the
        facet's own nodes first, then (smoothed normal) in 2D the nodes before and after it,
        in 3D the fans of its nodes (:func:`~contact_ufl.contact.master.node_fans`).
    table
        The fixed data of each facet side by side, ``int64`` ``(nf, gathered + vertices + ne
        + nflags)`` (its parts: :func:`table_parts`): the stacked index of the first
        displacement unknown of each gathered node (``columns``, ``gathered``), the
        rank-independent keys of the facet (tie-break: its sorted vertex input indices,
        ``keys``, ``vertices``), which of its
        edges lie on the boundary of the master surface (``boundary``, ``ne``) and (smoothed
        normal, 2D) whether the neighbour before / after exists (``flags``, 2; else none).
    """

    nodes: np.ndarray
    table: np.ndarray


def table_parts(table: np.ndarray, gathered: int, vertices: int) -> tuple[np.ndarray, ...]:
    """The columns, keys, boundary edges (``bool``) and flags (``bool``) of the rows of a
    table of :class:`MasterCandidates` (``gathered`` gathered nodes and ``vertices`` vertices
    a facet)."""
    ne = len(FACET_EDGES[vertices])
    columns, keys = table[:, :gathered], table[:, gathered : gathered + vertices]
    boundary = table[:, gathered + vertices : gathered + vertices + ne].astype(bool)
    return columns, keys, boundary, table[:, gathered + vertices + ne :].astype(bool)


@dataclass
class Candidates:
    """The fixed data of the candidate facets a rank received, in the search order (that of
    their vertex keys: rank-independent, so that ties between equidistant facets break the
    same way on any number of ranks).

    Attributes
    ----------
    table
        The rows received (of :class:`MasterCandidates`'s
        table), in the order received.
    order
        The search order of the received rows.
    keys, boundary, flags
        Their vertex keys, boundary edges and (smoothed normal, 2D) neighbour flags, in the
        search order.
    gather
        The stacked index of the unknown of every coordinate of every gathered node,
        ``(ncand, gathered, gdim)``.
    fans, counts
        The fan columns (:func:`fan_columns`) of each candidate and their numbers (the rest
        of a row is ``-1``).
    """

    table: np.ndarray
    order: np.ndarray
    keys: np.ndarray
    boundary: np.ndarray
    flags: np.ndarray
    gather: np.ndarray
    fans: np.ndarray
    counts: np.ndarray

    @classmethod
    def of(
        cls, table: np.ndarray, gathered: int, vertices: int, nodes_per_facet: int, gdim: int
    ) -> Candidates:
        """The data of the received rows ``table`` (``gathered`` gathered nodes, ``vertices``
        vertices, ``nodes_per_facet`` nodes a facet, in ``gdim``)."""
        order = np.lexsort(table[:, gathered : gathered + vertices].T[::-1])
        columns, keys, boundary, flags = table_parts(table[order], gathered, vertices)
        fans = fan_columns(columns, nodes_per_facet, np.arange(len(columns)))
        counts = np.count_nonzero(fans >= 0, axis=1)
        gather = columns[:, :, None] + np.arange(gdim)
        return cls(table.copy(), order, keys, boundary, flags, gather, fans, counts)


def fan_columns(columns: np.ndarray, nodes_per_facet: int, facets: np.ndarray) -> np.ndarray:
    """The columns gathered by the candidate facets that share a side with each of ``facets``
    (the facet included): a node of a segment (2D), an edge (two nodes) of a surface facet.

    Parameters
    ----------
    columns
        The gathered columns of the candidate facets, ``(ncand, gathered)``, the facet's own
        ``nodes_per_facet`` nodes first (``-1``: none).
    nodes_per_facet
        Nodes of a facet.
    facets
        Candidate indices.

    Returns
    -------
    ``(len(facets), width)``: the distinct columns of each facet's fan, ``-1`` padded.
    """
    if len(facets) == 0 or len(columns) == 0:
        return np.zeros((len(facets), 0), dtype=np.int64)
    ids, inverse = np.unique(columns, return_inverse=True)
    inverse = inverse.reshape(columns.shape)

    def incidence(k: int) -> scipy.sparse.csr_array:
        valid = columns[:, :k] >= 0
        rows = np.nonzero(valid)[0]
        data = np.ones(len(rows))
        return scipy.sparse.csr_array(
            (data, (rows, inverse[:, :k][valid])), shape=(len(columns), len(ids))
        )

    own, gathered = incidence(nodes_per_facet), incidence(columns.shape[1])
    chosen, where = np.unique(facets, return_inverse=True)
    shared = own[chosen] @ own.T  # nodes shared by a chosen facet and a candidate
    shared.data = (shared.data >= (1 if nodes_per_facet == 2 else 2)).astype(float)
    shared.eliminate_zeros()
    fans = (shared @ gathered).tocsr()
    fans.sort_indices()
    counts = np.diff(fans.indptr)
    out = np.full((len(chosen), counts.max()), -1, dtype=np.int64)
    rows = np.repeat(np.arange(len(chosen)), counts)
    out[rows, np.arange(len(rows)) - np.repeat(fans.indptr[:-1], counts)] = ids[fans.indices]
    return out[where]
