"""The contact kinematics of a meshed master side in UFL: the projected point, the master
normal, the proximity and the master virtual displacement at the projected point.

What UFL cannot see, the master surface at the projected points, is carried to every slave
quadrature point as data on the slave submesh (quadrature elements):

``xhat``
    the current positions of the nodes of the master facet found by the closest-point
    projection. It is a *field of the assembled system* (it has a test function, which is
    the master virtual displacement at the nodes), tied to the unknowns by ``xhat = Xhat +
    P u`` (``P`` gathers master dofs; see :mod:`contact_ufl.layout`).
``xhat0, x0, xi0, M``
    copies of the current master nodes and slave point, the reference coordinates of the
    projection and its linearisation matrix (:mod:`.projection`), held as data.

The projected point is written as ``xi = xi0 + M b(x - x0, xhat - xhat0)`` (the linearised
closest-point condition of ``consistent-tangent.md``): its value is the one found by the
search, and its Gateaux derivative is the implicit-function derivative. The master point
``y(xi)``, the tangents ``a_alpha(xi)``, the normal ``nu`` and the proximity ``g = -nu . (x -
y)`` are then UFL expressions of the unknowns, and ``ufl.derivative`` gives every term of
the tangent (sliding of ``y``, rotation of ``nu``, ``Grad U2*`` times ``d xi``).
"""

from __future__ import annotations

import dolfinx
import numpy as np
import ufl

from contact_ufl.contact.master import MeshMaster
from contact_ufl.contact.search import Pairing
from contact_ufl.contact.slave import SlaveSurface


def master_shape_functions(nn: int, xi: ufl.core.expr.Expr) -> tuple[list, list]:
    """UFL shape functions of a master facet and their xi-derivatives.

    Conventions as in :mod:`.projection`: segment (2 nodes), triangle (3 nodes), bilinear
    quadrilateral (4 nodes, basix vertex order).
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


class MeshKinematics:
    """Gap, normal and projected point of the slave points on a meshed master side.

    Parameters
    ----------
    u
        The displacement.
    slave, master
        The two sides of the pair.

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

    def __init__(self, u: dolfinx.fem.Function, slave: SlaveSurface, master: MeshMaster):
        self.u, self.slave, self.master = u, slave, master
        self.gdim = u.function_space.mesh.geometry.dim
        self.fdim = self.gdim - 1
        self.nn, self.nx = master.nn, master.nx
        space = slave.point_space
        self.Qx = space((self.nx * self.gdim,))
        self.xhat = dolfinx.fem.Function(self.Qx, name="master_nodes")
        self.xhat0 = dolfinx.fem.Function(self.Qx)
        self.x0 = dolfinx.fem.Function(space((self.gdim,)))
        self.xi0 = dolfinx.fem.Function(space((self.fdim,)))
        self.M = dolfinx.fem.Function(space((self.fdim, self.fdim)))
        self.mask = dolfinx.fem.Function(space(()))
        #: (smoothed normal) whether the neighbour before / after the facet exists
        self.neighbour_flags = dolfinx.fem.Function(space((2,))) if master.smoothed else None
        #: Freeze the projected point inside a Newton iteration (drop its variation from the
        #: tangent, as many codes do): Newton then converges only linearly. For comparisons.
        self.frozen_projection = False
        #: the closest points of the last search
        self.projection = None
        self._build()

    def nodes(self, f) -> ufl.core.expr.Expr:
        """The gathered nodes of a point field of ``xhat``'s shape, as an ``(nx, gdim)``
        UFL matrix."""
        gdim = self.gdim
        return ufl.as_matrix([[f[a * gdim + i] for i in range(gdim)] for a in range(self.nx)])

    def _build(self) -> None:
        gdim, fdim, nn = self.gdim, self.fdim, self.nn
        X = ufl.SpatialCoordinate(self.u.function_space.mesh)
        self.x = x = X + self.u
        xh, xh0 = self.nodes(self.xhat), self.nodes(self.xhat0)
        N0, dN0 = master_shape_functions(nn, self.xi0)
        y0 = interpolate(N0, xh0, gdim)
        dxh = xh - xh0
        dx = x - self.x0
        b = []
        for al in range(fdim):
            a0 = interpolate([dN0[a][al] for a in range(nn)], xh0, gdim)
            slide = dx - interpolate(N0, dxh, gdim)
            b.append(
                ufl.dot(a0, slide)
                + ufl.dot(self.x0 - y0, interpolate([dN0[a][al] for a in range(nn)], dxh, gdim))
            )
        self.xi = xi = self.xi0 + self.M * ufl.as_vector(b)
        self.N, dN = master_shape_functions(nn, xi)
        self.y = interpolate(self.N, xh, gdim)
        if self.master.smoothed:
            self.nu = smoothed_normal(xi, xh, self.neighbour_flags, self.mask)
        else:
            tangents = [interpolate([dN[a][al] for a in range(nn)], xh, gdim) for al in range(fdim)]
            self.nu = facet_normal(tangents, self.mask)
        self.gap = -ufl.dot(self.nu, x - self.y)

    def master_point(self, xi, nodes) -> ufl.core.expr.Expr:
        """The master point of reference coordinates ``xi`` on the facet of ``nodes``."""
        N, _ = master_shape_functions(self.nn, xi)
        return interpolate(N, nodes, self.gdim)

    def test_at_projection(self, vhat: ufl.Argument) -> ufl.core.expr.Expr:
        """The master virtual displacement ``U2*(Y(X)) = sum_a N_a(xi) vhat_a``."""
        return interpolate(self.N, self.nodes(vhat), self.gdim)

    def set_pairing(self, pairing: Pairing) -> None:
        """Make the point data those of a new search result (value of xi, M, nodes...)."""
        slave, proj, paired = self.slave, pairing.projection, pairing.paired
        self.projection = proj
        npts = len(pairing.points)
        # (npts, nx * gdim), spelled out for a rank without slave points (npts = 0)
        xhat = pairing.nodes.reshape(npts, int(np.prod(pairing.nodes.shape[1:])))
        slave.set_at_points(self.xhat, xhat)
        slave.set_at_points(self.xhat0, xhat)
        slave.set_at_points(self.x0, pairing.points)
        slave.set_at_points(self.xi0, np.where(paired[:, None], proj.xi, 0.0))
        sliding = paired[:, None, None] & (not self.frozen_projection)
        slave.set_at_points(self.M, np.where(sliding, proj.sliding, 0.0))
        slave.set_at_points(self.mask, paired.astype(float))
        if self.neighbour_flags is not None:
            slave.set_at_points(self.neighbour_flags, pairing.flags)
