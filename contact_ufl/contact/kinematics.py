"""The contact kinematics of a meshed master side in UFL: the projected point, the master
normal, the proximity and the master virtual displacement at the projected point.

What UFL cannot see, the master surface at the projected points, is carried to every slave
quadrature point as data on the slave submesh (quadrature elements):

``xhat``
    the current positions of the nodes of the master facet found by the closest-point
    projection. It is a *field of the assembled system* (it has a test function, which is
    the master virtual displacement at the nodes), tied to the unknowns by ``xhat = Xhat +
    P u`` (``P`` gathers master dofs; see :mod:`contact_ufl.layout`).
``xhat0, x0, xi0, sliding``
    copies of the current master nodes and slave point, the reference coordinates of the
    projection and its linearisation matrix ``M`` (:mod:`.search.projection`), held as data.

The projected point is written as ``xi = xi0 + M b(x - x0, xhat - xhat0)`` (the linearised
closest-point condition, ``docs/theory.md``): its value is the one found by the
search, and its Gateaux derivative is the implicit-function derivative. The master point
``y(xi)``, the tangents ``a_alpha(xi)``, the normal ``nu`` and the proximity ``g = -nu . (x -
y)`` are then UFL expressions of the unknowns, and ``ufl.derivative`` gives every term of
the tangent (sliding of ``y``, rotation of ``nu``, ``Grad U2*`` times ``d xi``).
"""

from __future__ import annotations

import dolfinx
import numpy as np
import ufl
from petsc4py import PETSc

from contact_ufl.contact.master import MeshMaster
from contact_ufl.contact.search import ClosestPointSearch, Pairing, Projection, shape_functions
from contact_ufl.contact.slave import SlaveSurface
from contact_ufl.layout import GlobalValues, StackedLayout


def master_shape_functions(nodes_per_facet: int, xi: ufl.core.expr.Expr) -> tuple[list, list]:
    """UFL shape functions of a master facet and their xi-derivatives.

    The facet kinds of :mod:`.search.kinds`: segment (2 nodes), triangle (3 nodes), bilinear
    quadrilateral (4 nodes, basix vertex order); quadratic segment (3 nodes, ``xi`` of one
    coordinate), triangle (6 nodes) and quadrilateral (9 nodes).
    """
    if nodes_per_facet == 3 and xi.ufl_shape == (1,) or nodes_per_facet in (6, 9):
        return quadratic_shape_functions(nodes_per_facet, xi)
    if nodes_per_facet == 2:
        s = xi[0]
        return [1 - s, s], [[-1.0], [1.0]]
    if nodes_per_facet == 3:
        s, t = xi[0], xi[1]
        return [1 - s - t, s, t], [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]
    if nodes_per_facet == 4:
        s, t = xi[0], xi[1]
        N = [(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t]
        dN = [[-(1 - t), -(1 - s)], [1 - t, -s], [-t, 1 - s], [t, s]]
        return N, dN
    raise ValueError(f"no master facet with {nodes_per_facet} nodes")


def _line(u) -> tuple[list, list]:
    """1D quadratic Lagrange functions (start, end, middle) of ``u`` and their derivatives."""
    return [(1 - u) * (1 - 2 * u), u * (2 * u - 1), 4 * u * (1 - u)], [
        4 * u - 3,
        4 * u - 1,
        4 - 8 * u,
    ]


def quadratic_shape_functions(nodes_per_facet: int, xi: ufl.core.expr.Expr) -> tuple[list, list]:
    """UFL twin of :func:`.search.shapes.quadratic_shape_functions`: the 3-node segment
    (ends, then midpoint), the 6-node triangle (vertices, then the midpoints of edges 01, 12,
    02) and the 9-node quadrilateral (:data:`.search.curved.QUADRILATERAL9_EDGES`)."""
    if nodes_per_facet == 3:
        line, dline = _line(xi[0])
        return line, [[d] for d in dline]
    if nodes_per_facet == 9:
        (ls, dls), (lt, dlt) = _line(xi[0]), _line(xi[1])
        index = ((0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (1, 2), (2, 1), (0, 2), (2, 2))
        N = [ls[i] * lt[j] for i, j in index]
        dN = [[dls[i] * lt[j], ls[i] * dlt[j]] for i, j in index]
        return N, dN
    L = [1 - xi[0] - xi[1], xi[0], xi[1]]
    dL = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]
    N = [L[i] * (2 * L[i] - 1) for i in range(3)]
    dN = [[(4 * L[i] - 1) * dL[i][al] for al in range(2)] for i in range(3)]
    for i, j in ((0, 1), (1, 2), (0, 2)):
        N.append(4 * L[i] * L[j])
        dN.append([4 * (L[j] * dL[i][al] + L[i] * dL[j][al]) for al in range(2)])
    return N, dN


def interpolate(coeffs, nodes, gdim: int) -> ufl.core.expr.Expr:
    """``sum_a coeffs[a] nodes[a, :]`` as a UFL vector."""
    return ufl.as_vector([sum(c * nodes[a, i] for a, c in enumerate(coeffs)) for i in range(gdim)])


def facet_normal(tangents: list, mask: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """Master normal from the tangents; zero (not NaN) where ``mask`` is 0."""
    if len(tangents) == 1:
        a1 = tangents[0]
        perp = ufl.as_vector([a1[1], -a1[0]])
    else:
        perp = ufl.cross(tangents[0], tangents[1])
    return perp / ufl.sqrt(ufl.dot(perp, perp) + (1.0 - mask))


def smoothed_normal(xi, nodes, flags, mask) -> ufl.core.expr.Expr:
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


def smoothed_normal_3d(xi, nodes, nodes_per_facet: int, mask) -> ufl.core.expr.Expr:
    """3D master normal interpolated from averaged nodal normals over the facet.

    ``nodes`` rows: the facet's ``nodes_per_facet`` nodes, then the fan of each (``K + 1``
    slots, see :mod:`.master`). The nodal normal of ``a`` is the normalised sum of the corner
    normals ``(s_i - a) x (s_i+1 - a)`` of its fan (the area-weighted average of the unit
    normals of the facets around ``a``; padded slots hold ``a`` and add zero); the normal at
    ``xi`` is the normalised interpolation of the nodal normals with the facet's shape
    functions.
    """
    slots = (nodes.ufl_shape[0] - nodes_per_facet) // nodes_per_facet
    N, _ = master_shape_functions(nodes_per_facet, xi)

    def node(k):
        return ufl.as_vector([nodes[k, i] for i in range(3)])

    def unit(v):
        return v / ufl.sqrt(ufl.dot(v, v) + (1.0 - mask))

    n = 0
    for a in range(nodes_per_facet):
        x_a = node(a)
        fan = [node(nodes_per_facet + a * slots + i) - x_a for i in range(slots)]
        n_a = sum(ufl.cross(fan[i], fan[i + 1]) for i in range(slots - 1))
        n = n + N[a] * unit(n_a)
    return unit(n)


class MeshKinematics:
    """Gap, normal and projected point of the slave points on a meshed master side.

    This is the master side as the rest of a contact pair sees it: UFL expressions of the
    slave point ``x``, the projected point ``y``, the normal ``nu`` and the proximity
    ``gap`` (and ``mask``, where a point has a master); the assembled fields it adds
    (:attr:`fields`) with their residuals (:meth:`master_residuals`, the master virtual work
    of the contact traction), and :meth:`update`, which runs the search and returns what
    the fields gather from the unknowns. Another master side (a rigid obstacle, a membrane)
    provides the same.

    Parameters
    ----------
    u
        The displacement.
    slave, master
        The two sides of the pair.
    search
        The closest-point search of the slave points on ``master``.

    Attributes
    ----------
    x, xi, y, nu, gap
        UFL: the current slave point, the reference coordinates of its projection, the
        projected point, the master normal there and the proximity ``g = -nu . (x - y)``.
    mask
        1 at the slave points that have a master facet, 0 elsewhere.
    xhat
        The gathered master nodes (a field of the assembled system).
    """

    def __init__(
        self,
        u: dolfinx.fem.Function,
        slave: SlaveSurface,
        master: MeshMaster,
        search: ClosestPointSearch,
    ):
        self.u, self.slave, self.master, self.search = u, slave, master, search
        self.gdim = u.function_space.mesh.geometry.dim
        self.fdim = self.gdim - 1
        self.nn, self.nx = master.nn, master.nx
        space = slave.point_space
        #: the point space of ``xhat``: ``nx`` gathered nodes of ``gdim`` coordinates
        self.xhat_space = space((self.nx * self.gdim,))
        self.xhat = dolfinx.fem.Function(self.xhat_space, name="master_nodes")
        self.xhat0 = dolfinx.fem.Function(self.xhat_space)
        self.x0 = dolfinx.fem.Function(space((self.gdim,)))
        self.xi0 = dolfinx.fem.Function(space((self.fdim,)))
        #: the linearisation matrix ``M`` of the projected point (``Projection.sliding``)
        self.sliding = dolfinx.fem.Function(space((self.fdim, self.fdim)))
        self.mask = dolfinx.fem.Function(space(()))
        #: (smoothed normal, 2D) whether the neighbour before / after the segment exists
        smoothed_2d = master.smoothed and self.gdim == 2
        self.neighbour_flags = dolfinx.fem.Function(space((2,))) if smoothed_2d else None
        #: (two-sided master, a membrane) the side of the master each slave point is on:
        #: +1 in front of the master's oriented normal, -1 behind it (the normal acting on the
        #: point is ``side`` times the master's); 0 before a point was first paired
        self.side = dolfinx.fem.Function(space(())) if master.two_sided else None
        self._side = np.zeros(slave.num_cells * slave.num_points)
        #: Freeze the projected point inside a Newton iteration (drop its variation from the
        #: tangent, as many codes do): Newton then converges only linearly. For comparisons.
        self.frozen_projection = False
        #: the closest points of the last search
        self.projection = None
        #: for every owned dof of ``xhat`` (unrolled), the stacked index of the unknown it
        #: gathers, or -1 (set by :meth:`update`)
        self.gather = None
        self._neighbourhood = None
        self._build()

    @property
    def sides(self) -> np.ndarray:
        """The side of a two-sided master each owned slave point faced when last paired
        (``-1`` or ``1``; ``0``: never paired), the memory of its search."""
        return self._side

    @sides.setter
    def sides(self, values: np.ndarray) -> None:
        self._side = np.array(values, dtype=float)

    def nodes(self, f) -> ufl.core.expr.Expr:
        """The gathered nodes of a point field of ``xhat``'s shape, as an ``(nx, gdim)``
        UFL matrix."""
        gdim = self.gdim
        return ufl.as_matrix([[f[a * gdim + i] for i in range(gdim)] for a in range(self.nx)])

    def _build(self) -> None:
        gdim, fdim, nodes_per_facet = self.gdim, self.fdim, self.nn
        X = ufl.SpatialCoordinate(self.u.function_space.mesh)
        self.x = x = X + self.u
        xh, xh0 = self.nodes(self.xhat), self.nodes(self.xhat0)
        N0, dN0 = master_shape_functions(nodes_per_facet, self.xi0)
        y0 = interpolate(N0, xh0, gdim)
        dxh = xh - xh0
        dx = x - self.x0
        b = []
        for al in range(fdim):
            a0 = interpolate([dN0[a][al] for a in range(nodes_per_facet)], xh0, gdim)
            slide = dx - interpolate(N0, dxh, gdim)
            b.append(
                ufl.dot(a0, slide)
                + ufl.dot(
                    self.x0 - y0,
                    interpolate([dN0[a][al] for a in range(nodes_per_facet)], dxh, gdim),
                )
            )
        self.xi = xi = self.xi0 + self.sliding * ufl.as_vector(b)
        self.N, dN = master_shape_functions(nodes_per_facet, xi)
        self.y = interpolate(self.N, xh, gdim)
        if self.master.smoothed and gdim == 2:
            self.nu = smoothed_normal(xi, xh, self.neighbour_flags, self.mask)
        elif self.master.smoothed:
            self.nu = smoothed_normal_3d(xi, xh, nodes_per_facet, self.mask)
        else:
            tangents = [
                interpolate([dN[a][al] for a in range(nodes_per_facet)], xh, gdim)
                for al in range(fdim)
            ]
            self.nu = facet_normal(tangents, self.mask)
        if self.side is not None:
            self.nu = self.side * self.nu
        self.gap = -ufl.dot(self.nu, x - self.y)

    def master_point(self, xi, nodes) -> ufl.core.expr.Expr:
        """The master point of reference coordinates ``xi`` on the facet of ``nodes``."""
        N, _ = master_shape_functions(self.nn, xi)
        return interpolate(N, nodes, self.gdim)

    def test_at_projection(self, vhat: ufl.Argument) -> ufl.core.expr.Expr:
        """The master virtual displacement ``U2*(Y(X)) = sum_a N_a(xi) vhat_a``."""
        return interpolate(self.N, self.nodes(vhat), self.gdim)

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """Fields of the assembled system the master side adds: the gathered nodes."""
        return [self.xhat]

    def master_residuals(self, traction: ufl.core.expr.Expr) -> list[ufl.Form]:
        """The residuals of :attr:`fields`: the virtual work of the contact traction on the
        master side, ``int T . U2*(Y) dS_o`` (action and reaction)."""
        vhat = ufl.TestFunction(self.xhat_space)
        return [ufl.dot(traction, self.test_at_projection(vhat)) * self.slave.ds]

    def update(self, layout: StackedLayout) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """Search, refresh the point data, and return the gathered fields: pairs of a field
        and, for every owned dof of it (unrolled, local order), the stacked index of the
        displacement unknown it gathers, or -1."""
        pairing = self.search.pair(self.u, layout)
        self.set_pairing(pairing)
        npts = len(pairing.points)
        self.gather = self.slave.unrolled(
            self.xhat_space, pairing.columns.reshape(npts, self.nx * self.gdim), fill=-1
        )
        self._neighbourhood = pairing.neighbourhood
        return [(self.xhat, self.gather)]

    def pattern_gathers(self) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """What the gathered fields may gather after a small change of the pairing: pairs of
        a field and, for every owned dof of it (unrolled, local order), the stacked indices
        of the unknowns of the same component at the nodes of its point's facet and of
        the facets beside it
        (``(ndofs, width)``, ``-1`` padded). A superset of the gathers of :meth:`update`
        (which returned ``xhat``'s): the solver's sparsity pattern is made from it, so that
        the pattern holds a point moving onto a neighbouring facet."""
        fan = self._neighbourhood
        npts, gdim = len(fan), self.gdim
        component = np.arange(gdim)[None, None, :, None]
        wide = np.where(fan[:, None, None, :] >= 0, fan[:, None, None, :] + component, -1)
        wide = np.broadcast_to(wide, (npts, self.nx, gdim, fan.shape[1]))
        wide = wide.reshape(npts, self.nx * gdim, fan.shape[1])
        return [(self.xhat, self.slave.unrolled(self.xhat_space, wide, fill=-1))]

    def set_pairing(self, pairing: Pairing) -> None:
        """Make the point data those of a new search result (value of xi, M, nodes...)."""
        slave, proj, paired = self.slave, pairing.projection, pairing.paired
        self.projection = proj
        npts = len(pairing.points)
        xhat = pairing.nodes.reshape(npts, self.nx * self.gdim)
        slave.set_at_points(self.xhat, xhat)
        slave.set_at_points(self.xhat0, xhat)
        slave.set_at_points(self.x0, pairing.points)
        slave.set_at_points(self.xi0, np.where(paired[:, None], proj.xi, 0.0))
        sliding = paired[:, None, None] & (not self.frozen_projection)
        slave.set_at_points(self.sliding, np.where(sliding, proj.sliding, 0.0))
        slave.set_at_points(self.mask, paired.astype(float))
        if self.neighbour_flags is not None:
            slave.set_at_points(self.neighbour_flags, pairing.flags)
        if self.side is not None:
            self._face(pairing)
            slave.set_at_points(self.side, self._side)

    def _face(self, pairing: Pairing) -> None:
        """The side of a two-sided master that acts on each paired point (in place: the
        projection's normal and gap become those of that side).

        A solid slave faces the master with its outward normal: the side whose normal
        opposes the slave's current normal acts. A membrane slave has two sides too: a
        point keeps the side it was on when it was first paired (its projection's side
        then), so that it stays on it when it presses on the master.
        """
        proj, paired = pairing.projection, pairing.paired
        if self.slave.membrane:
            first = paired & (self._side == 0.0)
            d = pairing.points[first] - proj.y[first]
            self._side[first] = np.where(np.einsum("pd,pd->p", d, proj.normal[first]) < 0, -1, 1)
        else:
            n_slave = self.slave.current_normals(self.u)
            facing = np.einsum("pd,pd->p", n_slave, proj.normal) > 0.0
            self._side = np.where(paired, np.where(facing, -1.0, 1.0), self._side)
        sign = np.where(paired, self._side, 1.0)
        proj.normal *= sign[:, None]
        proj.gap = np.where(paired, proj.gap * sign, proj.gap)

    @property
    def search_time(self) -> float:
        """Seconds spent in the closest-point search so far."""
        return self.search.time

    def set_time(self, t: float) -> None:
        """Nothing: a meshed master moves with the displacement."""

    def check_facing(self, description: str) -> Projection:
        """Raise (on every rank) if no slave point faces the master surface; the closest
        points of the reference configuration (see :meth:`.ClosestPointSearch.check_facing`)."""
        return self.search.check_facing(description)

    def slip_reference(self) -> MeshSlipReference:
        """The slip reference of the Coulomb law on this master side."""
        return MeshSlipReference(self)


class MeshSlipReference:
    """The slip reference ``y_n`` of friction on a meshed master side.

    ``y_n = sum_a N_a(xi_n) xhat_n,a``: the master *material* point a slave point was
    projected onto at the end of the last converged step, at its current position (the
    current positions ``xhat_n`` of the nodes of that step's master facet, gathered from the
    displacement like ``xhat``). ``xhat_n`` is a field of the assembled system (with a zero
    residual, so that its derivatives are assembled and chained onto the displacement).
    It holds the ``nn`` nodes of the facet only, not the neighbours that ``xhat`` carries
    for the smoothed normal (``y_n`` does not depend on them): with the smoothed 3D normal
    its blocks of the tangent are ``(nn / nx)^2``, about a hundredth, of ``xhat``'s.

    Parameters
    ----------
    kinematics
        The master side.
    """

    def __init__(self, kinematics: MeshKinematics):
        self.kinematics = k = kinematics
        #: the facet's own nodes of a point of ``xhat`` (the first ``nn`` of its ``nx``)
        self._facet_dofs = k.nn * k.gdim
        self.Qn = k.slave.point_space((self._facet_dofs,))
        self.xhat_n = dolfinx.fem.Function(self.Qn, name="master_nodes_last_step")
        self.xi_n = dolfinx.fem.Function(k.xi0.function_space)
        self.mask_n = dolfinx.fem.Function(k.mask.function_space)
        self._zero = dolfinx.fem.Function(k.mask.function_space)
        self._gather_n = None
        self._x_commit = None
        self._xhat_n_commit = None
        self._work = None  # the work vector and reader of follow, made once a step
        self._committed = None  # the converged state, until the next step begins
        gdim = k.gdim
        nodes_n = ufl.as_matrix(
            [[self.xhat_n[a * gdim + i] for i in range(gdim)] for a in range(k.nn)]
        )
        self.y_n = k.master_point(self.xi_n, nodes_n)

    def _facet_part(self, values: np.ndarray) -> np.ndarray:
        """The facet's own nodes (the dofs of ``xhat_n``) of an array over the dofs of
        ``xhat`` (unrolled, ``nx * gdim`` per point): a copy (with the facet normal,
        ``nx = nn``, a view would follow the later searches)."""
        k = self.kinematics
        return values.reshape(-1, k.nx * k.gdim)[:, : self._facet_dofs].flatten()

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """The last step's master nodes (gathered from the displacement)."""
        return [self.xhat_n]

    def residuals(self, ds: ufl.Measure) -> list[ufl.Form]:
        """The zero residual of ``xhat_n``: it has no equation of its own, but derivatives
        with respect to it are assembled and chained onto the displacement by T."""
        return [self._zero * ufl.dot(self.xhat_n, ufl.TestFunction(self.Qn)) * ds]

    def gathers(self) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """The last step's master nodes gather what the converged projection gathered."""
        if self._gather_n is None:
            self._gather_n = np.full_like(self._facet_part(self.kinematics.gather), -1)
        return [(self.xhat_n, self._gather_n)]

    def follow(self, x: PETSc.Vec, gathers: list[tuple[dolfinx.fem.Function, np.ndarray]]) -> None:
        """Current positions of the last step's master facet nodes at the unknowns ``x``:
        ``xhat_n,commit + P_n (u - u_commit)``, read from ``x`` at the columns of this
        field's gather in ``gathers`` (the nodes may live on any rank; a column ``-1``, a
        point out of contact, keeps the committed positions)."""
        xhat = self.kinematics.xhat
        owned = len(self._gather_n)
        if self._x_commit is None:
            owned_x = owned // self._facet_dofs * xhat.function_space.dofmap.index_map_bs
            self.xhat_n.x.array[:owned] = self._facet_part(xhat.x.array[:owned_x])
        else:
            if self._work is None:  # once a step: the committed columns are the step's
                self._work = (x.duplicate(), GlobalValues(x, self._gather_n))
            dx, reader = self._work
            x.copy(dx)
            dx.axpy(-1.0, self._x_commit)
            columns = next(cols for f, cols in gathers if f is self.xhat_n)
            moved = np.where(columns >= 0, reader.read(dx), 0.0)
            self.xhat_n.x.array[:owned] = self._xhat_n_commit + moved
        self.xhat_n.x.scatter_forward()

    def commit(self, x) -> None:
        """Remember the converged projection (it becomes the reference in
        :meth:`begin_step`)."""
        k = self.kinematics
        owned = len(k.gather)
        self._committed = (
            self._facet_part(k.gather),
            self._facet_part(k.xhat.x.array[:owned]),
            x.copy(),
            k.xi0.x.array.copy(),
            k.mask.x.array.copy(),
            self._facet_part(k.xhat.x.array),
        )

    def begin_step(self) -> None:
        """The last committed projection becomes the reference of the slip (idempotent:
        a step cut back and tried again starts from the same reference)."""
        if self._committed is None:
            return
        gather, xhat_owned, x, xi, mask, xhat = self._committed
        self._gather_n = gather
        self._work = None  # the columns read change with the step
        self._xhat_n_commit = xhat_owned
        self._x_commit = x
        self.xi_n.x.array[:] = xi
        self.mask_n.x.array[:] = mask
        self.xhat_n.x.array[:] = xhat
        self._committed = None

    def y_n_at_points(self) -> np.ndarray:
        """``y_n`` at the owned slave points, ``(n, gdim)``."""
        k, slave, gdim = self.kinematics, self.kinematics.slave, self.kinematics.gdim
        npts = slave.num_cells * slave.num_points
        nodes = slave.at_points(self.xhat_n).reshape(npts, k.nn, gdim)
        N_n = shape_functions(k.nn, gdim, slave.at_points(self.xi_n))[0]
        return np.einsum("pa,pad->pd", N_n, nodes)
