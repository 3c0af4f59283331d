"""The slave side of a contact pair: the slave surface, its quadrature points and the data
carried at them.

The slave surface S_oc^(1) is a submesh of the tagged facets. It carries the multipliers (P1
on the submesh) and the per-quadrature-point data of the contact terms (quadrature elements
on the submesh).

Two facts of DOLFINx 0.11 fix the layout used here:

* a quadrature element on the submesh stores values at the quadrature points of each
  *submesh cell in its own reference orientation*, and a parent ``ds`` integral reads them
  in that order; so the slave points are computed from the submesh cells, and mapped into
  the parent cells through a vertex matching;
* a facet of the parent mesh is on the boundary of exactly one cell, owned by the rank that
  owns that cell.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import basix
import basix.ufl
import dolfinx
import numpy as np
import scipy.sparse
import ufl
from mpi4py import MPI
from scipy.spatial import cKDTree

from contact_ufl import jit, keysets
from contact_ufl.contact.facets import (
    basix_cell,
    coordinate_element,
    exterior_facet_cells,
    facet_normals,
    outward_normals,
    scalar_element,
    tagged_facets,
)
from contact_ufl.contact.quadrature import composite_quadrature, iso_subdivisions
from contact_ufl.errors import collective_check

#: The value of ``ContactPair.multiplier_degree`` that asks for P1-iso-P2 multipliers.
ISO_MULTIPLIER = "iso"
#: The values of ``ContactPair.multiplier_degree``.
MULTIPLIER_DEGREES = (1, 2, ISO_MULTIPLIER)


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
    multiplier_degree
        The continuous multiplier space on the submesh: Lagrange of degree 1 or 2, or
        ``"iso"``: P1-iso-P2, piecewise linear on the once-refined cells, with the dofs of P2
        (:data:`ISO_MULTIPLIER`). With ``"iso"`` the contact rule is composite over the
        refined cells: ``subdivisions`` is rounded up to an even number.

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
    vertex_keys
        Input (mesh file) indices of the vertices of each owned slave facet, ``(ncells,
        nv)``: the numbering of :attr:`MeshMaster.keys <.master.MeshMaster.keys>`.
    """

    V: dolfinx.fem.FunctionSpace
    facet_tags: dolfinx.mesh.MeshTags
    tag: int
    quadrature_degree: int
    subdivisions: int = 1
    rule: str = "gauss"
    multiplier_degree: int | str = 1
    submesh: dolfinx.mesh.Mesh = field(init=False)
    entity_map: dolfinx.mesh.EntityMap = field(init=False)

    def __post_init__(self) -> None:
        mesh = self.V.mesh
        tdim = mesh.topology.dim
        #: whether the surface is a membrane's (string's) cells rather than facets of a solid
        self.membrane = self.facet_tags.dim == tdim
        sdim = self.facet_tags.dim
        entities = tagged_facets(self.facet_tags, self.tag, "slave")
        submesh = dolfinx.mesh.create_submesh(mesh, sdim, entities)
        self.submesh, self.entity_map, self._vertex_map = submesh[:3]
        num_owned = self.submesh.topology.index_map(sdim).size_local
        sub_cells = np.arange(num_owned, dtype=np.int32)
        parent = self.entity_map.sub_topology_to_topology(sub_cells, inverse=False)
        parent_cell = basix_cell(mesh, tdim)
        if self.membrane:
            self.parent_cells = parent
            nv = len(basix.topology(parent_cell)[0])
            local_vertices = np.tile(np.arange(nv), (len(parent), 1))
        else:
            cells, local = exterior_facet_cells(mesh, entities, "slave")
            order = np.argsort(entities)
            pos = order[np.searchsorted(entities, parent, sorter=order)]
            self.parent_cells = cells[pos]
            facet_vertices = np.array(basix.topology(parent_cell)[tdim - 1])
            local_vertices = facet_vertices[local[pos]]

        sub_cell = basix_cell(self.submesh, sdim)
        if self.iso:  # composite over the refined cells, where the multipliers are linear
            self.subdivisions = iso_subdivisions(self.subdivisions)
        self.points_ref, self.weights_ref = composite_quadrature(
            sub_cell, self.quadrature_degree, self.subdivisions, self.rule
        )
        self.num_points = len(self.weights_ref)
        ref = self._parent_reference_points(sub_cell, local_vertices, tdim)
        self._ref = ref
        nc, nq = len(self.parent_cells), self.num_points
        flat = ref.reshape(-1, tdim)
        cmap = coordinate_element(mesh)
        phi_geom = cmap.tabulate(0, flat)[0, :, :, 0]
        phi_geom = phi_geom.reshape(nc, nq, phi_geom.shape[-1])
        xg = mesh.geometry.x[mesh.geometry.dofmaps[0][self.parent_cells], : mesh.geometry.dim]
        self.X = np.einsum("cqn,cnd->cqd", phi_geom, xg)
        # the input (mesh file) indices of each facet's vertices: the numbering of the master
        # facets' keys, rank-independent (a self-contact search excludes a point's own facet)
        geometry_vertices = np.take_along_axis(
            mesh.geometry.dofmaps[0][self.parent_cells], local_vertices, axis=1
        )
        self.vertex_keys = mesh.geometry.input_global_indices[geometry_vertices].astype(np.int64)
        nv = len(basix.topology(sub_cell)[0])
        vertices = self.submesh.geometry.x[
            self.submesh.geometry.dofmaps[0][:nc, :nv], : mesh.geometry.dim
        ]
        if self.membrane:  # the normals of the vertex order: a membrane has two sides
            n = facet_normals(vertices)
            self.normals = n / np.linalg.norm(n, axis=1, keepdims=True)
        else:
            self.normals = outward_normals(vertices, xg.mean(axis=1))
        tab_u = scalar_element(self.V).tabulate(1, flat)[..., 0]  # (1 + tdim, npts, ndofs)
        self._phi_u = tab_u[0].reshape(nc, nq, tab_u.shape[-1])
        # reference gradients of the displacement basis: Grad phi = J^-T grad_xi phi
        dgeom = cmap.tabulate(1, flat)[1:, :, :, 0]
        dgeom = dgeom.reshape(tdim, nc, nq, dgeom.shape[-1])
        jac = np.einsum("kcqn,cnd->cqdk", dgeom, xg)  # dX/dxi, (nc, nq, gdim, tdim)
        dphi = tab_u[1:].reshape(tdim, nc, nq, tab_u.shape[-1])
        # (a membrane: the pseudo-inverse, the tangential gradient as UFL's on a manifold)
        inverse = np.linalg.pinv(jac) if self.membrane else np.linalg.inv(jac)
        self._grad_phi_u = np.einsum("cqkd,kcqn->cqnd", inverse, dphi)
        self._cell_dofs = self.V.dofmap.list[self.parent_cells]
        #: the contact measure: the parent ``ds`` over the slave facets (``dx`` over the
        #: cells of a membrane), with the rule's degree; with P1-iso-P2 multipliers the
        #: composite rule of the slave points itself, also in forms without point data
        #: (which would otherwise integrate the multipliers' kinks with one Gauss rule)
        metadata = {"quadrature_degree": self.quadrature_degree}
        if self.iso:  # as tuples: UFL's form signature (the JIT cache key) has every value
            metadata |= {
                "quadrature_rule": "custom",
                "quadrature_points": tuple(map(tuple, self.points_ref.tolist())),
                "quadrature_weights": tuple(self.weights_ref.tolist()),
            }
        self.ds = ufl.Measure(
            "dx" if self.membrane else "ds",
            domain=mesh,
            subdomain_data=self.facet_tags,
            subdomain_id=self.tag,
            metadata=metadata,
        )
        #: the space of the multiplier nodes on the slave submesh: continuous Lagrange of
        #: degree 1 (default) or 2, or P1-iso-P2 (:meth:`multiplier_element`)
        self.multiplier_space = dolfinx.fem.functionspace(self.submesh, self.multiplier_element())
        p1 = self.multiplier_space.ufl_element().basix_element
        self._phi_p1 = p1.tabulate(0, self.points_ref)[0, :, :, 0]  # (nq, nv)
        # which points lie in the support of each node function of a cell (P1-iso-P2: only
        # the refined cells around the node; Lagrange: the whole cell)
        self._support = self._phi_p1 > 1e-12 if self.iso else np.ones_like(self._phi_p1, bool)

    @property
    def iso(self) -> bool:
        """Whether the multipliers are P1-iso-P2 (``multiplier_degree="iso"``)."""
        return self.multiplier_degree == ISO_MULTIPLIER

    def multiplier_element(self, shape: tuple[int, ...] = ()) -> basix.ufl._ElementBase:
        """The element of the multipliers (values of ``shape``) on the slave submesh:
        Lagrange of ``multiplier_degree``, or P1-iso-P2 (basix's ``iso`` family of degree 1:
        the dofs of P2, linear on each of the cell's once-refined sub-cells)."""
        cell = self.submesh.basix_cell()
        if self.iso:
            return basix.ufl.element(basix.ElementFamily.iso, cell, 1, shape=shape)
        return basix.ufl.element("Lagrange", cell, self.multiplier_degree, shape=shape)

    def _parent_reference_points(self, sub_cell, local_vertices, tdim) -> np.ndarray:
        """Map the submesh quadrature points into the parent reference cells.

        The submesh cell's vertices are a permutation of its parent facet's (cell's, for a
        membrane) vertices ``local_vertices`` ``(nc, nv)`` (local vertex numbers in the parent
        cell); matching them by position gives an affine map between the two reference
        entities.
        """
        mesh = self.V.mesh
        gdim = mesh.geometry.dim
        parent_cell = basix_cell(mesh, tdim)
        ref_vertices = basix.geometry(parent_cell)
        nv = local_vertices.shape[1]
        # vertex positions of the parent facets (geometry nodes = first nodes are vertices)
        cell_nodes = mesh.geometry.dofmaps[0][self.parent_cells]
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
    def P1(self) -> dolfinx.fem.FunctionSpace:
        """The multiplier space (:attr:`multiplier_space`; by the name of its default degree
        1)."""
        return self.multiplier_space

    @property
    def num_cells(self) -> int:
        """Owned submesh cells (slave facets) on this rank."""
        return len(self.parent_cells)

    def displacement(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Displacement at the quadrature points, ``(ncells, nq, gdim)``."""
        bs = self.V.dofmap.index_map_bs
        values = self._interpolation @ u.x.array.reshape(-1, bs)  # (npoints, gdim)
        return values.reshape(*self._phi_u.shape[:2], bs)

    @functools.cached_property
    def _interpolation(self) -> scipy.sparse.csr_array:
        """The values of the displacement basis at the points, ``(npoints, nblocks)``: a
        point's row holds those of its cell's dofs, in their cell order (zeros included, so
        that a non-finite value anywhere in the cell reaches the point), so that ``P @ u``
        sums as the cell's basis does; several times faster than gathering the cells'
        values and multiplying per cell."""
        nc, nq, nd = self._phi_u.shape
        columns = np.repeat(self._cell_dofs, nq, axis=0).ravel()
        blocks = self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts
        starts = np.arange(0, nc * nq * nd + 1, nd)  # nd entries a point
        P = scipy.sparse.csr_array((self._phi_u.ravel(), columns, starts), shape=(nc * nq, blocks))
        P.has_sorted_indices = False  # keep the cell order: no sorting, no summing
        return P

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

    def current_normals(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Current unit normals ``F^-T N / |F^-T N|`` at the points, ``(npoints, gdim)``
        (of a membrane: on the side of its vertex-order normal)."""
        F = self.deformation_gradient(u)
        N = np.broadcast_to(self.normals[:, None, :], F.shape[:-1])
        n = np.linalg.solve(np.swapaxes(F, -1, -2), N[..., None])[..., 0]
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        return n.reshape(-1, F.shape[-1])

    def positions(self, u: dolfinx.fem.Function) -> np.ndarray:
        """Current positions x = X + u of the quadrature points, ``(ncells, nq, gdim)``."""
        return self.X + self.displacement(u)

    def bounding_box(self, x: np.ndarray, comm: MPI.Comm) -> np.ndarray:
        """Bounding box ``(2, gdim)`` of the points of this rank (inverted if none)."""
        gdim = self.V.mesh.geometry.dim
        if x.size == 0:
            return np.vstack([np.full(gdim, np.inf), np.full(gdim, -np.inf)])
        columns = np.ascontiguousarray(x.reshape(-1, gdim).T)  # NumPy reduces rows slowly
        return np.vstack([columns.min(axis=1), columns.max(axis=1)])

    @functools.cached_property
    def facet_size(self) -> float:
        """Mean diameter of the slave facets over all ranks (the slave mesh size)."""
        gdim = self.V.mesh.geometry.dim
        nodes = self.submesh.geometry.dofmaps[0][: self.num_cells]
        x = self.submesh.geometry.x[nodes, :gdim]  # (nc, nv, gdim)
        diameters = np.linalg.norm(x[:, :, None] - x[:, None, :], axis=-1).max(axis=(1, 2))
        comm = self.V.mesh.comm
        total, count = comm.allreduce(np.array([diameters.sum(), len(diameters)]), MPI.SUM)
        return float(total / count)

    @functools.cached_property
    def point_weights(self) -> np.ndarray:
        """The reference measure of each owned slave point, ``(ncells * nq,)``: the rule's
        weights times the measure of the straight cell through the vertices of the point's
        facet over that of the reference cell (exact on flat facets)."""
        gdim = self.V.mesh.geometry.dim
        nodes = self.submesh.geometry.dofmaps[0][: self.num_cells]
        x = self.submesh.geometry.x[nodes, :gdim]  # the vertices come first
        if self.submesh.topology.dim == 1:
            measure = np.linalg.norm(x[:, 1] - x[:, 0], axis=-1)
        else:  # half the cross product of the edges (triangle) or diagonals (quadrilateral)
            if self.submesh.basix_cell() == basix.CellType.quadrilateral:
                a, b = x[:, 3] - x[:, 0], x[:, 2] - x[:, 1]
            else:
                a, b = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
            measure = 0.5 * np.linalg.norm(np.cross(a, b), axis=-1)
        reference = self.weights_ref.sum()  # the reference cell's measure
        return (measure[:, None] * self.weights_ref[None, :] / reference).ravel()

    # -- data at the slave points: quadrature elements on the submesh -------------------
    def point_space(self, shape: tuple[int, ...]) -> dolfinx.fem.FunctionSpace:
        """A space of values of ``shape`` at the slave quadrature points (quadrature element)."""
        element = basix.ufl.quadrature_element(
            self.submesh.basix_cell(),
            value_shape=shape,
            points=self.points_ref,
            weights=self.weights_ref,
        )
        return dolfinx.fem.functionspace(self.submesh, element)

    def _owned_blocks(self, Q: dolfinx.fem.FunctionSpace) -> np.ndarray:
        return Q.dofmap.list[: self.num_cells].ravel()

    def set_at_points(self, f: dolfinx.fem.Function, values: np.ndarray) -> None:
        """Set the point function ``f`` to ``values`` ``(npoints, ...)`` at the owned points,
        and update its ghosts."""
        bs = f.function_space.dofmap.index_map_bs
        f.x.array.reshape(-1, bs)[self._owned_blocks(f.function_space)] = values.reshape(-1, bs)
        f.x.scatter_forward()

    def at_points(self, f: dolfinx.fem.Function) -> np.ndarray:
        """Values of the point function ``f`` at the owned points, ``(npoints, bs)``."""
        bs = f.function_space.dofmap.index_map_bs
        return f.x.array.reshape(-1, bs)[self._owned_blocks(f.function_space)]

    def unrolled(self, Q: dolfinx.fem.FunctionSpace, values: np.ndarray, fill) -> np.ndarray:
        """``values`` ``(npoints, bs, ...)`` of the owned points as an array over the owned
        dofs of the point space ``Q`` (unrolled, local order; then the trailing axes of
        ``values``), ``fill`` at dofs of no owned point."""
        bs = Q.dofmap.index_map_bs
        rest = values.shape[2:]
        out = np.full((Q.dofmap.index_map.size_local, bs, *rest), fill, dtype=values.dtype)
        out[self._owned_blocks(Q)] = values.reshape(len(values), bs, *rest)
        return out.reshape(len(out) * bs, *rest)

    # -- the multiplier nodes (P1 on the submesh) ----------------------------------------
    def p1_at_points(self, f: dolfinx.fem.Function) -> np.ndarray:
        """A P1 function (scalar or vector) of the submesh at the owned points, ``(npoints,)``
        or ``(npoints, bs)``."""
        bs = f.function_space.dofmap.index_map_bs
        dofs = f.function_space.dofmap.list[: self.num_cells]
        values = f.x.array.reshape(-1, bs)[dofs]  # (nc, nv, bs)
        at_points = np.einsum("qn,cnd->cqd", self._phi_p1, values).reshape(-1, bs)
        return at_points[:, 0] if f.ufl_shape == () else at_points

    def assemble_nodal(self, form: dolfinx.fem.Form, space: dolfinx.fem.FunctionSpace):
        """Assemble the linear ``form`` over a P1 ``space`` of the submesh; the owned and ghost
        values, accumulated."""
        f = dolfinx.fem.Function(space)
        dolfinx.fem.assemble_vector(f.x.array, form)
        f.x.scatter_reverse(dolfinx.la.InsertMode.add)
        return f.x.array

    @functools.cached_property
    def nodal_mass(self) -> np.ndarray:
        """``int phi_i dS_o`` of the owned multiplier nodes (the reference surface)."""
        form = jit.form(ufl.TestFunction(self.P1) * self.ds, entity_maps=[self.entity_map])
        return self.assemble_nodal(form, self.P1)[: self.P1.dofmap.index_map.size_local].copy()

    def node_blocks(self) -> np.ndarray:
        """For each owned multiplier node, the local dof block (node) of the parent
        displacement at the same vertex, ``(n,)``."""
        if self.multiplier_degree != 1:
            return self._node_blocks_by_position()
        mesh, sdim = self.V.mesh, self.submesh.topology.dim
        tdim = mesh.topology.dim
        nv = self._phi_p1.shape[1]
        self.submesh.topology.create_connectivity(sdim, 0)
        mesh.topology.create_connectivity(tdim, 0)
        sub_vertices = self.submesh.topology.connectivity(sdim, 0).array.reshape(-1, nv)
        dofs = self.P1.dofmap.list  # (all local cells: an owned node may have no owned cell)
        owned = self.P1.dofmap.index_map.size_local
        vertex_of_node = np.full(owned + self.P1.dofmap.index_map.num_ghosts, -1, np.int64)
        vertex_of_node[dofs.ravel()] = sub_vertices[: len(dofs)].ravel()
        parent_vertex = self._vertex_map.sub_topology_to_topology(
            vertex_of_node[:owned].astype(np.int32), inverse=False
        )
        nvc = len(basix.topology(basix_cell(mesh, tdim))[0])
        cell_vertices = mesh.topology.connectivity(tdim, 0).array.reshape(-1, nvc)
        vertices = mesh.topology.index_map(0)
        block_of_vertex = np.full(vertices.size_local + vertices.num_ghosts, -1, np.int64)
        block_of_vertex[cell_vertices.ravel()] = self.V.dofmap.list[:, :nvc].ravel()
        return block_of_vertex[parent_vertex]

    def _node_blocks_by_position(self) -> np.ndarray:
        """:meth:`node_blocks` of a degree-2 or P1-iso-P2 multiplier (degree-2 displacement):
        the displacement dof block of the slave cells at the position of each owned multiplier
        node (vertices and edge midpoints coincide); raises (collective) if a node has no
        slave cell on this rank."""
        owned = self.multiplier_space.dofmap.index_map.size_local
        gdim = self.V.mesh.geometry.dim
        nodes = self.multiplier_space.tabulate_dof_coordinates()[:owned, :gdim]
        blocks = keysets.unique(self._cell_dofs)
        coords = self.V.tabulate_dof_coordinates()[blocks, :gdim]
        scale = self.facet_size  # (collective)
        found = np.full(owned, -1, dtype=np.int64)
        if len(blocks) and owned:
            distance, index = cKDTree(coords).query(nodes)
            found = np.where(distance <= 1e-10 * scale, blocks[index], -1)
        collective_check(
            self.V.mesh.comm,
            bool(np.all(found >= 0)),
            f"multiplier_degree={self.multiplier_degree!r}: a multiplier node has no slave "
            "facet on its rank (the held multipliers need one): use multiplier_degree=1",
        )
        return found

    def nodal_normal_projectors(self) -> np.ndarray:
        """``N N^T`` of the reference normals ``N`` of the slave cells around each owned
        multiplier node, averaged, ``(n, gdim, gdim)`` (the sign of ``N`` does not matter:
        a membrane's vertex-order normals may point either way)."""
        gdim = self.normals.shape[1]
        space = dolfinx.fem.functionspace(self.submesh, self.multiplier_element((gdim * gdim + 1,)))
        f = dolfinx.fem.Function(space)
        values = f.x.array.reshape(-1, gdim * gdim + 1)
        outer = np.einsum("ci,cj->cij", self.normals, self.normals).reshape(-1, gdim * gdim)
        per_cell = np.hstack([outer, np.ones((len(outer), 1))])
        dofs = space.dofmap.list[: self.num_cells]
        np.add.at(values, dofs, per_cell[:, None, :])
        f.x.scatter_reverse(dolfinx.la.InsertMode.add)
        owned = space.dofmap.index_map.size_local
        summed = f.x.array.reshape(-1, gdim * gdim + 1)[:owned]
        return (summed[:, :-1] / summed[:, -1:]).reshape(-1, gdim, gdim)

    def count_at_nodes(self, mask: np.ndarray) -> np.ndarray:
        """For each owned multiplier node, how many of the (owned) points ``mask`` selects
        lie in the support of its function (Lagrange: the cells around it; P1-iso-P2: the
        refined cells around it), over all ranks."""
        counts = dolfinx.fem.Function(self.P1)
        selected = mask.reshape(self.num_cells, self.num_points).astype(float)
        per_node = selected @ self._support  # (nc, nodes of a cell)
        dofs = self.P1.dofmap.list[: self.num_cells]
        np.add.at(counts.x.array, dofs, per_node)
        counts.x.scatter_reverse(dolfinx.la.InsertMode.add)
        return counts.x.array[: self.P1.dofmap.index_map.size_local]
