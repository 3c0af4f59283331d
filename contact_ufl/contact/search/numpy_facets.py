"""The master facets as the NumPy back end sees them: per-facet data (centroid, radius, the
slab of the distance lower bound, the Gram inverse of a triangle, the bilinear form of a
quadrilateral), the exact projections of (point, facet) pairs, vectorised over the pairs,
and the linearisation ``M`` of the closest points (:mod:`.projection`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from contact_ufl.contact.search.curved import (
    CURVED_EDGES,
    bernstein_hull,
    curve_closest,
    quadrilateral_interior,
    triangle_interior,
)
from contact_ufl.contact.search.kinds import EDGES, QUADRATIC, FloatArray, IntArray, facet_kind
from contact_ufl.contact.search.shapes import centre_normal, normalise
from contact_ufl.contact.search.trees import TreeCache, tree_levels

_NEWTON_ITERATIONS = 25


_NEWTON_TOL = 1e-13  # on the reference-coordinate step


@dataclass
class Pairs:
    """Exact projections of (point, facet) pairs."""

    xi: FloatArray  # (P, fdim)
    dist: FloatArray  # (P,)
    edge: IntArray  # (P,) -1 interior, else edge number in EDGES[kind]
    vertex: npt.NDArray[np.bool_]  # (P,) closest point at a vertex


def concatenate(a: Pairs, b: Pairs) -> Pairs:
    """The pairs of ``a`` followed by those of ``b``."""
    return Pairs(
        xi=np.concatenate([a.xi, b.xi]),
        dist=np.concatenate([a.dist, b.dist]),
        edge=np.concatenate([a.edge, b.edge]),
        vertex=np.concatenate([a.vertex, b.vertex]),
    )


def _centroid_radius(
    X: list[list[FloatArray]],
) -> tuple[list[FloatArray], list[list[FloatArray]], FloatArray]:
    """Centroid columns (the mean of the points), the offsets of the points from it and the
    radius ``R_f`` (largest offset) of each facet from the coordinate columns ``X[a][k]`` of
    its hull points: every point of a facet is a convex combination of its hull points (also
    for the bilinear quadrilateral), so it lies within ``R_f`` of the centroid."""
    points_per_facet, g = len(X), len(X[0])
    c = []
    for k in range(g):
        ck = X[0][k] + X[1][k]
        for a in range(2, points_per_facet):
            ck += X[a][k]
        c.append(ck / points_per_facet)
    offsets = [[Xa[k] - c[k] for k in range(g)] for Xa in X]
    radius2 = sum(dk * dk for dk in offsets[0])
    for d in offsets[1:]:
        np.maximum(radius2, sum(dk * dk for dk in d), out=radius2)
    return c, offsets, np.sqrt(radius2)


def _bilinear(X: list[list[FloatArray]]) -> list[list[FloatArray]]:
    """``y = c0 + s c1 + t c2 + s t c3`` of bilinear quadrilaterals, by coordinate columns."""
    x0, x1, x2, x3 = X
    return [
        x0,
        [x1[k] - x0[k] for k in range(3)],
        [x2[k] - x0[k] for k in range(3)],
        [x0[k] - x1[k] - x2[k] + x3[k] for k in range(3)],
    ]


class MasterFacets:
    """Master facets with the per-facet data of the search and the projections.

    The facets are sorted by their radius ``R_f`` into levels (:func:`tree_levels`), each
    with a KD-tree of its centroids, taken from ``trees`` (a :class:`TreeCache`, if given)
    when a master surface of the same shape was searched before and no node of the level has
    moved more than ``_MOVE R`` (``R`` the largest radius of the level) since that tree was
    built: the level's ``slack`` is then that movement, a bound of how far every centroid is
    from the one the tree holds, and the search widens its bounds by it.
    """

    def __init__(self, nodes: FloatArray, trees: TreeCache | None = None) -> None:
        self.nodes = nodes
        self.nf, self.nodes_per_facet, self.gdim = nodes.shape
        self.fdim = self.gdim - 1
        self.kind = facet_kind(self.nodes_per_facet, self.gdim)
        g = self.gdim
        # the points whose convex hull holds the facet: its nodes, or the Bernstein control
        # points of a quadratic facet (which is not in the convex hull of its nodes)
        hull = bernstein_hull(self.kind, nodes) if self.kind in QUADRATIC else nodes
        # per-facet data from the coordinate columns of the nodes (a loop over the few nodes
        # and coordinates of a facet: reductions over such short axes are slow in NumPy)
        X = [
            [np.ascontiguousarray(nodes[:, a, k]) for k in range(g)]
            for a in range(self.nodes_per_facet)
        ]
        if hull is not nodes:
            X_nodes = X
            X = [
                [np.ascontiguousarray(hull[:, a, k]) for k in range(g)]
                for a in range(self.nodes_per_facet)
            ]
        c, offsets, self.size = _centroid_radius(X)
        self.centroid = np.stack(c, axis=1)
        self.R_max = float(self.size.max()) if self.nf else 0.0
        trees = trees if trees is not None else TreeCache()
        self.levels = tree_levels(hull, self.centroid, self.size, trees)
        # slab of the facet: unit normal at the centre, largest hull offset along it
        n = normalise(centre_normal(X if hull is nodes else X_nodes, self.nodes_per_facet, g))
        self.axis = np.stack(n, axis=1)
        thickness = np.abs(sum(offsets[0][k] * n[k] for k in range(g)))
        for d in offsets[1:]:
            np.maximum(thickness, np.abs(sum(d[k] * n[k] for k in range(g))), out=thickness)
        self.thickness = thickness
        # the data of the lower bound as contiguous columns (gathered per pair: cheaper than
        # rows) c_0 .. c_g-1, n_0 .. n_g-1, T, R
        self.slab = (*c, *n, self.thickness, self.size)
        if self.kind == "triangle":
            a1 = [X[1][k] - X[0][k] for k in range(3)]
            a2 = [X[2][k] - X[0][k] for k in range(3)]
            g11, g12, g22 = _dot3(a1, a1), _dot3(a1, a2), _dot3(a2, a2)
            det = g11 * g22 - g12 * g12
            ok = det > 1e-14 * g11 * g22
            inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)  # degenerate: never inside
            self.gram_inv = (g22 * inv, -g12 * inv, g11 * inv)
        elif self.kind == "quadrilateral":
            self.bilinear = _bilinear(X)

    def lower_bound(self, x: FloatArray, f: IntArray, pid: IntArray | None = None) -> FloatArray:
        """A lower bound of the distance of the points ``x`` (P, gdim) to the facets ``f``
        (of the points ``x[pid]`` if ``pid`` is given).

        Every facet point ``p`` lies in the convex hull of the nodes (of a quadratic facet, of
        its Bernstein control points), so within ``R_f`` of the centroid ``c`` and within
        ``T_f`` of it along the normal ``n`` at the centre: with ``d = x - c``,
        ``|x - p|^2 >= (|n . d| - T_f)_+^2 + (|d - (n . d) n| - R_f)_+^2``.
        """
        g, slab = self.gdim, self.slab
        if pid is None:
            d = [x[:, k] - slab[k][f] for k in range(g)]
        else:
            d = [x[:, k][pid] - slab[k][f] for k in range(g)]
        normal = d[0] * slab[g][f]
        square = d[0] * d[0]
        for k in range(1, g):
            normal += d[k] * slab[g + k][f]
            square += d[k] * d[k]
        normal = np.abs(normal)
        tangent = np.sqrt(np.maximum(square - normal * normal, 0.0))
        a = np.maximum(normal - slab[2 * g][f], 0.0)
        b = np.maximum(tangent - slab[2 * g + 1][f], 0.0)
        return np.sqrt(a * a + b * b)

    # -- exact projections on (point, facet) pairs ----------------------------------------

    def project(self, x: FloatArray, f: IntArray, pid: IntArray, npts: int) -> Pairs:
        """Project the points ``x`` (P, gdim) on the facets ``f`` (P,).

        ``pid`` (P,) numbers the points of the pairs (``0 <= pid < npts``); the quadrilateral
        projection uses it to skip the facets that cannot hold the closest point.
        """
        # coordinate columns of the pairs' nodes and points (cheaper than rows of 2 or 3)
        if self.kind in QUADRATIC:
            return self._project_quadratic(x, self.nodes[f])
        g = self.gdim
        X = [[self.nodes[:, a, k][f] for k in range(g)] for a in range(self.nodes_per_facet)]
        xs = [x[:, k] for k in range(g)]
        pairs = self._edges(xs, X)
        if self.kind == "segment":
            pairs.edge[:] = -1
        elif self.kind == "triangle":
            self._triangle_interior(xs, X, f, pairs)
        else:
            self._quadrilateral_interior(x, f, pid, npts, pairs)
        return pairs

    def _project_quadratic(self, x: FloatArray, nodes: FloatArray) -> Pairs:
        """Project the points ``x`` (P, gdim) on the quadratic facets ``nodes`` (P, nodes, gdim):
        the closest point on the (curved) edges, replaced by an interior minimum of a
        6-node triangle or 9-node quadrilateral where that is closer (:mod:`.curved`)."""
        if self.kind == "segment3":
            u, dist = curve_closest(x, nodes[:, 0], nodes[:, 1], nodes[:, 2])
            edge = np.full(len(u), -1, dtype=np.int64)
            return Pairs(xi=u[:, None], dist=dist, edge=edge, vertex=(u == 0.0) | (u == 1.0))
        best_d = best_u = None
        best_k = np.zeros(len(x), dtype=np.int64)
        for n, (i, j, m) in enumerate(CURVED_EDGES[self.kind]):
            u, d = curve_closest(x, nodes[:, i], nodes[:, j], nodes[:, m])
            if best_d is None:
                best_d, best_u = d, u
                continue
            better = d < best_d
            best_d, best_u = np.where(better, d, best_d), np.where(better, u, best_u)
            best_k = np.where(better, n, best_k)
        starts = np.array([s for _, _, s, _ in EDGES[self.kind]])
        ends = np.array([e for _, _, _, e in EDGES[self.kind]])
        xi = starts[best_k] + best_u[:, None] * (ends[best_k] - starts[best_k])
        pairs = Pairs(xi=xi, dist=best_d, edge=best_k, vertex=(best_u == 0.0) | (best_u == 1.0))
        interior = triangle_interior if self.kind == "triangle6" else quadrilateral_interior
        xi_in, dist_in, inner = interior(x, nodes)
        take = np.flatnonzero(inner & (dist_in < pairs.dist))
        pairs.xi[take] = xi_in[take]
        pairs.dist[take] = dist_in[take]
        pairs.edge[take] = -1
        pairs.vertex[take] = False
        return pairs

    def _edges(self, xs: list[FloatArray], X: list[list[FloatArray]]) -> Pairs:
        """Closest point on the straight edges of each facet (a segment is its own edge).

        ``xs``: coordinate columns of the points; ``X[a][k]``: coordinate ``k`` of node ``a``
        of the facet of each pair.
        """
        g = len(xs)
        edges = EDGES.get(self.kind, ((0, 1, (0.0,), (1.0,)),))
        best_d = best_u = best_k = None
        for n, (a, b, _, _) in enumerate(edges):
            e = [X[b][k] - X[a][k] for k in range(g)]
            r = [xs[k] - X[a][k] for k in range(g)]
            ee = sum(e[k] * e[k] for k in range(1, g)) + e[0] * e[0]
            re = sum(r[k] * e[k] for k in range(1, g)) + r[0] * e[0]
            u = np.clip(re / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
            w = [r[k] - u * e[k] for k in range(g)]
            d = np.sqrt(sum(w[k] * w[k] for k in range(1, g)) + w[0] * w[0])
            if best_d is None:
                best_d, best_u, best_k = d, u, np.zeros(d.shape, dtype=np.int64)
                continue
            better = d < best_d
            best_d = np.where(better, d, best_d)
            best_u = np.where(better, u, best_u)
            best_k = np.where(better, n, best_k)
        starts = np.array([s for _, _, s, _ in edges])
        ends = np.array([e for _, _, _, e in edges])
        xi = starts[best_k] + best_u[:, None] * (ends[best_k] - starts[best_k])
        return Pairs(xi=xi, dist=best_d, edge=best_k, vertex=(best_u == 0.0) | (best_u == 1.0))

    def _triangle_interior(
        self, xs: list[FloatArray], X: list[list[FloatArray]], f: IntArray, pairs: Pairs
    ) -> None:
        """Replace the edge result by the projection on the plane where that is inside."""
        a1 = [X[1][k] - X[0][k] for k in range(3)]
        a2 = [X[2][k] - X[0][k] for k in range(3)]
        r = [xs[k] - X[0][k] for k in range(3)]
        b1 = r[0] * a1[0] + r[1] * a1[1] + r[2] * a1[2]
        b2 = r[0] * a2[0] + r[1] * a2[1] + r[2] * a2[2]
        g11, g12, g22 = (column[f] for column in self.gram_inv)
        xi1 = g11 * b1 + g12 * b2
        xi2 = g12 * b1 + g22 * b2
        inside = (xi1 > 0.0) & (xi2 > 0.0) & (xi1 + xi2 < 1.0)
        if not inside.any():
            return
        i = np.flatnonzero(inside)
        xi1, xi2 = xi1[i], xi2[i]
        w = [r[k][i] - xi1 * a1[k][i] - xi2 * a2[k][i] for k in range(3)]
        pairs.xi[i] = np.stack([xi1, xi2], axis=1)
        pairs.dist[i] = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        pairs.edge[i] = -1
        pairs.vertex[i] = False

    def _quadrilateral_interior(
        self, x: FloatArray, f: IntArray, pid: IntArray, npts: int, pairs: Pairs
    ) -> None:
        """Replace the edge result by an interior stationary point where that is closer."""
        # skip the pairs whose facet is farther than a facet point of another pair (upper
        # bounds: the distances to the centroid and to the edges)
        dc = np.linalg.norm(x - self.centroid[f], axis=1)
        upper = np.full(npts, np.inf)
        np.minimum.at(upper, pid, np.minimum(dc, pairs.dist))
        lower = self.lower_bound(x, f)
        todo = np.flatnonzero(lower <= upper[pid] * (1 + 1e-9) + 1e-9 * self.size[f])
        if todo.size == 0:
            return
        X = x[todo]
        coef = [[column[f[todo]] for column in cj] for cj in self.bilinear]
        xi, dist, conv, pd = _quad_newton(X, coef, np.full((todo.size, 2), 0.5))
        # not converged, or stuck inside at a saddle or maximum: restart from four other points
        inner = np.all((xi > 0.0) & (xi < 1.0), axis=1)
        redo = np.flatnonzero(~conv | (inner & ~pd))
        if redo.size:
            for start in ((0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)):
                xi_r, dist_r, _, pd_r = _quad_newton(
                    X[redo],
                    [[column[redo] for column in cj] for cj in coef],
                    np.tile(start, (redo.size, 1)),
                )
                inner_r = np.all((xi_r > 0.0) & (xi_r < 1.0), axis=1)
                inner = np.all((xi[redo] > 0.0) & (xi[redo] < 1.0), axis=1)
                better = inner_r & (~inner | (dist_r < dist[redo]))
                xi[redo[better]] = xi_r[better]
                dist[redo[better]] = dist_r[better]
        inner = np.all((xi > 0.0) & (xi < 1.0), axis=1)
        take = inner & (dist < pairs.dist[todo])
        i = todo[take]
        pairs.xi[i] = xi[take]
        pairs.dist[i] = dist[take]
        pairs.edge[i] = -1
        pairs.vertex[i] = False


def _quad_newton(
    x: FloatArray, coef: list[list[FloatArray]], xi: FloatArray
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """Minimise ``|x - y(s, t)|^2`` over ``[0, 1]^2`` on bilinear patches by projected Newton.

    ``y = c0 + s c1 + t c2 + s t c3`` with ``coef[j][k]`` the column of coordinate ``k`` of
    ``c_j``. The Hessian is replaced by the Gauss-Newton matrix where it is not positive
    definite; a coordinate on a bound that the gradient pushes outwards is held there; the
    iterate is clamped to the box after each step, and a step that increases the distance is
    halved (at most three times).

    Returns the final ``xi`` (P, 2), its distance, whether the step fell below the tolerance,
    and whether the Hessian is positive definite there.
    """
    P = x.shape[0]
    # coordinate columns: C[j][k] = coordinate k of c_j, X[k] of the points
    C = coef
    X = [np.ascontiguousarray(x[:, k]) for k in range(3)]
    s_all, t_all = xi[:, 0].copy(), xi[:, 1].copy()
    conv = np.zeros(P, dtype=bool)
    act = np.arange(P)
    c, xa, s, t = C, X, s_all, t_all  # the columns of the active points

    def residual(s_: FloatArray, t_: FloatArray) -> list[FloatArray]:
        return [
            xa[k] - (c[0][k] + s_ * c[1][k] + t_ * c[2][k] + s_ * t_ * c[3][k]) for k in range(3)
        ]

    for _ in range(_NEWTON_ITERATIONS):
        if act.size == 0:
            break
        a1 = [c[1][k] + t * c[3][k] for k in range(3)]
        a2 = [c[2][k] + s * c[3][k] for k in range(3)]
        r = residual(s, t)
        g1, g2 = -_dot3(r, a1), -_dot3(r, a2)
        h11, h22, h12gn = _dot3(a1, a1), _dot3(a2, a2), _dot3(a1, a2)
        h12 = h12gn - _dot3(r, c[3])
        det = h11 * h22 - h12 * h12
        indefinite = det <= 1e-12 * h11 * h22
        h12 = np.where(indefinite, h12gn, h12)
        det = h11 * h22 - h12 * h12
        det = np.where(det > 0, det, np.inf)  # degenerate patch: no step
        step1, step2 = -(h22 * g1 - h12 * g2) / det, -(h11 * g2 - h12 * g1) / det
        # projected Newton: a coordinate on a bound that the gradient pushes out stays there,
        # the other one takes a one-dimensional Newton step (d2f/dxi_i^2 = |a_i|^2)
        fix1 = ((s <= 0.0) & (g1 > 0.0)) | ((s >= 1.0) & (g1 < 0.0))
        fix2 = ((t <= 0.0) & (g2 > 0.0)) | ((t >= 1.0) & (g2 < 0.0))
        one = fix1 ^ fix2
        if one.any():
            step1 = np.where(one, np.where(fix1, 0.0, -g1 / np.where(h11 > 0, h11, np.inf)), step1)
            step2 = np.where(one, np.where(fix2, 0.0, -g2 / np.where(h22 > 0, h22, np.inf)), step2)
        both = fix1 & fix2
        step1, step2 = np.where(both, 0.0, step1), np.where(both, 0.0, step2)
        f0 = _dot3(r, r)
        new_s, new_t = np.clip(s + step1, 0.0, 1.0), np.clip(t + step2, 0.0, 1.0)
        for _ in range(3):
            rn = residual(new_s, new_t)
            worse = _dot3(rn, rn) > f0 * (1 + 1e-10)  # not rounding noise near the minimum
            if not worse.any():
                break
            step1, step2 = np.where(worse, step1 * 0.5, step1), np.where(worse, step2 * 0.5, step2)
            new_s = np.where(worse, np.clip(s + step1, 0.0, 1.0), new_s)
            new_t = np.where(worse, np.clip(t + step2, 0.0, 1.0), new_t)
        done = np.maximum(np.abs(new_s - s), np.abs(new_t - t)) <= _NEWTON_TOL
        s_all[act], t_all[act] = new_s, new_t
        conv[act[done]] = True
        keep = ~done
        act = act[keep]
        c = [[column[keep] for column in cj] for cj in c]
        xa = [column[keep] for column in xa]
        s, t = new_s[keep], new_t[keep]

    c, xa, s, t = C, X, s_all, t_all
    a1 = [c[1][k] + t * c[3][k] for k in range(3)]
    a2 = [c[2][k] + s * c[3][k] for k in range(3)]
    r = residual(s, t)
    h11, h22 = _dot3(a1, a1), _dot3(a2, a2)
    h12 = _dot3(a1, a2) - _dot3(r, c[3])
    pd = (h11 > 0) & (h11 * h22 - h12 * h12 > 0)
    return np.stack([s, t], axis=1), np.sqrt(_dot3(r, r)), conv, pd


def _dot3(a: list[FloatArray], b: list[FloatArray]) -> FloatArray:
    """Dot products of vectors given as three coordinate columns."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def sliding_matrix(
    master: MasterFacets,
    xi: FloatArray,
    a: FloatArray,
    r: FloatArray,
    d2N: FloatArray,
    f: IntArray,
    edge: IntArray,
    vertex: npt.NDArray[np.bool_],
) -> FloatArray:
    """Linearisation matrix ``M`` of the closest points (:mod:`.projection`)."""
    P, fdim = xi.shape
    g = master.gdim
    # A_ab = a_a . a_b - (x - y) . d(a_a)/d(xi^b),  d(a_a)/d(xi^b) = sum_n d2N_n x_n: zero
    # on a straight facet but for the bilinear quadrilateral, whose only second derivative
    # is d2y/ds dt = c3; the curvature term of a quadratic facet from d2N
    col = [[a[:, i, k] for k in range(g)] for i in range(fdim)]
    curvature = None
    if master.kind in QUADRATIC:
        curv = np.einsum("pnab,png->pabg", d2N, master.nodes[f])
        curvature = np.einsum("pg,pabg->pab", r, curv)
    sliding = np.zeros((P, fdim, fdim))
    if fdim == 1:
        A11 = sum(c * c for c in col[0])
        if curvature is not None:
            A11 = A11 - curvature[:, 0, 0]
        ok = ~vertex & (A11 != 0)
        sliding[:, 0, 0] = np.where(ok, 1.0 / np.where(ok, A11, 1.0), 0.0)
        return sliding
    A00 = sum(c * c for c in col[0])
    A11 = sum(c * c for c in col[1])
    A01 = sum(c0 * c1 for c0, c1 in zip(col[0], col[1], strict=True))
    if master.kind == "quadrilateral":
        c3 = master.bilinear[3]
        A01 = A01 - sum(r[:, k] * c3[k][f] for k in range(g))
    if curvature is not None:
        A00 = A00 - curvature[:, 0, 0]
        A11 = A11 - curvature[:, 1, 1]
        A01 = A01 - curvature[:, 0, 1]
    interior = (edge < 0) & ~vertex
    det = A00 * A11 - A01 * A01
    ok = interior & (det != 0)
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    sliding[:, 0, 0] = A11 * inv
    sliding[:, 1, 1] = A00 * inv
    sliding[:, 0, 1] = sliding[:, 1, 0] = -A01 * inv
    on_edge = (edge >= 0) & ~vertex
    if on_edge.any():
        tangents = np.array([np.subtract(e, s) for _, _, s, e in EDGES[master.kind]])
        i = np.flatnonzero(on_edge)
        t0, t1 = tangents[edge[i], 0], tangents[edge[i], 1]
        tAt = t0 * (A00[i] * t0 + A01[i] * t1) + t1 * (A01[i] * t0 + A11[i] * t1)
        tAt = np.where(tAt != 0, tAt, np.inf)
        sliding[i, 0, 0] = t0 * t0 / tAt
        sliding[i, 0, 1] = sliding[i, 1, 0] = t0 * t1 / tAt
        sliding[i, 1, 1] = t1 * t1 / tAt
    return sliding
