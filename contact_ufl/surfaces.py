"""Contact surfaces: the slave surface with its quadrature points, the master surface facets.

The slave surface S_oc^(1) is a submesh of the tagged facets. It carries the multipliers and
the per-quadrature-point data of the contact terms (quadrature elements on the submesh). The
master surface S_oc^(2) is a set of oriented facets whose nodes are displacement dofs; its
current geometry is interpolated from those nodes, so the closest-point projection and the
master virtual displacement U2*(Y) use one and the same surface.

Two facts of DOLFINx 0.11 fix the layout used here (see ``shared/dolfinx-0.11-notes.md``):

* a quadrature element on the submesh stores values at the quadrature points of each
  *submesh cell in its own reference orientation*, and a parent ``ds`` integral reads them
  in that order; so the slave points are computed from the submesh cells, and mapped into
  the parent cells through a vertex matching;
* a facet of the parent mesh is on the boundary of exactly one cell, owned by the rank that
  owns that cell.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import basix
import dolfinx
import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from contact_ufl.errors import collective_check


def _basix_cell(mesh: dolfinx.mesh.Mesh, dim: int) -> basix.CellType:
    topology = mesh.topology
    cell = topology.cell_type if dim == topology.dim else topology.entity_types[dim][0]
    return getattr(basix.CellType, cell.name)


def _coordinate_element(mesh: dolfinx.mesh.Mesh) -> basix.finite_element.FiniteElement:
    return mesh.ufl_domain().ufl_coordinate_element().basix_element


def _scalar_element(V: dolfinx.fem.FunctionSpace) -> basix.finite_element.FiniteElement:
    element = V.ufl_element()
    if element.num_sub_elements:
        element = element.sub_elements[0]
    return element.basix_element


def tagged_facets(facet_tags: dolfinx.mesh.MeshTags, tag: int, role: str) -> npt.NDArray[np.int32]:
    """Local facets carrying ``tag``; raise on every rank when no rank has any."""
    comm = facet_tags.topology.comm
    facets = facet_tags.find(tag)
    total = comm.allreduce(len(facets), op=MPI.SUM)
    known = comm.allreduce(set(np.unique(facet_tags.values).tolist()), op=MPI.BOR)
    collective_check(
        comm,
        total > 0,
        f"{role} surface: facet tag {tag} is empty or does not exist "
        f"(tags present: {sorted(known)})",
    )
    return facets


def exterior_facet_cells(
    mesh: dolfinx.mesh.Mesh, facets: npt.NDArray[np.int32], role: str
) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.int32]]:
    """The (cell, local facet) of boundary facets; raise if a facet is interior."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    mesh.topology.create_connectivity(tdim, tdim - 1)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    c2f = mesh.topology.connectivity(tdim, tdim - 1)
    offsets = f2c.offsets
    ncells = offsets[facets + 1] - offsets[facets]
    collective_check(
        mesh.comm,
        bool(np.all(ncells == 1)),
        f"{role} surface: {int(np.sum(ncells != 1))} tagged facets are interior facets "
        "(a contact surface must be on the boundary of its body)",
    )
    cells = f2c.array[offsets[facets]]
    nfc = c2f.offsets[1] - c2f.offsets[0]
    cell_facets = c2f.array.reshape(-1, nfc)[cells]
    local = np.argmax(cell_facets == facets[:, None], axis=1).astype(np.int32)
    return cells.astype(np.int32), local


#: Quadrature rules of the contact integrals, by name.
QUADRATURE_RULES = {"gauss": basix.QuadratureType.default, "lobatto": basix.QuadratureType.gll}


def composite_quadrature(
    cell: basix.CellType, degree: int, subdivisions: int = 1, rule: str = "gauss"
) -> tuple[np.ndarray, np.ndarray]:
    """A rule of ``degree`` repeated on a uniform ``subdivisions``-fold split of ``cell``.

    A master facet edge inside a slave facet puts a kink into the contact integrand, which
    one Gauss rule integrates only to O(1/n^2); a composite rule bounds the kink's error by
    the size of one sub-cell. ``rule`` is a key of :data:`QUADRATURE_RULES`; the Lobatto
    rule (intervals and quadrilaterals) has points on the vertices of the (sub-)cells.
    """
    if rule == "lobatto" and cell == basix.CellType.triangle:
        raise ValueError("the Lobatto contact rule needs interval or quadrilateral facets")
    points, weights = basix.make_quadrature(cell, degree, rule=QUADRATURE_RULES[rule])
    points = np.clip(points, 0.0, 1.0)  # GLL end points come with round-off outside [0, 1]
    m = subdivisions
    if m == 1:
        return points, weights
    if cell == basix.CellType.interval:
        corners = np.arange(m)[:, None, None] / m  # (m, 1, 1)
        sub = corners + points[None] / m
    elif cell == basix.CellType.quadrilateral:
        i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
        corners = np.stack([i.ravel(), j.ravel()], axis=1)[:, None, :] / m
        sub = corners + points[None] / m
    elif cell == basix.CellType.triangle:
        i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
        up = (i + j < m).ravel()
        down = (i + j < m - 1).ravel()
        ij = np.stack([i.ravel(), j.ravel()], axis=1).astype(float)
        e0, e1 = np.array([1.0, 0.0]), np.array([0.0, 1.0])
        v_up = [ij[up], ij[up] + e0, ij[up] + e1]
        v_down = [ij[down] + e0 + e1, ij[down] + e1, ij[down] + e0]
        v = [np.vstack([a, b]) / m for a, b in zip(v_up, v_down, strict=True)]
        sub = (
            v[0][:, None, :]
            + points[None, :, :1] * (v[1] - v[0])[:, None, :]
            + points[None, :, 1:] * (v[2] - v[0])[:, None, :]
        )
    else:
        raise ValueError(f"no composite rule on {cell}")
    nsub = sub.shape[0]
    return sub.reshape(-1, points.shape[1]), np.tile(weights, nsub) / nsub


@dataclass
class SlaveSurface:
    """The slave contact surface and its quadrature points.

    Parameters
    ----------
    V
        Displacement space of the (parent) mesh.
    facet_tags
        Facet tags of the mesh.
    tag
        Tag of the slave facets.
    quadrature_degree
        Degree of the quadrature rule of the contact integrals.
    subdivisions
        Repeat that rule on a uniform split of each facet into this many parts per edge.
    rule
        ``"gauss"`` or ``"lobatto"`` (:data:`QUADRATURE_RULES`).

    Attributes
    ----------
    submesh, entity_map
        The facet submesh and its map to the parent mesh.
    points_ref
        Reference coordinates of the quadrature points in the submesh cell, ``(nq, fdim)``.
    parent_cells
        Parent cell of each owned submesh cell.
    X
        Reference (undeformed) positions of the quadrature points, ``(ncells, nq, gdim)``.
    """

    V: dolfinx.fem.FunctionSpace
    facet_tags: dolfinx.mesh.MeshTags
    tag: int
    quadrature_degree: int
    subdivisions: int = 1
    rule: str = "gauss"
    submesh: dolfinx.mesh.Mesh = field(init=False)
    entity_map: dolfinx.mesh.EntityMap = field(init=False)

    def __post_init__(self) -> None:
        mesh = self.V.mesh
        tdim, fdim = mesh.topology.dim, mesh.topology.dim - 1
        facets = tagged_facets(self.facet_tags, self.tag, "slave")
        cells, local = exterior_facet_cells(mesh, facets, "slave")
        self.submesh, self.entity_map = dolfinx.mesh.create_submesh(mesh, fdim, facets)[:2]
        num_owned = self.submesh.topology.index_map(fdim).size_local
        sub_cells = np.arange(num_owned, dtype=np.int32)
        parent = self.entity_map.sub_topology_to_topology(sub_cells, inverse=False)
        order = np.argsort(facets)
        pos = order[np.searchsorted(facets, parent, sorter=order)]
        self.parent_cells = cells[pos]
        parent_local = local[pos]

        sub_cell = _basix_cell(self.submesh, fdim)
        self.points_ref, self.weights_ref = composite_quadrature(
            sub_cell, self.quadrature_degree, self.subdivisions, self.rule
        )
        self.num_points = len(self.weights_ref)
        ref = self._parent_reference_points(sub_cell, parent_local, tdim)
        self._ref = ref
        nc, nq = len(self.parent_cells), self.num_points
        flat = ref.reshape(-1, tdim)
        cmap = _coordinate_element(mesh)
        phi_geom = cmap.tabulate(0, flat)[0, :, :, 0]
        phi_geom = phi_geom.reshape(nc, nq, phi_geom.shape[-1])
        xg = mesh.geometry.x[mesh.geometry.dofmaps[0][self.parent_cells], : mesh.geometry.dim]
        self.X = np.einsum("cqn,cnd->cqd", phi_geom, xg)
        nv = len(basix.topology(sub_cell)[0])
        vertices = self.submesh.geometry.x[
            self.submesh.geometry.dofmaps[0][:nc, :nv], : mesh.geometry.dim
        ]
        self.normals = outward_normals(vertices, xg.mean(axis=1))
        tab_u = _scalar_element(self.V).tabulate(1, flat)[..., 0]  # (1 + tdim, npts, ndofs)
        self._phi_u = tab_u[0].reshape(nc, nq, tab_u.shape[-1])
        # reference gradients of the displacement basis: Grad phi = J^-T grad_xi phi
        dgeom = cmap.tabulate(1, flat)[1:, :, :, 0]
        dgeom = dgeom.reshape(tdim, nc, nq, dgeom.shape[-1])
        jac = np.einsum("kcqn,cnd->cqdk", dgeom, xg)  # dX/dxi, (nc, nq, gdim, tdim)
        dphi = tab_u[1:].reshape(tdim, nc, nq, tab_u.shape[-1])
        self._grad_phi_u = np.einsum("cqkd,kcqn->cqnd", np.linalg.inv(jac), dphi)
        self._cell_dofs = self.V.dofmap.list[self.parent_cells]

    def _parent_reference_points(self, sub_cell, parent_local, tdim) -> np.ndarray:
        """Map the submesh quadrature points into the parent reference cells.

        The submesh cell's vertices are a permutation of its parent facet's vertices; matching
        them by position gives an affine map between the two reference facets.
        """
        mesh = self.V.mesh
        gdim, fdim = mesh.geometry.dim, tdim - 1
        parent_cell = _basix_cell(mesh, tdim)
        ref_vertices = basix.geometry(parent_cell)
        facet_vertices = np.array(basix.topology(parent_cell)[fdim])  # (nfacets, nv)
        nv = facet_vertices.shape[1]
        # vertex positions of the parent facets (geometry nodes = first nodes are vertices)
        cell_nodes = mesh.geometry.dofmaps[0][self.parent_cells]
        local_vertices = facet_vertices[parent_local]  # (nc, nv)
        xpar = mesh.geometry.x[np.take_along_axis(cell_nodes, local_vertices, axis=1), :gdim]
        sub_nodes = self.submesh.geometry.dofmaps[0][: len(self.parent_cells), :nv]
        xsub = self.submesh.geometry.x[sub_nodes, :gdim]
        dist = np.linalg.norm(xsub[:, :, None, :] - xpar[:, None, :, :], axis=-1)
        perm = np.argmin(dist, axis=2)  # sub vertex i == parent facet vertex perm[i]
        vert_ref = ref_vertices[np.take_along_axis(local_vertices, perm, axis=1)]  # (nc, nv, tdim)
        p1 = basix.create_element(basix.ElementFamily.P, sub_cell, 1)
        phi = p1.tabulate(0, self.points_ref)[0, :, :, 0]  # (nq, nv)
        return np.einsum("qv,cvd->cqd", phi, vert_ref)

    @property
    def num_cells(self) -> int:
        """Owned submesh cells (slave facets) on this rank."""
        return len(self.parent_cells)

    def displacement(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Displacement at the quadrature points, ``(ncells, nq, gdim)``."""
        bs = self.V.dofmap.index_map_bs
        values = u.x.array.reshape(-1, bs)[self._cell_dofs]  # (nc, ndofs, gdim)
        return np.einsum("cqn,cnd->cqd", self._phi_u, values)

    def deformation_gradient(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Deformation gradient at the quadrature points, ``(ncells, nq, gdim, gdim)``."""
        bs = self.V.dofmap.index_map_bs
        values = u.x.array.reshape(-1, bs)[self._cell_dofs]
        grad_u = np.einsum("cnd,cqnk->cqdk", values, self._grad_phi_u)
        return grad_u + np.eye(bs)

    def area_ratio(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Current over reference area ``da/dA = J |F^-T N|`` at the points, ``(ncells, nq)``."""
        F = self.deformation_gradient(u)
        N = np.broadcast_to(self.normals[:, None, :], F.shape[:-1])
        FinvT_N = np.linalg.solve(np.swapaxes(F, -1, -2), N[..., None])[..., 0]
        return np.linalg.det(F) * np.linalg.norm(FinvT_N, axis=-1)

    def positions(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Current positions x = X + u of the quadrature points, ``(ncells, nq, gdim)``."""
        return self.X + self.displacement(u)

    def bounding_box(self, x: np.ndarray, comm: MPI.Comm) -> np.ndarray:
        """Bounding box ``(2, gdim)`` of the points of this rank (inverted if none)."""
        gdim = self.V.mesh.geometry.dim
        if x.size == 0:
            return np.vstack([np.full(gdim, np.inf), np.full(gdim, -np.inf)])
        pts = x.reshape(-1, gdim)
        return np.vstack([pts.min(axis=0), pts.max(axis=0)])


@dataclass
class MasterSurface:
    """The master contact surface: oriented facets whose nodes are displacement dofs.

    Facet nodes are the vertices of the facets (linear segments, triangles, bilinear
    quadrilaterals), ordered so that the normal of ``contact_ufl.projection`` points out of
    the master body.

    Attributes
    ----------
    nodes
        Local block index (displacement dof block) of each facet node, ``(nf, nn)``.
    X_nodes
        Reference positions of the nodes, ``(nf, nn, gdim)``.
    global_nodes
        Global block index of each node in the displacement index map, ``(nf, nn)``.
    keys
        Sorted input (mesh file) indices of the vertices of each facet, ``(nf, nn)``: the
        same on any number of ranks and in any rigidly moved copy of the scene.
    boundary_edges
        For each facet, which of its :data:`FACET_EDGES` lie on the boundary of the master
        surface (2D: which of its two nodes are end points of the surface), ``(nf, ne)``.
    """

    V: dolfinx.fem.FunctionSpace
    facet_tags: dolfinx.mesh.MeshTags
    tag: int

    def __post_init__(self) -> None:
        mesh = self.V.mesh
        tdim, fdim = mesh.topology.dim, mesh.topology.dim - 1
        facets = tagged_facets(self.facet_tags, self.tag, "master")
        num_owned = mesh.topology.index_map(fdim).size_local
        facets = facets[facets < num_owned]
        cells, local = exterior_facet_cells(mesh, facets, "master")
        layout = self.V.dofmap.dof_layout
        reference_facets = basix.topology(_basix_cell(mesh, tdim))[fdim]
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
        flip = np.einsum("fd,fd->f", _facet_normals(X), X.mean(axis=1) - cell_centre) < 0.0
        swap = (0, 1) if nv == 2 else (1, 2)
        nodes[flip, swap[0]], nodes[flip, swap[1]] = nodes[flip, swap[1]], nodes[flip, swap[0]]
        self.nodes = nodes
        self.X_nodes = coords[nodes]
        imap = self.V.dofmap.index_map
        self.global_nodes = imap.local_to_global(nodes.ravel().astype(np.int32)).reshape(
            nodes.shape
        )
        # a key of each facet independent of the partition and of rigid motions: the sorted
        # input (file) indices of its vertices, to break ties between equidistant facets
        geometry_nodes = np.take_along_axis(
            mesh.geometry.dofmaps[0][cells], np.array(reference_facets)[local], axis=1
        )
        node_keys = mesh.geometry.input_global_indices[geometry_nodes]
        self.keys = np.sort(node_keys, axis=1)
        self.boundary_edges = _boundary_edges(self.V.mesh.comm, node_keys, nodes, flip, swap)

    @property
    def num_facets(self) -> int:
        """Owned master facets on this rank."""
        return len(self.nodes)

    def current_nodes(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Current node positions ``(nf, nn, gdim)``."""
        bs = self.V.dofmap.index_map_bs
        return self.X_nodes + u.x.array.reshape(-1, bs)[self.nodes]


def _facet_normals(X: np.ndarray) -> np.ndarray:
    """Un-normalised normals of oriented facets under the projection's conventions."""
    if X.shape[1] == 2:
        a = X[:, 1] - X[:, 0]
        return np.stack([a[:, 1], -a[:, 0]], axis=1)
    if X.shape[1] == 3:
        return np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    return np.cross(X[:, 1] - X[:, 0] + X[:, 3] - X[:, 2], X[:, 2] - X[:, 0] + X[:, 3] - X[:, 1])


def outward_normals(vertices: np.ndarray, cell_centres: np.ndarray) -> np.ndarray:
    """Unit normals of facets given by their vertices, pointing away from their cells."""
    n = _facet_normals(vertices)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    sign = np.sign(np.einsum("fd,fd->f", n, vertices.mean(axis=1) - cell_centres))
    return n * sign[:, None]


def global_bounds(comm: MPI.Comm, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners of the bounding box of ``points`` ``(n, gdim)`` of all ranks."""
    gdim = points.shape[1]
    lo = points.min(axis=0) if len(points) else np.full(gdim, np.inf)
    hi = points.max(axis=0) if len(points) else np.full(gdim, -np.inf)
    glo, ghi = np.empty(gdim), np.empty(gdim)
    comm.Allreduce(np.ascontiguousarray(lo, dtype=float), glo, op=MPI.MIN)
    comm.Allreduce(np.ascontiguousarray(hi, dtype=float), ghi, op=MPI.MAX)
    return glo, ghi


#: Edges of a master facet by its (oriented) node numbers: the end points of a segment, the
#: edges of a triangle and of a bilinear quadrilateral (basix vertex order).
FACET_EDGES = {2: [(0,), (1,)], 3: [(0, 1), (0, 2), (1, 2)], 4: [(0, 1), (0, 2), (1, 3), (2, 3)]}


def _boundary_edges(comm: MPI.Comm, node_keys: np.ndarray, nodes: np.ndarray, flip, swap):
    """Which facet edges (end points in 2D) belong to one master facet only, over all ranks.

    ``node_keys`` are the input indices of the facet nodes before the orientation swap
    ``swap`` applied to the facets ``flip``; they are swapped the same way here.
    """
    keys = node_keys.copy()
    keys[flip, swap[0]], keys[flip, swap[1]] = node_keys[flip, swap[1]], node_keys[flip, swap[0]]
    nn = nodes.shape[1]
    edges = FACET_EDGES[nn]
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


def gathered_node_positions(
    comm: MPI.Comm, global_nodes: np.ndarray, positions: np.ndarray, wanted: np.ndarray
) -> np.ndarray:
    """Positions of the nodes ``wanted`` (global indices, any shape) from the nodes
    ``global_nodes`` with ``positions`` (``(..., gdim)``) of all ranks."""
    gdim = positions.shape[-1]
    keys = np.concatenate(comm.allgather(global_nodes.reshape(-1).astype(np.int64)))
    values = np.concatenate(comm.allgather(positions.reshape(-1, gdim)))
    keys, first = np.unique(keys, return_index=True)
    pos = np.searchsorted(keys, wanted.reshape(-1))
    return values[first][pos].reshape(*wanted.shape, gdim)
