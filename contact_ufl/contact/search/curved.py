"""Closest points on quadratic (curved) master facets: 3-node segments, 6-node triangles
and 9-node quadrilaterals.

A degree-2 displacement makes every master facet a quadratic one once deformed (and a
degree-2 geometry makes it curved from the start): its current shape is
``y(xi) = sum_a N_a(xi) x_a`` with the quadratic Lagrange shape functions of its nodes,
the vertices then the edge midpoints (see :func:`.shapes.quadratic_shape_functions`). The
kernels here are vectorised over (point, facet) pairs, like those of :mod:`.numpy_facets`,
which uses them for the quadratic kinds:

* :func:`curve_closest`: the closest point of a quadratic curve (a 3-node segment, or an
  edge of a 6-node triangle): projected Newton on ``u`` in ``[0, 1]`` from the projection on
  the chord, compared with the two end points;
* :func:`triangle_interior`: an interior stationary point of ``|x - y(xi)|^2`` on a 6-node
  triangle (Newton from the projection on the plane of the vertices, restarted from the
  centroid where it may have missed an interior minimum: :func:`_restart`), to be compared
  with the closest points on the three curved edges; :func:`quadrilateral_interior`
  likewise on a 9-node quadrilateral (the facet of a quadratic hexahedron; Newton from the
  centre, restarted from up to four other points);
* :func:`bernstein_hull`: the Bernstein control points of a quadratic facet: the facet lies
  in their convex hull (the Bernstein weights are non-negative and sum to one), which is what
  the distance bounds of the candidate search need (a quadratic facet is *not* in the convex
  hull of its nodes).

A strongly curved facet seen from beyond its centre of curvature can have two local minima
of the distance; the one found from the chord (plane) projection is then not guaranteed
global. Facets of a mesh that resolves the surface are far from this.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from contact_ufl.contact.search.kinds import FloatArray
from contact_ufl.contact.search.shapes import quadratic_shape_functions

_ITERATIONS = 25


_TOL = 1e-13  # on the reference-coordinate step

#: Newton settled outside a facet is restarted from other points (an interior minimum may
#: remain) only where the point is farther than this fraction of the facet's radius of
#: curvature (:func:`curvature`): nearer, the facet would have to fold for the distance to
#: have a second minimum on it.
RESTART_CURVATURE = 0.2


#: The edges of a 6-node triangle: start vertex, end vertex, midpoint node (node order
#: ``v0, v1, v2, m01, m12, m02``), in the order of the straight triangle's edges.
TRIANGLE6_EDGES = ((0, 1, 3), (1, 2, 4), (0, 2, 5))


#: The edges of a 9-node quadrilateral (node order: the basix vertices ``v0 (0, 0), v1 (1,
#: 0), v2 (0, 1), v3 (1, 1)``, the midpoints of the edges 01, 13, 23, 02, then the centre),
#: in the order of the bilinear quadrilateral's edges.
QUADRILATERAL9_EDGES = ((0, 1, 4), (1, 3, 5), (2, 3, 6), (0, 2, 7))


#: The edges of each quadratic facet kind of two reference dimensions.
CURVED_EDGES = {"triangle6": TRIANGLE6_EDGES, "quadrilateral9": QUADRILATERAL9_EDGES}


def bernstein_hull(kind: str, nodes: FloatArray) -> FloatArray:
    """The Bernstein control points of quadratic facets ``nodes (nf, nodes, gdim)``: the
    vertices, and for an edge ``ij`` of midpoint node ``m`` the point ``2 m - (x_i + x_j)/2``.
    Every point of the facet is a convex combination of them."""
    hull = nodes.copy()
    edges = ((0, 1, 2),) if kind == "segment3" else CURVED_EDGES[kind]
    for i, j, m in edges:
        hull[:, m] = 2.0 * nodes[:, m] - 0.5 * (nodes[:, i] + nodes[:, j])
    if kind == "quadrilateral9":  # the centre: the 1D transform along s, then along t
        along_s = 2.0 * nodes[:, 8] - 0.5 * (nodes[:, 7] + nodes[:, 5])  # at t = 1/2
        hull[:, 8] = 2.0 * along_s - 0.5 * (hull[:, 4] + hull[:, 6])
    return hull


def curve_closest(
    x: FloatArray, A: FloatArray, B: FloatArray, C: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Closest points of ``x (P, g)`` on the quadratic curves through ``A`` (u = 0), ``C``
    (u = 1/2) and ``B`` (u = 1), ``u`` in ``[0, 1]``.

    ``y(u) = A + u b1 + u^2 b2`` (``b1 = 4C - 3A - B``, ``b2 = 2A + 2B - 4C``). Projected
    Newton on ``f(u) = |x - y(u)|^2 / 2`` from the projection on the chord ``AB`` (the
    Gauss-Newton curvature ``|y'|^2`` where ``f'' <= 0``, steps halved while ``f`` grows),
    then the best of that point and the two ends. Returns ``u`` (exactly 0 or 1 at an end)
    and the distance.
    """
    b1 = 4.0 * C - 3.0 * A - B
    b2 = 2.0 * A + 2.0 * B - 4.0 * C
    r0 = x - A
    chord = B - A
    cc = np.einsum("pg,pg->p", chord, chord)
    u = np.clip(np.einsum("pg,pg->p", r0, chord) / np.where(cc > 0, cc, 1.0), 0.0, 1.0)

    def residual(u_, rows):
        return r0[rows] - u_[:, None] * b1[rows] - (u_ * u_)[:, None] * b2[rows]

    act = np.arange(len(u))
    for _ in range(_ITERATIONS):
        if act.size == 0:
            break
        ua = u[act]
        r = residual(ua, act)
        dy = b1[act] + 2.0 * ua[:, None] * b2[act]
        g = -np.einsum("pg,pg->p", r, dy)
        gn = np.einsum("pg,pg->p", dy, dy)
        h = gn - 2.0 * np.einsum("pg,pg->p", r, b2[act])
        h = np.where(h > 1e-12 * gn, h, gn)
        step = -g / np.where(h > 0, h, np.inf)
        step = np.where(((ua <= 0.0) & (g > 0)) | ((ua >= 1.0) & (g < 0)), 0.0, step)
        f0 = np.einsum("pg,pg->p", r, r)
        new = np.clip(ua + step, 0.0, 1.0)
        for _ in range(3):
            rn = residual(new, act)
            worse = np.einsum("pg,pg->p", rn, rn) > f0 * (1 + 1e-10)
            if not worse.any():
                break
            step = np.where(worse, 0.5 * step, step)
            new = np.where(worse, np.clip(ua + step, 0.0, 1.0), new)
        done = np.abs(new - ua) <= _TOL
        u[act] = new
        act = act[~done]
    rows = np.arange(len(u))
    d_newton = np.linalg.norm(residual(u, rows), axis=1)
    d_start = np.linalg.norm(r0, axis=1)
    d_end = np.linalg.norm(x - B, axis=1)
    best = np.argmin(np.stack([d_newton, d_start, d_end], axis=1), axis=1)
    u = np.choose(best, [u, np.zeros_like(u), np.ones_like(u)])
    dist = np.choose(best, [d_newton, d_start, d_end])
    return u, dist


def quadrilateral_interior(
    x: FloatArray, nodes: FloatArray
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """Interior local minima of ``|x - y(xi)|^2`` on 9-node quadrilaterals ``nodes (P, 9,
    3)``, as :func:`triangle_interior`: Newton from the centre, restarted from four other
    points in turn while the last one calls for it (:func:`_restart`)."""
    kind = "quadrilateral9"
    xi, dist, good, settled = _newton(kind, x, nodes, np.full((len(x), 2), 0.5))
    again = _restart(kind, nodes, dist, good, settled)
    for start in ((0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)):
        redo = np.flatnonzero(again)
        if redo.size == 0:
            break
        xi_r, dist_r, good_r, settled_r = _newton(
            kind, x[redo], nodes[redo], np.tile(start, (redo.size, 1))
        )
        take = redo[good_r]
        xi[take], dist[take], good[take] = xi_r[good_r], dist_r[good_r], True
        again[redo] = _restart(kind, nodes[redo], dist_r, good_r, settled_r)
    return xi, dist, good


def triangle_interior(
    x: FloatArray, nodes: FloatArray
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """Interior local minima of ``|x - y(xi)|^2`` on 6-node triangles ``nodes (P, 6, 3)``.

    Newton on ``xi`` from the projection on the plane of the vertices (clamped into the
    triangle), restarted from the centroid where it does not settle at a strict local
    minimum, or settles outside the triangle at a distance over :data:`RESTART_CURVATURE`
    times its radius of curvature (nearer, the closest point is on an edge, which the
    caller projects): the Hessian
    ``a_a . a_b - (x - y) . y_,ab`` (the metric where that is not positive definite), steps
    halved while the distance grows. Returns ``xi (P, 2)``, the distance, and whether ``xi``
    is a strict interior minimum (converged, inside, positive definite Hessian).
    """
    v0, v1, v2 = nodes[:, 0], nodes[:, 1], nodes[:, 2]
    a1, a2 = v1 - v0, v2 - v0
    G = np.stack(
        [np.stack([_dot(a1, a1), _dot(a1, a2)], 1), np.stack([_dot(a1, a2), _dot(a2, a2)], 1)], 1
    )
    rhs = np.stack([_dot(x - v0, a1), _dot(x - v0, a2)], axis=1)
    det = np.linalg.det(G)
    ok = det > 1e-14 * G[:, 0, 0] * G[:, 1, 1]
    start = np.full((len(x), 2), 1.0 / 3.0)
    if ok.any():
        start[ok] = np.linalg.solve(G[ok], rhs[ok][:, :, None])[:, :, 0]
    start = np.clip(start, 0.0, 1.0)
    start /= np.maximum(start.sum(axis=1), 1.0)[:, None]
    xi, dist, good, settled = _newton("triangle6", x, nodes, start)
    redo = np.flatnonzero(_restart("triangle6", nodes, dist, good, settled))
    if redo.size:
        xi_r, dist_r, good_r, _ = _newton(
            "triangle6", x[redo], nodes[redo], np.full((redo.size, 2), 1.0 / 3.0)
        )
        take = redo[good_r]
        xi[take], dist[take], good[take] = xi_r[good_r], dist_r[good_r], True
    return xi, dist, good


def _restart(kind, nodes, dist, good, settled):
    """Whether Newton's result calls for a restart: not an interior minimum, and either not
    settled or settled at a distance over :data:`RESTART_CURVATURE` times the facet's radius
    of curvature (:func:`curvature`)."""
    far = dist * curvature(kind, nodes) > RESTART_CURVATURE
    return ~good & (~settled | far)


def curvature(kind: str, nodes: FloatArray) -> FloatArray:
    """A curvature scale of quadratic facets ``nodes (P, nodes, 3)`` of two reference
    dimensions: ``8 |delta| / L^2`` (that of a parabola of height ``|delta|`` over a chord
    ``L``), with ``delta`` the largest offset of a midpoint node from its chord's midpoint
    (of the centre node of a 9-node quadrilateral from the centre of the 8-node one through
    its other nodes) and ``L`` the shortest edge chord."""
    edges = CURVED_EDGES[kind]
    offset2 = np.max([_sq(nodes[:, m] - 0.5 * (nodes[:, i] + nodes[:, j])) for i, j, m in edges], 0)
    if kind == "quadrilateral9":
        serendipity = 0.5 * nodes[:, 4:8].sum(axis=1) - 0.25 * nodes[:, :4].sum(axis=1)
        offset2 = np.maximum(offset2, _sq(nodes[:, 8] - serendipity))
    chord2 = np.min([_sq(nodes[:, j] - nodes[:, i]) for i, j, _ in edges], axis=0)
    return 8.0 * np.sqrt(offset2) / chord2


def _sq(v: FloatArray) -> FloatArray:
    return v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2]


def _newton(kind, x, nodes, xi):
    """Newton iterations of :func:`triangle_interior` (:func:`quadrilateral_interior`)
    from ``xi``: ``xi``, the distance, whether ``xi`` is a strict interior local minimum and
    whether it is a strict local minimum of the facet's extension (converged, positive
    definite Hessian: *settled*, inside the facet or not)."""
    xi = xi.copy()
    conv = np.zeros(len(x), dtype=bool)
    act = np.arange(len(x))
    for _ in range(_ITERATIONS):
        if act.size == 0:
            break
        r, a, H, gn = _state(kind, x[act], nodes[act], xi[act])
        grad = -np.einsum("pg,pag->pa", r, a)
        det = H[:, 0, 0] * H[:, 1, 1] - H[:, 0, 1] * H[:, 1, 0]
        indefinite = (det <= 1e-12 * H[:, 0, 0] * H[:, 1, 1]) | (H[:, 0, 0] <= 0)
        H[indefinite] = gn[indefinite]
        det = H[:, 0, 0] * H[:, 1, 1] - H[:, 0, 1] * H[:, 1, 0]
        det = np.where(det > 0, det, np.inf)
        step = (
            -np.stack(
                [
                    H[:, 1, 1] * grad[:, 0] - H[:, 0, 1] * grad[:, 1],
                    H[:, 0, 0] * grad[:, 1] - H[:, 1, 0] * grad[:, 0],
                ],
                axis=1,
            )
            / det[:, None]
        )
        # keep the iterate near the triangle (a minimum outside it is on an edge)
        step = np.clip(step, -0.5, 0.5)
        f0 = _dot(r, r)
        new = xi[act] + step
        for _ in range(3):
            rn = x[act] - np.einsum(
                "pn,png->pg", quadratic_shape_functions(kind, new)[0], nodes[act]
            )
            worse = _dot(rn, rn) > f0 * (1 + 1e-10)
            if not worse.any():
                break
            step = np.where(worse[:, None], 0.5 * step, step)
            new = np.where(worse[:, None], xi[act] + step, new)
        done = np.abs(new - xi[act]).max(axis=1) <= _TOL
        xi[act] = new
        conv[act[done]] = True
        act = act[~done]
    r, _, H, _ = _state(kind, x, nodes, xi)
    inside = (xi[:, 0] > 0.0) & (xi[:, 1] > 0.0)
    inside &= (xi.sum(axis=1) < 1.0) if kind == "triangle6" else np.all(xi < 1.0, axis=1)
    pd = (H[:, 0, 0] > 0) & (H[:, 0, 0] * H[:, 1, 1] - H[:, 0, 1] * H[:, 1, 0] > 0)
    return xi, np.sqrt(_dot(r, r)), conv & pd & inside, conv & pd


def _state(kind, x, nodes, xi):
    """``x - y``, the tangents ``a (P, 2, 3)``, the Hessian of ``|x - y|^2 / 2`` and the
    metric at ``xi``."""
    N, dN, d2N = quadratic_shape_functions(kind, xi)
    r = x - np.einsum("pn,png->pg", N, nodes)
    a = np.einsum("pna,png->pag", dN, nodes)
    gn = np.einsum("pag,pbg->pab", a, a)
    curvature = np.einsum("pnab,png->pabg", d2N, nodes)
    H = gn - np.einsum("pg,pabg->pab", r, curvature)
    return r, a, H, gn


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("pg,pg->p", a, b)
