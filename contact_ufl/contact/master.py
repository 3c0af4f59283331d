"""The master side of a contact pair: a meshed master surface.

The master surface S_oc^(2) is a set of oriented facets whose nodes are displacement dofs;
its current geometry is interpolated from those nodes, so the closest-point projection and
the master virtual displacement U2*(Y) use one and the same surface. What the search needs
of it (:meth:`MeshMaster.candidates`) is the current nodes of every facet, the stacked
indices of the unknowns they gather, and per-facet data (keys for the tie-break, boundary
edges, and for the smoothed normal the neighbouring nodes).

The smoothed normal (``master_normal="smoothed"``) is interpolated from nodal normals, which
depend on the nodes around each facet node; those nodes are carried with the facet's own:

* 2D: the node before and the node after the segment (:func:`segment_neighbours`).
* 3D: the *fan* of each facet node ``a``, the ring of its edge neighbours in cyclic order
  (:func:`node_fans`): ``K + 1`` slots ``s_0 .. s_K``, consecutive slots being the two edge
  neighbours of ``a`` in one facet around ``a``; ``K`` is the most facets around any node of
  the master surface (at most :data:`MAX_FACETS_AROUND_NODE`). A closed fan repeats its first
  neighbour, and unused slots hold ``a`` itself, so that every slot pair gives the corner
  normal ``(s_i - a) x (s_i+1 - a)`` of one facet or zero: no flags are needed. A facet
  carries ``nx = nn (K + 2)`` nodes (duplicates included: the fans of its nodes overlap).
"""

from __future__ import annotations

import basix
import dolfinx
import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from contact_ufl import keysets
from contact_ufl.contact.facets import (
    basix_cell,
    exterior_facet_cells,
    facet_normals,
    tagged_facets,
)
from contact_ufl.contact.search import FACET_EDGES, MasterCandidates
from contact_ufl.errors import collective_check
from contact_ufl.layout import StackedLayout

#: The most master facets around one node of a 3D master surface with the smoothed normal.
#: A slave point carries ``nn (K + 2)`` master nodes for ``K`` facets around a node (the most
#: over the surface): with this bound at most 42 (triangles) or 56 (quadrilaterals); a
#: structured triangulated surface has K = 6 to 8 (27 to 33 nodes), a structured quadrilateral
#: one K = 4 (24 nodes).
MAX_FACETS_AROUND_NODE = 12

#: The nodes of a 3D master facet in cyclic order around it (basix vertex order in, so the
#: bilinear quadrilateral's ``(0, 1, 3, 2)``); the order turns about the outward normal.
CYCLIC_ORDER = {3: (0, 1, 2), 4: (0, 1, 3, 2)}


class MeshMaster:
    """A meshed master surface: oriented facets whose nodes are displacement dofs.

    Facet nodes are the vertices of the facets (linear segments, triangles, bilinear
    quadrilaterals), ordered so that the normal of :mod:`.search.kinds` points out of
    the master body; with a degree-2 displacement followed by the dofs of the facet's edge
    midpoints (3-node segments, 6-node triangles, 9-node quadrilaterals of
    :mod:`.search.kinds`).

    Parameters
    ----------
    u
        The displacement of the master's mesh (its nodes are dofs of ``u``).
    facet_tags, tag
        The facet tags of that mesh and the master surface's tag.
    smoothed
        Whether the normal is smoothed (2D): the neighbours of every segment are gathered.
    block
        The block of ``u`` in the unknowns of the problem (one block per mesh).
    orientation
        (membrane) The sign per cell of the membrane's oriented normal: ``facet_tags`` are
        then the membrane's cell tags, its cells are the master facets, and the master is
        two-sided (:attr:`two_sided`).

    Attributes
    ----------
    nodes
        Local block index (displacement dof block) of each facet node, ``(nf, nn)``.
    nv
        Vertices of a facet (``nn`` for linear facets): the keys and boundary edges are
        those of the vertices.
    X_nodes
        Reference positions of the nodes, ``(nf, nn, gdim)``.
    global_nodes
        Global block index of each node in the displacement index map, ``(nf, nn)``.
    keys
        Sorted input (mesh file) indices of the vertices of each facet, ``(nf, nn)``: the
        same on any number of ranks and in any rigidly moved copy of the scene.
    node_keys
        The input indices of the vertices of each facet in the order of ``nodes``.
    boundary_edges
        For each facet, which of its :data:`FACET_EDGES` lie on the boundary of the master
        surface (2D: which of its two nodes are end points of the surface), ``(nf, ne)``.
    """

    def __init__(
        self,
        u: dolfinx.fem.Function,
        facet_tags: dolfinx.mesh.MeshTags,
        tag: int,
        smoothed: bool,
        block: int = 0,
        orientation: dolfinx.fem.Function | None = None,
    ):
        self.u, self.V = u, u.function_space
        self.facet_tags, self.tag, self.smoothed, self.block = facet_tags, tag, smoothed, block
        #: whether either side of the surface may be the one in contact (a membrane)
        self.two_sided = facet_tags.dim == self.V.mesh.topology.dim
        if self.two_sided:
            self._build_membrane(orientation)
        else:
            self._build()
        #: nodes of a facet (the largest over the ranks: a rank may have no facet)
        self.nn = int(self.V.mesh.comm.allreduce(self.nodes.shape[1], MPI.MAX))
        #: nodes carried to a slave point: the facet's, and (smoothed) in 2D its two
        #: neighbours, in 3D the fans of its nodes (see the module's docstring)
        self.nx = self.nn
        if smoothed and self.V.mesh.geometry.dim == 2:
            self._ring, self._ring_flags = segment_neighbours(self.V.mesh.comm, self.global_nodes)
        elif smoothed:
            fans = node_fans(self.V.mesh.comm, self.global_nodes, self.nn, self.node_keys)
            self._ring = fans.reshape(len(fans), fans.shape[1] * fans.shape[2])
            self._ring_flags = np.zeros((len(fans), 0), dtype=bool)
        if smoothed:
            self.nx += int(self.V.mesh.comm.allreduce(self._ring.shape[1], MPI.MAX))
            #: the rows of the ring's nodes in the facets' nodes of all ranks (fixed)
            self._ring_rows = node_rows(self.V.mesh.comm, self.global_nodes, self._ring)
        self._fixed: tuple[StackedLayout, np.ndarray] | None = None

    def candidates(self, layout: StackedLayout) -> MasterCandidates:
        """This rank's facets at the current displacement (collective with ``smoothed``)."""
        comm = self.V.mesh.comm
        current = self.current_nodes()
        if self.smoothed:  # carry the neighbour nodes of every facet along
            gdim = current.shape[-1]
            everyone = current.reshape(-1, gdim)
            if comm.size > 1:
                everyone = np.concatenate(comm.allgather(everyone))
            ring = everyone[self._ring_rows].reshape(*self._ring.shape, gdim)
            current = np.concatenate([current, ring], axis=1)
        return MasterCandidates(current, self._table(layout))

    def _table(self, layout: StackedLayout) -> np.ndarray:
        """The fixed data of the facets side by side (:class:`MasterCandidates`): made once
        per layout."""
        if self._fixed is None or self._fixed[0] is not layout:
            global_nodes = self.global_nodes.astype(np.int64)
            flags = np.zeros((len(global_nodes), 0), dtype=np.int64)
            if self.smoothed:
                global_nodes = np.hstack([global_nodes, self._ring])
                flags = self._ring_flags.astype(np.int64)
            bs = self.V.dofmap.index_map_bs
            columns = layout.from_block_global(self.block, global_nodes * bs)
            keys, boundary = self.keys.astype(np.int64), self.boundary_edges.astype(np.int64)
            self._fixed = (layout, np.hstack([columns, keys, boundary, flags]))
        return self._fixed[1]

    def _build(self) -> None:
        mesh = self.V.mesh
        tdim, fdim = mesh.topology.dim, mesh.topology.dim - 1
        facets = tagged_facets(self.facet_tags, self.tag, "master")
        num_owned = mesh.topology.index_map(fdim).size_local
        facets = facets[facets < num_owned]
        cells, local = exterior_facet_cells(mesh, facets, "master")
        layout = self.V.dofmap.dof_layout
        reference_facets = basix.topology(basix_cell(mesh, tdim))[fdim]
        nv = len(reference_facets[0])
        # the vertex dofs of each reference facet (vertices come first in the closure)
        closure = np.array(
            [layout.entity_closure_dofs(fdim, f)[:nv] for f in range(len(reference_facets))]
        )
        cell_dofs = self.V.dofmap.list[cells]
        nodes = np.take_along_axis(cell_dofs, closure[local], axis=1)
        coords = self.V.tabulate_dof_coordinates()[:, : mesh.geometry.dim]
        X = coords[nodes]
        # orient: the normal must point away from the cell
        cell_centre = coords[cell_dofs].mean(axis=1)
        flip = np.einsum("fd,fd->f", facet_normals(X), X.mean(axis=1) - cell_centre) < 0.0
        swap = (0, 1) if nv == 2 else (1, 2)
        nodes[flip, swap[0]], nodes[flip, swap[1]] = nodes[flip, swap[1]], nodes[flip, swap[0]]
        geometry_nodes = np.take_along_axis(
            mesh.geometry.dofmaps[0][cells], np.array(reference_facets)[local], axis=1
        )
        if layout.num_dofs > len(basix.topology(basix_cell(mesh, tdim))[0]):
            vertices = np.array(reference_facets)[local]  # cell-local vertex numbers
            vertices[flip, swap[0]], vertices[flip, swap[1]] = (
                vertices[flip, swap[1]],
                vertices[flip, swap[0]],
            )
            nodes = np.hstack(
                [nodes, cell_dofs[np.arange(len(cells))[:, None], self._midpoints(vertices, local)]]
            )
        self._finish(nodes, geometry_nodes, flip, swap)

    def _midpoints(self, vertices: np.ndarray, local: np.ndarray) -> np.ndarray:
        """The cell-local dofs of the edge midpoints of quadratic facets of the oriented
        cell-local ``vertices`` ``(nf, nv)`` (local facets ``local``): of the segment's edge
        (2D); of the edges 01, 12 and 02 of a triangle; of the edges 01, 13, 23 and 02 of a
        quadrilateral, then its centre (the node orders of :mod:`.search.kinds`)."""
        mesh = self.V.mesh
        layout = self.V.dofmap.dof_layout
        edges = basix.topology(basix_cell(mesh, mesh.topology.dim))[1]
        nvc = len(basix.topology(basix_cell(mesh, mesh.topology.dim))[0])
        edge_of = np.full((nvc, nvc), -1, dtype=np.int64)
        for e, (i, j) in enumerate(edges):
            edge_of[i, j] = edge_of[j, i] = e
        edge_dof = np.array([layout.entity_dofs(1, e)[0] for e in range(len(edges))])
        nv = vertices.shape[1]
        pairs = {2: ((0, 1),), 3: ((0, 1), (1, 2), (0, 2)), 4: ((0, 1), (1, 3), (2, 3), (0, 2))}
        mids = [edge_dof[edge_of[vertices[:, i], vertices[:, j]]] for i, j in pairs[nv]]
        if nv == 4:  # the centre dof of the quadrilateral facet
            fdim = mesh.topology.dim - 1
            faces = basix.topology(basix_cell(mesh, mesh.topology.dim))[fdim]
            face_dof = np.array([layout.entity_dofs(fdim, f)[0] for f in range(len(faces))])
            mids.append(face_dof[local])
        return np.stack(mids, axis=1)

    def _finish(self, nodes, geometry_nodes, flip, swap) -> None:
        """Positions, global numbers, keys and boundary edges of the oriented facets of
        ``nodes`` (geometry nodes of their vertices before the orientation swap)."""
        self.nodes = nodes
        coords = self.V.tabulate_dof_coordinates()[:, : self.V.mesh.geometry.dim]
        self.X_nodes = coords[nodes]
        imap = self.V.dofmap.index_map
        self.global_nodes = imap.local_to_global(nodes.ravel().astype(np.int32)).reshape(
            nodes.shape
        )
        #: vertices of a facet (its first nodes; a quadratic facet's midpoint nodes follow)
        self.nv = geometry_nodes.shape[1]
        nodes = nodes[:, : self.nv]
        # a key of each facet independent of the partition and of rigid motions: the sorted
        # input (file) indices of its vertices, to break ties between equidistant facets
        node_keys = self.V.mesh.geometry.input_global_indices[geometry_nodes]
        self.keys = np.sort(node_keys, axis=1)
        # the input indices of the nodes, oriented like ``nodes``
        oriented = node_keys.copy()
        oriented[flip, swap[0]], oriented[flip, swap[1]] = (
            node_keys[flip, swap[1]],
            node_keys[flip, swap[0]],
        )
        self.node_keys = oriented
        self.boundary_edges = _boundary_edges(self.V.mesh.comm, oriented, nodes)

    def _build_membrane(self, orientation: dolfinx.fem.Function) -> None:
        """The master facets of a membrane (string): its tagged cells, ordered so that the
        normal of :mod:`.search.kinds` is the membrane's oriented normal ``n0``."""
        mesh = self.V.mesh
        tdim = mesh.topology.dim
        cells = tagged_facets(self.facet_tags, self.tag, "master")
        cells = cells[cells < mesh.topology.index_map(tdim).size_local]
        nv = len(basix.topology(basix_cell(mesh, tdim))[0])
        nodes = self.V.dofmap.list[cells][:, :nv].copy()  # P1: the vertex dofs, in cell order
        sign = orientation.x.array[orientation.function_space.dofmap.list[cells, 0]]
        flip = sign < 0.0
        swap = (0, 1) if nv == 2 else (1, 2)
        nodes[flip, swap[0]], nodes[flip, swap[1]] = nodes[flip, swap[1]], nodes[flip, swap[0]]
        self._finish(nodes, mesh.geometry.dofmaps[0][cells][:, :nv], flip, swap)

    @property
    def num_facets(self) -> int:
        """Owned master facets on this rank."""
        return len(self.nodes)

    def current_nodes(self) -> np.ndarray:
        """Current node positions ``(nf, nn, gdim)``."""
        bs = self.V.dofmap.index_map_bs
        return self.X_nodes + self.u.x.array.reshape(-1, bs)[self.nodes]


def _boundary_edges(comm: MPI.Comm, keys: np.ndarray, nodes: np.ndarray):
    """Which facet edges (end points in 2D) belong to one master facet only, over all ranks.

    ``keys`` are the input indices of the (oriented) facet nodes ``nodes``.
    """
    edges = FACET_EDGES[nodes.shape[1]]
    width = len(edges[0])
    local = np.stack([np.sort(keys[:, list(e)], axis=1) for e in edges], axis=1)  # (nf, ne, w)
    everything = np.concatenate(comm.allgather(local.reshape(-1, width)))
    unique, counts = np.unique(everything, axis=0, return_counts=True)
    once = unique[counts == 1]
    flat = local.reshape(-1, width)
    if len(once) == 0 or len(flat) == 0:
        return np.zeros(local.shape[:2], dtype=bool)
    return _rows_in(flat, once).reshape(local.shape[:2])


def _rows_in(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Which rows of the integer array ``a`` are rows of ``b`` (vectorised)."""
    row = np.dtype([("", a.dtype)] * a.shape[1])
    a_rows = np.ascontiguousarray(a).view(row).ravel()
    b_rows = np.ascontiguousarray(b.astype(a.dtype)).view(row).ravel()
    return np.isin(a_rows, b_rows)


def segment_neighbours(
    comm: MPI.Comm, global_nodes: np.ndarray
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.bool_]]:
    """The nodes before and after each oriented master segment (2D), over all ranks.

    Oriented segments ``(a, b)`` of one surface follow each other: the segment before ends at
    ``a``, the one after starts at ``b``. Returns, for each segment, the global node index of
    the node before ``a`` and of the node after ``b``, ``(nf, 2)``, and whether they exist
    (at an end of the surface the node itself stands in, flagged ``False``).
    """
    everything = np.concatenate(comm.allgather(global_nodes.astype(np.int64))).reshape(-1, 2)
    first, second = everything[:, 0], everything[:, 1]
    by_second, by_first = np.argsort(second), np.argsort(first)
    a, b = global_nodes[:, 0].astype(np.int64), global_nodes[:, 1].astype(np.int64)

    def lookup(keys, sorted_order, values, query):
        pos = np.searchsorted(keys[sorted_order], query)
        pos = np.minimum(pos, max(len(keys) - 1, 0))
        found = len(keys) > 0
        hit = keys[sorted_order][pos] == query if found else np.zeros(len(query), bool)
        return np.where(hit, values[sorted_order][pos], query), hit

    before, has_before = lookup(second, by_second, first, a)
    after, has_after = lookup(first, by_first, second, b)
    return np.stack([before, after], axis=1), np.stack([has_before, has_after], axis=1)


def node_fans(
    comm: MPI.Comm,
    global_nodes: np.ndarray,
    nodes_per_facet: int,
    node_keys: np.ndarray | None = None,
) -> npt.NDArray[np.int64]:
    """The fan of every node of the oriented 3D master facets, over all ranks.

    The fan of a node ``a`` lists its edge neighbours in cyclic order about the outward
    normal: ``s_0 = next(f_1)``, ``s_k = prev(f_k)`` for the facets ``f_1 .. f_v`` around
    ``a`` in turn, ``next``/``prev`` being the nodes after and before ``a`` in a facet's
    :data:`CYCLIC_ORDER` (the facet after ``f_k`` has ``next = prev(f_k)``). An open fan (a
    node on the boundary of the surface) starts at the facet with no facet before it; a
    closed fan starts at the neighbour of smallest key and ends with ``s_v = s_0``. The
    unused slots up to ``K`` hold ``a`` itself, ``K`` being the most facets around a node of
    the surface.

    Parameters
    ----------
    comm
        Communicator of the master surface.
    global_nodes
        Global index of the nodes of this rank's oriented facets, ``(nf, nodes_per_facet)``.
    nodes_per_facet
        Nodes of a facet (3 or 4).
    node_keys
        Keys of those nodes that do not depend on the partition (input indices), so that
        the fans, and the order of the sums over them, are the same on any number of ranks;
        default: the global indices.

    Returns
    -------
    ndarray, shape (nf, nodes_per_facet, K + 1)
        Global node index of the slots of the fan of each node of this rank's facets.
    """
    cyclic = list(CYCLIC_ORDER[nodes_per_facet])

    def corners_of_all_ranks(a: np.ndarray) -> np.ndarray:
        everything = np.concatenate(comm.allgather(a.astype(np.int64).reshape(-1)))
        return everything.reshape(-1, nodes_per_facet)[:, cyclic]

    ordered = corners_of_all_ranks(global_nodes)
    keys = corners_of_all_ranks(global_nodes if node_keys is None else node_keys)
    # the corners of all facets: node, the node after it and the node before it
    node = ordered.ravel()
    after = np.roll(ordered, -1, axis=1).ravel()
    after_key = np.roll(keys, -1, axis=1).ravel()
    before = np.roll(ordered, 1, axis=1).ravel()
    fan_nodes, counts = np.unique(node, return_counts=True)
    K = int(counts.max(initial=0))
    collective_check(
        comm,
        K <= MAX_FACETS_AROUND_NODE,
        f"a node of the master surface has {K} facets around it: the smoothed master normal "
        f"carries at most MAX_FACETS_AROUND_NODE = {MAX_FACETS_AROUND_NODE} "
        "(contact_ufl.contact.master)",
    )
    span = int(node.max(initial=0)) + 1
    find_after, unique_after = _lookup(node * span + after)
    collective_check(
        comm,
        unique_after,
        "the master surface is not a consistently oriented manifold (an edge is shared by "
        "more than two facets, or twice in the same direction): no smoothed normal",
    )
    find_before, _ = _lookup(node * span + before)
    # each fan starts at a corner with no corner before it (open fan), else at the corner
    # whose next neighbour has the smallest key
    _, has_before = find_before(node * span + after)
    by_node = np.lexsort((after_key, has_before, node))
    start = by_node[np.searchsorted(node[by_node], fan_nodes)]
    wanted = keysets.unique(global_nodes.astype(np.int64))
    index = np.searchsorted(fan_nodes, wanted)
    slots = np.repeat(wanted[:, None], K + 1, axis=1)
    if len(wanted):
        first, corner = start[index], start[index].copy()
        slots[:, 0] = after[corner]
        walking = np.ones(len(wanted), dtype=bool)
        walked = np.zeros(len(wanted), dtype=np.int64)
        for k in range(K):  # bounded by the fan size, vectorised over the nodes
            slots[walking, k + 1] = before[corner[walking]]
            walked += walking
            following, found = find_after(node[corner] * span + before[corner])
            walking &= found & (following != first)
            corner = np.where(walking, following, corner)
    complete = not len(wanted) or bool(np.all(walked == counts[index]))
    collective_check(
        comm,
        complete,
        "a node of the master surface has facets around it that do not form one fan (the "
        "surface is pinched there): no smoothed normal",
    )
    return slots[np.searchsorted(wanted, global_nodes.astype(np.int64))]


def _lookup(keys: np.ndarray):
    """A vectorised search of the integer ``keys``: returns a function that gives, for
    ``query``, the index of an equal key and whether there is one; and whether the keys are
    unique."""
    order = np.argsort(keys, kind="stable")
    ordered = keys[order]

    def find(query: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if len(keys) == 0:
            return np.zeros(len(query), dtype=np.int64), np.zeros(len(query), dtype=bool)
        pos = np.minimum(np.searchsorted(ordered, query), len(keys) - 1)
        return order[pos], ordered[pos] == query

    return find, bool(np.all(np.diff(ordered) != 0))


def node_rows(comm: MPI.Comm, global_nodes: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """The rows of the nodes ``wanted`` (global indices, any shape) in the nodes
    ``global_nodes`` of all ranks, in rank order (one row per node and entry of
    ``global_nodes``: the first that holds it), raveled."""
    keys = np.concatenate(comm.allgather(global_nodes.reshape(-1).astype(np.int64)))
    find, _ = _lookup(keys)  # a stable order: of equal keys, the first row is found
    return find(wanted.reshape(-1))[0]
