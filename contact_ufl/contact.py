"""The frictionless contact terms of the augmented-Lagrangian weak form.

For one contact pair (slave facet tag, master facet tag) this module builds, in UFL, the
contact integrals of ``formulation.md``

    - int_{S_oc} <lambda_N + eps_N g> nu . (U1* - U2*(Y)) dS_o
    - int_{S_oc} (lambda_N - <lambda_N + eps_N g>) lambda_N* dS_o    (times eps_N, see below)

(the seed's weak form times -1, so that the bulk term reads ``+ int Pi : Grad U*``).

What UFL cannot see, the master surface at the projected points, is carried to every slave
quadrature point as data on the slave submesh (quadrature elements):

``xhat``
    the current positions of the nodes of the master facet found by the closest-point
    projection. It is a *field of the assembled system* (it has a test function, which is
    the master virtual displacement at the nodes), tied to the unknowns by ``xhat = Xhat +
    P u`` (``P`` gathers master dofs; see :mod:`contact_ufl.layout`).
``xhat0, x0, xi0, M``
    copies of the current master nodes and slave point, the reference coordinates of the
    projection and its linearisation matrix (``contact_ufl.projection``), held as data.

The projected point is written as ``xi = xi0 + M b(x - x0, xhat - xhat0)`` (the linearised
closest-point condition of ``consistent-tangent.md``): its value is the one found by the
search, and its Gateaux derivative is the implicit-function derivative. The master point
``y(xi)``, the tangents ``a_alpha(xi)``, the normal ``nu`` and the proximity ``g = -nu . (x -
y)`` are then UFL expressions of the unknowns, and ``ufl.derivative`` gives every term of
the tangent (sliding of ``y``, rotation of ``nu``, ``Grad U2*`` times ``d xi``).

Discrete multiplier: ``lambda_N`` is continuous piecewise linear on the slave submesh (P1).
It interpolates a continuous contact pressure with the same resolution as the slave trace
of a P1 displacement, so the active set and the gap condition are imposed in the weak
(mortar) sense at the contact quadrature points, and the multiplier *is* the nodal pressure
(property (c) of ``formulation.md``). The slave side should be the finer mesh, as usual
with standard mortar multipliers.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import basix.ufl
import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl.errors import check_positive, collective_check
from contact_ufl.layout import StackedLayout
from contact_ufl.projection import Projection, closest_points
from contact_ufl.surfaces import (
    QUADRATURE_RULES,
    MasterSurface,
    SlaveSurface,
    gathered_node_positions,
    global_bounds,
    segment_neighbours,
)


@dataclass(frozen=True)
class ContactPair:
    """A contact pair of a scene.

    Parameters
    ----------
    slave
        Facet tag of the slave (contactor) surface; it carries the multipliers.
    master
        Facet tag of the master (target) surface.
    eps_N
        Normal augmentation parameter (> 0). It does not change the exact solution; a value
        of the order of ``E / h`` gives good Newton convergence.
    mu
        Coulomb friction coefficient (>= 0). Friction terms exist only where ``mu > 0``.
    eps_T
        Tangential augmentation parameter (> 0), defaults to ``eps_N``.
    search_radius
        Distance beyond which a slave point is known not to be in contact in a Newton
        iteration; only master facets within it are searched. Defaults to a quarter of the
        diagonal of the bounding box of the two surfaces.
    quadrature_degree
        Degree of the Gauss rule of the contact integrals (defaults to ``2 p + 1`` for
        displacement degree ``p``).
    quadrature_subdivisions
        Repeat that rule on a uniform split of every slave facet (composite rule): the master
        facet edges put kinks into the integrand that one Gauss rule resolves poorly.
    quadrature_rule
        ``"gauss"`` (default) or ``"lobatto"`` (Gauss-Lobatto-Legendre, intervals and
        quadrilaterals): the Lobatto points include the vertices of the slave facets, so a
        slave edge or corner that meets the master surface (the tip of a beam) is itself a
        contact point and cannot sink into the master between Gauss points.
    master_normal
        ``"facet"`` (default): the normal of the master facet. ``"smoothed"`` (2D): the
        normal interpolated along the segment from averaged nodal normals, continuous from
        one segment to the next; a slave point sliding over a master vertex then meets no
        jump of the contact force's direction (large sliding, ironing). The nodal normals
        depend on the neighbouring nodes, which are gathered with the segment's own.
    """

    slave: int
    master: int
    eps_N: float
    mu: float = 0.0
    eps_T: float | None = None
    search_radius: float | None = None
    quadrature_degree: int | None = None
    quadrature_subdivisions: int = 1
    quadrature_rule: str = "gauss"
    master_normal: str = "facet"

    def validate(self, comm: MPI.Comm) -> None:
        """Raise a clear error (on every rank) for invalid parameters."""
        check_positive(comm, eps_N=self.eps_N)
        collective_check(comm, self.mu >= 0.0, f"mu must be >= 0, got mu = {self.mu}")
        if self.eps_T is not None:
            check_positive(comm, eps_T=self.eps_T)
        if self.search_radius is not None:
            check_positive(comm, search_radius=self.search_radius)
        collective_check(
            comm,
            int(self.quadrature_subdivisions) >= 1,
            f"quadrature_subdivisions must be >= 1, got {self.quadrature_subdivisions}",
        )
        collective_check(
            comm,
            self.quadrature_rule in QUADRATURE_RULES,
            f"quadrature_rule must be one of {sorted(QUADRATURE_RULES)}, "
            f"got {self.quadrature_rule!r}",
        )
        collective_check(
            comm,
            self.master_normal in ("facet", "smoothed"),
            f"master_normal must be 'facet' or 'smoothed', got {self.master_normal!r}",
        )
        collective_check(
            comm,
            self.slave != self.master,
            f"slave and master tags must differ (both {self.slave})",
        )


def macaulay(a: ufl.core.expr.Expr, touching: float | ufl.core.expr.Expr = 0.0):
    """Macaulay bracket ``<a> = max(a, 0)``.

    With ``touching > 0``, the values ``-touching < a <= 0`` count as positive (value ``a``,
    derivative 1): a point within round-off of touching is in contact. Scenes that start
    exactly at ``g = 0`` with ``lambda = 0`` sit on the kink of the bracket, where round-off
    alone would pick a random active set (and a singular tangent) for the first iterate; the
    value changes by at most ``touching``.
    """
    return ufl.conditional(ufl.gt(a, -touching), a, 0.0)


def master_shape_functions(nn: int, xi: ufl.core.expr.Expr) -> tuple[list, list]:
    """UFL shape functions of a master facet and their xi-derivatives.

    Conventions as in :mod:`contact_ufl.projection`: segment (2 nodes), triangle (3 nodes),
    bilinear quadrilateral (4 nodes, basix vertex order).
    """
    if nn == 2:
        s = xi[0]
        return [1 - s, s], [[-1.0], [1.0]]
    if nn == 3:
        s, t = xi[0], xi[1]
        return [1 - s - t, s, t], [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]
    if nn == 4:
        s, t = xi[0], xi[1]
        N = [(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t]
        dN = [[-(1 - t), -(1 - s)], [1 - t, -s], [-t, 1 - s], [t, s]]
        return N, dN
    raise ValueError(f"no master facet with {nn} nodes")


def _interpolate(coeffs, nodes, gdim: int) -> ufl.core.expr.Expr:
    return ufl.as_vector([sum(c * nodes[a, i] for a, c in enumerate(coeffs)) for i in range(gdim)])


def _unit_normal(tangents: list, mask: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """Master normal from the tangents; zero (not NaN) where ``mask`` is 0."""
    if len(tangents) == 1:
        a1 = tangents[0]
        perp = ufl.as_vector([a1[1], -a1[0]])
    else:
        perp = ufl.cross(tangents[0], tangents[1])
    return perp / ufl.sqrt(ufl.dot(perp, perp) + (1.0 - mask))


def _smoothed_normal(xi, nodes, flags, mask) -> ufl.core.expr.Expr:
    """2D master normal interpolated from averaged nodal normals along the segment.

    ``nodes`` rows: the segment's nodes ``a, b``, then the node before ``a`` and after ``b``
    (``flags`` say whether those exist; at an end of the surface the segment's own tangent
    stands in). The nodal normal of ``a`` is the sum of the unit normals of the two segments
    at ``a``; the normal at ``xi`` the normalised linear interpolation of the nodal ones.
    """
    a, b, before, after = (ufl.as_vector([nodes[k, 0], nodes[k, 1]]) for k in range(4))
    segment = b - a
    incoming = flags[0] * (a - before) + (1.0 - flags[0]) * segment
    outgoing = flags[1] * (after - b) + (1.0 - flags[1]) * segment

    def unit_perp(t):
        perp = ufl.as_vector([t[1], -t[0]])
        return perp / ufl.sqrt(ufl.dot(perp, perp) + (1.0 - mask))

    n_a = unit_perp(incoming) + unit_perp(segment)
    n_b = unit_perp(segment) + unit_perp(outgoing)
    n = (1.0 - xi[0]) * n_a + xi[0] * n_b
    return n / ufl.sqrt(ufl.dot(n, n) + (1.0 - mask))


def smoothed_normals(xi: np.ndarray, nodes: np.ndarray, flags: np.ndarray) -> np.ndarray:
    """NumPy twin of :func:`_smoothed_normal` for paired points: ``xi (n, 1)``, ``nodes
    (n, 4, 2)``, ``flags (n, 2)``; returns unit normals ``(n, 2)``."""
    a, b, before, after = (nodes[:, k] for k in range(4))
    segment = b - a
    incoming = np.where(flags[:, :1], a - before, segment)
    outgoing = np.where(flags[:, 1:], after - b, segment)

    def unit_perp(t):
        perp = np.stack([t[:, 1], -t[:, 0]], axis=1)
        return perp / np.linalg.norm(perp, axis=1, keepdims=True)

    n = (1.0 - xi) * (unit_perp(incoming) + unit_perp(segment)) + xi * (
        unit_perp(segment) + unit_perp(outgoing)
    )
    return n / np.linalg.norm(n, axis=1, keepdims=True)


class FrictionlessContact:
    """Frictionless contact terms of one contact pair.

    Parameters
    ----------
    u
        The displacement (one function over the mesh of all bodies).
    facet_tags
        Facet tags of the mesh.
    pair
        The contact pair.
    """

    def __init__(
        self, u: dolfinx.fem.Function, facet_tags: dolfinx.mesh.MeshTags, pair: ContactPair
    ):
        V = u.function_space
        mesh = V.mesh
        pair.validate(mesh.comm)
        self.u, self.V, self.pair = u, V, pair
        self.gdim = gdim = mesh.geometry.dim
        self.fdim = fdim = mesh.topology.dim - 1
        degree = V.ufl_element().embedded_superdegree
        # the master surface is interpolated from its vertices: exact for P1/Q1 only
        geometry_degree = mesh.geometry.cmaps[0].degree
        collective_check(
            mesh.comm,
            degree == 1 and geometry_degree == 1,
            f"contact needs degree-1 displacement and geometry (got {degree} and "
            f"{geometry_degree}): higher-order master surfaces are not implemented",
        )
        qdeg = pair.quadrature_degree or 2 * degree + 1
        self.slave = SlaveSurface(
            V, facet_tags, pair.slave, qdeg, pair.quadrature_subdivisions, pair.quadrature_rule
        )
        self.master = MasterSurface(V, facet_tags, pair.master)
        self.nn = nn = comm_max(mesh.comm, self.master.nodes.shape[1])
        self.smoothed = pair.master_normal == "smoothed"
        if self.smoothed:
            collective_check(
                mesh.comm,
                gdim == 2,
                "master_normal='smoothed' is implemented for 2D (segment) master surfaces only",
            )
            self._neighbours, self._has_neighbour = segment_neighbours(
                mesh.comm, self.master.global_nodes
            )
        #: master nodes carried to each slave point: the facet's, then (smoothed) its
        #: neighbours before and after
        self.nx = nn + 2 if self.smoothed else nn
        sub = self.slave.submesh

        def space(shape):
            element = basix.ufl.quadrature_element(
                sub.basix_cell(),
                value_shape=shape,
                points=self.slave.points_ref,
                weights=self.slave.weights_ref,
            )
            return dolfinx.fem.functionspace(sub, element)

        self.Qx = space((self.nx * gdim,))
        self.xhat = dolfinx.fem.Function(self.Qx, name="master_nodes")
        self.xhat0 = dolfinx.fem.Function(self.Qx)
        self.x0 = dolfinx.fem.Function(space((gdim,)))
        self.xi0 = dolfinx.fem.Function(space((fdim,)))
        self.M = dolfinx.fem.Function(space((fdim, fdim)))
        self.mask = dolfinx.fem.Function(space(()))
        #: (smoothed normal) whether the neighbour before / after the facet exists
        self.neighbour_flags = dolfinx.fem.Function(space((2,))) if self.smoothed else None
        self.L = dolfinx.fem.functionspace(sub, ("Lagrange", 1))
        self.lambda_N = dolfinx.fem.Function(self.L, name="lambda_N")
        p1 = self.L.ufl_element().basix_element
        self._phi_lambda = p1.tabulate(0, self.slave.points_ref)[0, :, :, 0]
        self.eps_N = dolfinx.fem.Constant(mesh, float(pair.eps_N))
        self.ds = ufl.Measure(
            "ds",
            domain=mesh,
            subdomain_data=facet_tags,
            subdomain_id=pair.slave,
            metadata={"quadrature_degree": qdeg},
        )
        #: a gap within round-off of zero, ``1e-12`` of the surfaces' size (see :func:`macaulay`)
        self.touching = 1e-12 * self._surfaces_diameter()
        self._kinematics()
        self.radius = pair.search_radius or self._default_radius()
        self._check_facing()
        self.search_time = 0.0
        self.projection: Projection | None = None
        self._surface_forms: dict[str, list[dolfinx.fem.Form]] = {}
        #: Freeze the projected point inside a Newton iteration (drop its variation from the
        #: tangent, as many codes do): Newton then converges only linearly. For comparisons.
        self.frozen_projection = False

    # -- UFL ----------------------------------------------------------------------------
    def _kinematics(self) -> None:
        gdim, fdim, nn = self.gdim, self.fdim, self.nn
        X = ufl.SpatialCoordinate(self.V.mesh)
        self.x = x = X + self.u

        def nodes(f):
            return ufl.as_matrix([[f[a * gdim + i] for i in range(gdim)] for a in range(self.nx)])

        xh, xh0 = nodes(self.xhat), nodes(self.xhat0)
        N0, dN0 = master_shape_functions(nn, self.xi0)
        y0 = _interpolate(N0, xh0, gdim)
        dxh = xh - xh0
        dx = x - self.x0
        b = []
        for al in range(fdim):
            a0 = _interpolate([dN0[a][al] for a in range(nn)], xh0, gdim)
            slide = dx - _interpolate(N0, dxh, gdim)
            b.append(
                ufl.dot(a0, slide)
                + ufl.dot(self.x0 - y0, _interpolate([dN0[a][al] for a in range(nn)], dxh, gdim))
            )
        self.xi = xi = self.xi0 + self.M * ufl.as_vector(b)
        self.N, dN = master_shape_functions(nn, xi)
        self.y = _interpolate(self.N, xh, gdim)
        if self.smoothed:
            self.nu = _smoothed_normal(xi, xh, self.neighbour_flags, self.mask)
        else:
            tangents = [
                _interpolate([dN[a][al] for a in range(nn)], xh, gdim) for al in range(fdim)
            ]
            self.nu = _unit_normal(tangents, self.mask)
        self.gap = -ufl.dot(self.nu, x - self.y)
        self.t_N = self.mask * macaulay(
            self.lambda_N + self.eps_N * self.gap, self.eps_N * self.touching
        )

    def master_test_at_projection(self, vhat: ufl.Argument) -> ufl.core.expr.Expr:
        """The master virtual displacement ``U2*(Y(X)) = sum_a N_a(xi) vhat_a``."""
        gdim = self.gdim
        nodes = ufl.as_matrix([[vhat[a * gdim + i] for i in range(gdim)] for a in range(self.nn)])
        return _interpolate(self.N, nodes, gdim)

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """Fields of the assembled system this pair adds (after the displacement)."""
        return [self.xhat, self.lambda_N]

    @property
    def unknowns(self) -> list[dolfinx.fem.Function]:
        """Unknowns this pair adds (after the displacement)."""
        return [self.lambda_N]

    def traction(self) -> ufl.core.expr.Expr:
        """Contact traction on the slave surface, ``T = t_N nu`` (frictionless)."""
        return self.t_N * self.nu

    def surface_integrands(self) -> dict[str, ufl.core.expr.Expr]:
        """Named integrands over the slave surface for :meth:`integrate`: ``"traction"``, the
        whole contact traction (:meth:`traction`), and ``"normal"``, its normal-pressure
        part ``t_N nu``."""
        return {"traction": self.traction(), "normal": self.t_N * self.nu}

    def integrate(self, name: str) -> np.ndarray:
        """``int integrand dS_o`` over the slave surface, summed over all ranks, of the
        integrand ``name`` of :meth:`surface_integrands` (its forms compiled once)."""
        if name not in self._surface_forms:
            expr = self.surface_integrands()[name]
            parts = [expr[i] for i in range(expr.ufl_shape[0])] if expr.ufl_shape else [expr]
            self._surface_forms[name] = [
                dolfinx.fem.form(e * self.ds, entity_maps=[self.slave.entity_map]) for e in parts
            ]
        local = np.array([dolfinx.fem.assemble_scalar(f) for f in self._surface_forms[name]])
        return self.V.mesh.comm.allreduce(local, MPI.SUM)

    def residuals(self, v: ufl.Argument) -> tuple[ufl.Form, list[ufl.Form]]:
        """Contact part of the displacement residual, and the residuals of :attr:`fields`."""
        vhat, lambda_test = ufl.TestFunction(self.Qx), ufl.TestFunction(self.L)
        traction = self.traction()
        F_u = -ufl.dot(traction, v) * self.ds
        F_x = ufl.dot(traction, self.master_test_at_projection(vhat)) * self.ds
        # the seed's multiplier equation times eps_N (an equivalent weak form): its rows are
        # forces like those of the displacement, for conditioning and one tolerance
        F_l = -(self.lambda_N - self.t_N) * lambda_test * self.ds
        return F_u, [F_x, F_l]

    def update_history(self, T, x, block_slice) -> None:
        """Refresh data that needs the chain operator (none without friction)."""

    def commit(self, x) -> None:
        """Accept the current state as the converged state of a load step."""

    def begin_step(self) -> None:
        """Start a load step from the last committed state (history-dependent terms)."""

    # -- search -------------------------------------------------------------------------
    def _surfaces_diameter(self) -> float:
        """Diagonal of the bounding box of both reference surfaces (all ranks)."""
        comm = self.V.mesh.comm
        pts = [self.slave.X.reshape(-1, self.gdim), self.master.X_nodes.reshape(-1, self.gdim)]
        lo, hi = global_bounds(comm, np.vstack(pts))
        return float(np.linalg.norm(hi - lo))

    def _default_radius(self) -> float:
        return 0.25 * self._surfaces_diameter()

    def _check_facing(self) -> None:
        """Raise if no slave point faces the master surface in the reference configuration."""
        x = self.slave.X.reshape(-1, self.gdim)
        nodes, _, _ = self._candidates(self.master.X_nodes, x)
        proj = closest_points(x, nodes, np.inf)
        # a slave point faces the master when it lies on the outer side of the master facet
        # and the two outward normals oppose each other
        normals = np.repeat(self.slave.normals, self.slave.num_points, axis=0)
        outside = np.einsum("pd,pd->p", proj.normal, x - proj.y) >= -1e-8 * (1 + proj.distance)
        opposed = np.einsum("pd,pd->p", proj.normal, normals) < 0.0
        facing = np.count_nonzero((proj.facet >= 0) & outside & opposed)
        total = self.V.mesh.comm.allreduce(facing, MPI.SUM)
        collective_check(
            self.V.mesh.comm,
            total > 0,
            f"slave surface (tag {self.pair.slave}) never faces master surface "
            f"(tag {self.pair.master}): no slave point lies on the outer side of the master "
            "facets (wrong tags or swapped bodies?)",
        )

    def _candidates(self, master_nodes: np.ndarray, points: np.ndarray, payload=None):
        """Master facets of all ranks near this rank's slave points (bounding-box filter)."""
        comm = self.V.mesh.comm
        box = self.slave.bounding_box(points, comm)
        boxes = comm.allgather(box)
        n = len(master_nodes)
        payload = np.zeros((n, 0)) if payload is None else payload
        if n:
            lo, hi = master_nodes.min(axis=1), master_nodes.max(axis=1)
        sends = []
        for b in boxes:
            if n == 0:
                sends.append((master_nodes, payload))
                continue
            near = np.all((lo <= b[1] + self.radius) & (hi >= b[0] - self.radius), axis=1)
            sends.append((master_nodes[near], payload[near]))
        received = comm.alltoall(sends) if comm.size > 1 else sends
        nodes = np.concatenate([r[0] for r in received]).reshape(-1, *master_nodes.shape[1:])
        data = np.concatenate([r[1] for r in received]).reshape(len(nodes), *payload.shape[1:])
        return nodes, data, len(nodes)

    def update(self, layout: StackedLayout) -> np.ndarray:
        """Project the slave points onto the master surface and refresh the data.

        Parameters
        ----------
        layout
            Layout of the unknowns; block 0 is the displacement.

        Returns
        -------
        The gathered fields: pairs of a field and, for every owned dof of it (unrolled, local
        order), the stacked index of the displacement unknown it gathers, or -1.
        """
        start = time.perf_counter()
        gdim, nn, nx = self.gdim, self.nn, self.nx
        comm = self.V.mesh.comm
        bs = self.V.dofmap.index_map_bs
        points = self.slave.positions(self.u).reshape(-1, gdim)
        current = self.master.current_nodes(self.u)
        global_nodes = self.master.global_nodes.astype(np.int64)
        extra = []
        if self.smoothed:  # carry the neighbour nodes of every segment along
            before_after = gathered_node_positions(comm, global_nodes, current, self._neighbours)
            current = np.concatenate([current, before_after], axis=1)
            global_nodes = np.hstack([global_nodes, self._neighbours])
            extra = [self._has_neighbour.astype(np.int64)]
        cols = layout.from_block_global(0, global_nodes * bs)
        payload = np.hstack(
            [
                cols,
                self.master.keys.astype(np.int64),
                self.master.boundary_edges.astype(np.int64),
                *extra,
            ]
        )
        nodes, payload, _ = self._candidates(current, points, payload)
        # candidates in a rank-independent order: ties between facets break the same way
        order = np.lexsort(payload[:, nx : nx + nn].T[::-1])
        nodes, payload = nodes[order], payload[order]
        ne = self.master.boundary_edges.shape[1]
        cols = payload[:, :nx]
        boundary = payload[:, nx + nn : nx + nn + ne].astype(bool)
        proj = closest_points(points, nodes[:, :nn], self.radius)
        release_beyond_boundary(proj, points, boundary, self.touching)
        paired = proj.facet >= 0
        if self.smoothed:
            flags = payload[proj.facet[paired], nx + nn + ne :].astype(bool)
            normal = smoothed_normals(proj.xi[paired], nodes[proj.facet[paired]], flags)
            proj.normal[paired] = normal
            proj.gap[paired] = -np.einsum("pd,pd->p", normal, points[paired] - proj.y[paired])
            all_flags = np.zeros((len(points), 2))
            all_flags[paired] = flags
            self._set(self.neighbour_flags, all_flags)
        self.projection = proj
        npts = len(points)
        xhat = np.zeros((npts, nx * gdim))
        xhat[paired] = nodes[proj.facet[paired]].reshape(-1, nx * gdim)
        gather = np.full((npts, nx, gdim), -1, dtype=np.int64)
        gather[paired] = cols[proj.facet[paired]][:, :, None] + np.arange(gdim)
        self._set(self.xhat, xhat)
        self._set(self.xhat0, xhat)
        self._set(self.x0, points)
        self._set(self.xi0, np.where(paired[:, None], proj.xi, 0.0))
        sliding = paired[:, None, None] & (not self.frozen_projection)
        self._set(self.M, np.where(sliding, proj.sliding, 0.0))
        self._set(self.mask, paired.astype(float))
        self.search_time += time.perf_counter() - start
        self._gather = self._unrolled(self.Qx, gather.reshape(npts, nx * gdim), fill=-1)
        return [(self.xhat, self._gather)]

    def assemble_nodal(self, form: dolfinx.fem.Form, space) -> np.ndarray:
        """Assemble the linear ``form`` over a multiplier ``space`` of the slave submesh;
        the owned and ghost values, accumulated."""
        f = dolfinx.fem.Function(space)
        dolfinx.fem.assemble_vector(f.x.array, form)
        f.x.scatter_reverse(dolfinx.la.InsertMode.add)
        return f.x.array

    @functools.cached_property
    def nodal_mass(self) -> np.ndarray:
        """``int phi_i dS_o`` of the owned multiplier nodes (the reference surface)."""
        form = dolfinx.fem.form(
            ufl.TestFunction(self.L) * self.ds, entity_maps=[self.slave.entity_map]
        )
        return self.assemble_nodal(form, self.L)[: self.L.dofmap.index_map.size_local].copy()

    def count_at_nodes(self, mask: np.ndarray) -> np.ndarray:
        """For each owned multiplier node, how many of the (owned) points ``mask`` selects
        lie in the cells around it, over all ranks."""
        counts = dolfinx.fem.Function(self.L)
        per_cell = mask.reshape(self.slave.num_cells, self.slave.num_points).sum(axis=1)
        dofs = self.L.dofmap.list[: self.slave.num_cells]
        np.add.at(counts.x.array, dofs, per_cell[:, None].astype(float))
        counts.x.scatter_reverse(dolfinx.la.InsertMode.add)
        return counts.x.array[: self.L.dofmap.index_map.size_local]

    def multiplier_at_points(self) -> np.ndarray:
        """lambda_N at the owned slave quadrature points, ``(ncells * nq,)``."""
        dofs = self.L.dofmap.list[: self.slave.num_cells]
        return np.einsum("qn,cn->cq", self._phi_lambda, self.lambda_N.x.array[dofs]).ravel()

    def active(self) -> np.ndarray:
        """Mask of the owned slave quadrature points in contact (``lambda_N + eps_N g > 0``,
        or within round-off of it: see :func:`macaulay`)."""
        return self._touching()

    def normal_traction_at_points(self) -> np.ndarray:
        """``t_N = <lambda_N + eps_N g>`` at the owned slave points (0 where unpaired)."""
        proj = self.projection
        lam = self.multiplier_at_points()
        gap = np.where(proj.facet >= 0, proj.gap, -np.inf)
        return np.maximum(lam + float(self.eps_N.value) * gap, 0.0)

    def _touching(self) -> np.ndarray:
        """Mask of the owned points where the bracket counts as positive (:func:`macaulay`)."""
        proj = self.projection
        eps = float(self.eps_N.value)
        a = self.multiplier_at_points() + eps * np.where(proj.facet >= 0, proj.gap, -np.inf)
        return a > -eps * self.touching

    def traction_at_points(self) -> np.ndarray:
        """Contact traction on the slave body at the owned slave points, ``(n, gdim)``: the
        integrand of :meth:`traction` (nominal, per unit reference area)."""
        return self.normal_traction_at_points()[:, None] * self.projection.normal

    def _owned_blocks(self, Q: dolfinx.fem.FunctionSpace) -> np.ndarray:
        return Q.dofmap.list[: self.slave.num_cells].ravel()

    def _set(self, f: dolfinx.fem.Function, values: np.ndarray) -> None:
        bs = f.function_space.dofmap.index_map_bs
        f.x.array.reshape(-1, bs)[self._owned_blocks(f.function_space)] = values.reshape(-1, bs)
        f.x.scatter_forward()

    def _unrolled(self, Q, values: np.ndarray, fill) -> np.ndarray:
        bs = Q.dofmap.index_map_bs
        out = np.full((Q.dofmap.index_map.size_local, bs), fill, dtype=values.dtype)
        out[self._owned_blocks(Q)] = values
        return out.ravel()


def _on_edges(nn: int, xi: np.ndarray, tol: float = 1e-12) -> np.ndarray:
    """Which edges of :data:`~contact_ufl.surfaces.FACET_EDGES` hold the points ``xi``."""
    if nn == 2:
        return np.stack([xi[:, 0] <= tol, xi[:, 0] >= 1 - tol], axis=1)
    s, t = xi[:, 0], xi[:, 1]
    if nn == 3:
        return np.stack([t <= tol, s <= tol, s + t >= 1 - tol], axis=1)
    return np.stack([t <= tol, s <= tol, s >= 1 - tol, t >= 1 - tol], axis=1)


def release_beyond_boundary(
    proj: Projection, points: np.ndarray, boundary: np.ndarray, tolerance: float = 0.0
) -> None:
    """Unpair the points beyond the edge of the master surface (in place).

    A point whose closest point is on an edge (2D: an end point) of the master *surface*
    boundary, and off the normal through it by more than ``tolerance`` (a length: round-off),
    lies beyond the surface: it is not in contact (the last facet is not a half-plane).
    ``boundary``: boundary-edge flags per candidate.
    """
    paired = np.flatnonzero(proj.facet >= 0)
    if len(paired) == 0:
        return
    facet = proj.facet[paired]
    on_edge = _on_edges(boundary.shape[1], proj.xi[paired])  # as many edges as nodes
    at_boundary = (on_edge & boundary[facet]).any(axis=1)
    d = points[paired] - proj.y[paired]
    normal_part = np.einsum("pd,pd->p", d, proj.normal[paired])
    off_normal = np.linalg.norm(d - normal_part[:, None] * proj.normal[paired], axis=1)
    beyond = (
        at_boundary & (off_normal > 1e-6 * np.linalg.norm(d, axis=1)) & (off_normal > tolerance)
    )
    released = paired[beyond]
    proj.facet[released] = -1
    proj.gap[released] = -np.inf


def comm_max(comm: MPI.Comm, value: int) -> int:
    """Largest value over the ranks."""
    return int(comm.allreduce(value, MPI.MAX))
