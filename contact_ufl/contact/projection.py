"""Closest-point projection of many slave points onto a master surface made of facets.

Every facet kind (segments, triangles, bilinear quadrilaterals, and the quadratic 3-node
segments, 6-node triangles and 9-node quadrilaterals) is searched by a compiled kernel
(``search_kernel.c``, built on first use by :mod:`.compiled`): a bounding-volume hierarchy
over the facets walked by branch and bound per point, with the exact projections of the
NumPy kernels below (and of :mod:`.curved`) and the tie-break between equidistant facets
(:func:`_select`) in C. ``CONTACT_UFL_SEARCH=numpy`` selects the NumPy search
(plus :class:`scipy.spatial.cKDTree` for the
candidates), vectorised over points and facets: the only Python loops run over a fixed small
number of items (nodes, edges and coordinates of a facet, Newton iterations, blocks of points,
levels). The hot kernels work on coordinate columns (one 1D gather per node coordinate) rather
than on rows of 2 or 3 numbers, which NumPy gathers and reduces slowly. Throughput:
``benchmarks/search.py``.

Facet kinds and conventions
---------------------------
The master facets are given as ``nodes``, an array ``(nf, nn, gdim)`` of current node
positions, already oriented by the caller. The kind follows from ``(nn, gdim)``:

* segment, ``nn = 2, gdim = 2``: ``N = [1 - xi, xi]``, ``xi`` in ``[0, 1]``,
  ``a1 = x1 - x0``, normal ``nu = (a1[1], -a1[0]) / |a1|``;
* triangle, ``nn = 3, gdim = 3``: ``N = [1 - xi1 - xi2, xi1, xi2]``, ``a1 = x1 - x0``,
  ``a2 = x2 - x0``, ``nu = a1 x a2 / |a1 x a2|``;
* quadrilateral, ``nn = 4, gdim = 3``, bilinear in the basix vertex order:
  ``N = [(1-s)(1-t), s(1-t), (1-s)t, st]``, ``(s, t)`` in ``[0, 1]^2``, ``a1 = dy/ds``,
  ``a2 = dy/dt``, ``nu = a1 x a2 / |a1 x a2|`` (not constant on a warped quadrilateral).
* quadratic segment, ``nn = 3, gdim = 2`` (``"segment3"``): the two ends, then the
  midpoint node; quadratic triangle, ``nn = 6, gdim = 3`` (``"triangle6"``): the vertices,
  then the midpoint nodes of the edges 01, 12, 02; quadratic quadrilateral, ``nn = 9, gdim =
  3`` (``"quadrilateral9"``): the basix vertices, the midpoint nodes of the edges 01, 13, 23,
  02, then the centre node. Quadratic Lagrange shape functions
  (:func:`.curved.quadratic_shape_functions`), the normal as above from the tangents at
  ``xi``: the facets of a degree-2 displacement (curved once deformed, or from the start on
  a degree-2 geometry), projected by the kernels of :mod:`.curved`.

With these conventions the proximity ``g = -nu . (x - y)`` is positive when the slave point
``x`` lies behind the master surface (penetration) and negative when it is in front of it.

Linearisation
-------------
The reference coordinates ``xi`` of the closest point move with the slave point ``x`` and the
master nodes ``x_a`` as ``d(xi) = M b``, with

``b_alpha = a_alpha . (dx - sum_a N_a dx_a) + (x - y) . sum_a dN_a/dxi^alpha dx_a``

and ``A_ab = a_a . a_b - (x - y) . d(a_a)/d(xi^b)``. ``M`` depends on where the closest point
lies, classified with the exact clamped reference coordinates (a coordinate clamped to its bound
is on that bound, one that is not clamped is not):

* strictly inside the facet: ``M = A^-1``;
* on an edge (one bound active, for the triangle ``xi1 = 0``, ``xi2 = 0`` or the hypotenuse
  ``xi1 + xi2 = 1``), ``t`` the edge direction in reference space: ``M = t t^T / (t^T A t)``;
* at a vertex (end point of a segment, two bounds active): ``M = 0``.
"""

from __future__ import annotations

import itertools
import os
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from contact_ufl.contact import compiled
from contact_ufl.contact.curved import (
    CURVED_EDGES,
    bernstein_hull,
    curve_closest,
    quadratic_shape_functions,
    quadrilateral_interior,
    triangle_interior,
)

__all__ = [
    "Projection",
    "SelfContact",
    "TreeCache",
    "closest_points",
    "facet_kind",
    "shape_functions",
]

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

#: Facet kind of each supported ``(nn, gdim)``.
_KINDS = {
    (2, 2): "segment",
    (3, 3): "triangle",
    (4, 3): "quadrilateral",
    (3, 2): "segment3",
    (6, 3): "triangle6",
    (9, 3): "quadrilateral9",
}

#: The quadratic (curved) kinds, projected by the kernels of :mod:`.curved`.
QUADRATIC = ("segment3", "triangle6", "quadrilateral9")

#: Straight edges of each 2D facet kind: (start node, end node, xi at start, xi at end).
#: Along an edge ``xi = xi_start + u (xi_end - xi_start)``, ``y = x_start + u (x_end - x_start)``.
_EDGES = {
    "triangle": (
        (0, 1, (0.0, 0.0), (1.0, 0.0)),  # xi2 = 0
        (1, 2, (1.0, 0.0), (0.0, 1.0)),  # xi1 + xi2 = 1
        (0, 2, (0.0, 0.0), (0.0, 1.0)),  # xi1 = 0
    ),
    "quadrilateral": (
        (0, 1, (0.0, 0.0), (1.0, 0.0)),  # t = 0
        (1, 3, (1.0, 0.0), (1.0, 1.0)),  # s = 1
        (2, 3, (0.0, 1.0), (1.0, 1.0)),  # t = 1
        (0, 2, (0.0, 0.0), (0.0, 1.0)),  # s = 0
    ),
}
#: the 6-node triangle has the straight triangle's edges in reference space (its nodes
#: there are the vertices; the midpoint nodes are in :data:`.curved.TRIANGLE6_EDGES`)
_EDGES["triangle6"] = _EDGES["triangle"]
_EDGES["quadrilateral9"] = _EDGES["quadrilateral"]

_K = {2: 8, 3: 16}  # neighbours of the first KD-tree query, by dimension
_TREES = 4  # KD-trees kept for reuse (one per master surface of a distinct shape)
_MOVE = 0.25  # a search tree is reused while no node has moved more than this times R_max
_LEVEL_RADIUS = 2.0  # facets of radius up to this times the median share the first KD-tree
_LEVEL_RATIO = 4.0  # ratio of the largest facet radii of successive KD-tree levels
_BLOCK = 1 << 12  # points processed at once (keeps the arrays of the candidate pairs in cache)
_NEWTON_ITERATIONS = 25
_NEWTON_TOL = 1e-13  # on the reference-coordinate step
_TIE = 1e-10  # relative distance tolerance of the tie-break
_ALIGN = 1e-12  # alignments (and relative squared centroid distances) equal in the tie-break
_CELLS = 64  # cells per dimension of the grid that orders the points
_SORT = 1 << 14  # facets above which the points are ordered by cells
_DIRECTIONS = {2: 8, 3: 32}  # normal bins of a self-contact search, by dimension
_DIRECTIONS_MIN = 1 << 10  # facets above which a self-contact search goes by normal bins
_FIELDS = ("facet", "xi", "y", "normal", "gap", "distance", "sliding")
#: The facet kinds of the compiled search (kind numbers of ``search_kernel.c``).
_COMPILED_KINDS = {
    "segment": 0,
    "triangle": 1,
    "quadrilateral": 2,
    "segment3": 3,
    "triangle6": 4,
    "quadrilateral9": 5,
}
NON_FINITE = "{what} of the closest-point search hold non-finite values (NaN or infinity)"


def non_finite(what: str, values: np.ndarray) -> str | None:
    """The message of :data:`NON_FINITE` for ``what`` (points, or facets' nodes: the rows of
    ``values``) naming how many rows hold a NaN or infinity and the first one, or ``None``
    if every value is finite."""
    bad = ~np.isfinite(values.reshape(len(values), -1)).all(axis=1)
    if not bad.any():
        return None
    first = int(np.argmax(bad))
    return NON_FINITE.format(what=what) + f": {int(bad.sum())} of {len(values)}, first row {first}"


#: An admissibility test of (point, facet) pairs: point and facet indices in, mask out.
Admit = Callable[[IntArray, IntArray], npt.NDArray[np.bool_]]


@dataclass
class Projection:
    """Closest points of slave points on a master surface.

    Attributes
    ----------
    facet : ndarray of int64, shape (np,)
        Index into the facets given of the facet holding the closest point, ``-1`` where no
        facet lies within the search radius.
    xi : ndarray, shape (np, fdim)
        Reference coordinates of the closest point on that facet.
    y : ndarray, shape (np, gdim)
        Closest point ``y = sum_a N_a(xi) x_a``.
    normal : ndarray, shape (np, gdim)
        Master unit normal ``nu`` at ``xi``.
    gap : ndarray, shape (np,)
        Proximity ``g = -nu . (x - y)``; ``g > 0`` means penetration.
    distance : ndarray, shape (np,)
        ``|x - y|``.
    sliding : ndarray, shape (np, fdim, fdim)
        Linearisation matrix ``M``: ``d(xi) = M b`` (see the module docstring).

    Notes
    -----
    Where ``facet == -1`` the other fields hold placeholders: ``xi = 0``, ``y = x`` (the slave
    point itself), ``normal = 0``, ``distance = inf``, ``gap = -inf`` (never in contact) and
    ``sliding = 0``.
    """

    facet: IntArray
    xi: FloatArray
    y: FloatArray
    normal: FloatArray
    gap: FloatArray
    distance: FloatArray
    sliding: FloatArray


@dataclass
class SelfContact:
    """Which (point, facet) pairs may pair when a surface is searched against itself.

    A point of a surface is at distance zero from the facet that holds it and close to that
    facet's neighbours: those are excluded by topology, not by a distance, so that no
    tolerance is needed. A pair (point ``p``, facet ``f``) is admissible when

    * ``f`` shares no node with the facet holding ``p`` (node numbers compared exactly), and
    * the normal ``n_f`` at the centre of ``f`` opposes the point's current outward normal
      ``n_p``: ``n_f . n_p < 0`` (a facet behind the point, on the same side of the body,
      faces the same way and is not a contact partner).

    Attributes
    ----------
    point_nodes : ndarray of int64, shape (np, m)
        Node numbers of the facet holding each point (``m`` nodes per slave facet).
    facet_nodes : ndarray of int64, shape (nf, nn)
        Node numbers of each master facet, in the same numbering (global or input indices).
    point_normals : ndarray, shape (np, gdim)
        Current outward unit normal of the surface at each point.
    """

    point_nodes: IntArray
    facet_nodes: IntArray
    point_normals: FloatArray

    def admissible(self, pid: IntArray, fid: IntArray, facet_normal: FloatArray) -> BoolArray:
        """Mask of the admissible pairs (points ``pid``, facets ``fid``, (P,) each), given
        the unit normals ``facet_normal`` (P, gdim) of the facets at their centres."""
        mine, theirs = self.point_nodes[pid], self.facet_nodes[fid]
        share = np.zeros(pid.shape, dtype=bool)
        for i in range(mine.shape[1]):
            for j in range(theirs.shape[1]):
                share |= mine[:, i] == theirs[:, j]
        opposed = _dot(self.point_normals[pid], facet_normal) < 0.0
        return ~share & opposed


def facet_kind(nn: int, gdim: int) -> str:
    """Name the facet kind of ``nn`` nodes in dimension ``gdim``.

    Parameters
    ----------
    nn : int
        Number of nodes of a facet.
    gdim : int
        Geometric dimension.

    Returns
    -------
    str
        ``"segment"``, ``"triangle"`` or ``"quadrilateral"``.

    Raises
    ------
    ValueError
        For any other combination.
    """
    try:
        return _KINDS[(int(nn), int(gdim))]
    except KeyError:
        raise ValueError(
            f"unsupported master facet: {nn} nodes in {gdim}D "
            "(segments: 2 nodes in 2D; triangles: 3 nodes, quadrilaterals: 4 nodes in 3D)"
        ) from None


def shape_functions(
    nn: int, gdim: int, xi: npt.ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Shape functions of a master facet and their first and second derivatives.

    Parameters
    ----------
    nn : int
        Number of nodes of the facet (2, 3 or 4).
    gdim : int
        Geometric dimension (2 for segments, 3 otherwise).
    xi : array_like, shape (np, fdim)
        Reference coordinates, ``fdim = gdim - 1``.

    Returns
    -------
    N : ndarray, shape (np, nn)
        Shape functions.
    dN : ndarray, shape (np, nn, fdim)
        ``dN[p, a, alpha] = dN_a / dxi^alpha``.
    d2N : ndarray, shape (np, nn, fdim, fdim)
        ``d2N[p, a, alpha, beta] = d2N_a / dxi^alpha dxi^beta``.
    """
    kind = facet_kind(nn, gdim)
    fdim = gdim - 1
    xi = np.asarray(xi, dtype=np.float64).reshape(-1, fdim)
    if kind in QUADRATIC:
        return quadratic_shape_functions(kind, xi)
    npts = xi.shape[0]
    dN = np.zeros((npts, nn, fdim))
    d2N = np.zeros((npts, nn, fdim, fdim))
    if kind == "segment":
        u = xi[:, 0]
        N = np.stack([1.0 - u, u], axis=1)
        dN[:, :, 0] = [-1.0, 1.0]
    elif kind == "triangle":
        N = np.stack([1.0 - xi[:, 0] - xi[:, 1], xi[:, 0], xi[:, 1]], axis=1)
        dN[:] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]
    else:
        s, t = xi[:, 0], xi[:, 1]
        N = np.stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t], axis=1)
        dN[:, :, 0] = np.stack([t - 1.0, 1.0 - t, -t, t], axis=1)
        dN[:, :, 1] = np.stack([s - 1.0, -s, 1.0 - s, s], axis=1)
        d2N[:, :, 0, 1] = d2N[:, :, 1, 0] = [1.0, -1.0, -1.0, 1.0]
    return N, dN, d2N


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("...i,...i->...", a, b)


def _normalise(v: list[FloatArray]) -> list[FloatArray]:
    """Unit vectors from the coordinate columns ``v``; zero where ``v`` is zero."""
    length = np.sqrt(sum(vk * vk for vk in v))
    scale = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0)
    return [vk * scale for vk in v]


def _tangents(dN: FloatArray, X: FloatArray) -> FloatArray:
    """Tangent vectors ``a[p, alpha] = sum_n dN[p, n, alpha] X[p, n]`` (P, fdim, gdim) from
    the shape function derivatives (P, nn, fdim) and the nodes (P, nn, gdim)."""
    a = dN[:, 0, :, None] * X[:, 0, None, :]
    for n in range(1, X.shape[1]):
        a += dN[:, n, :, None] * X[:, n, None, :]
    return a


def _unit_normal(a: FloatArray) -> FloatArray:
    """Unit normal from the tangent vectors ``a`` (P, fdim, gdim); zero if degenerate."""
    if a.shape[1] == 1:
        n = np.stack([a[:, 0, 1], -a[:, 0, 0]], axis=1)
    else:
        n = np.cross(a[:, 0], a[:, 1])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


@dataclass
class _Pairs:
    """Exact projections of (point, facet) pairs."""

    xi: FloatArray  # (P, fdim)
    dist: FloatArray  # (P,)
    edge: IntArray  # (P,) -1 interior, else edge number in _EDGES[kind]
    vertex: npt.NDArray[np.bool_]  # (P,) closest point at a vertex


def _centre_normal(X: list[list[FloatArray]], nn: int, g: int) -> list[FloatArray]:
    """Columns of the normal ``a1 x a2`` (2D: ``(a1[1], -a1[0])``) at the centre of each
    facet of ``nn`` nodes in dimension ``g``, from the coordinate columns ``X[a][k]`` of its
    nodes."""
    centre = 1.0 / 3.0 if facet_kind(nn, g) == "triangle6" else 0.5
    _, dN, _ = shape_functions(nn, g, np.full((1, g - 1), centre))
    a = [
        [
            sum(dN[0, n, alpha] * X[n][k] for n in range(nn) if dN[0, n, alpha] != 0)
            for k in range(g)
        ]
        for alpha in range(g - 1)
    ]
    if g == 2:
        return [a[0][1], -a[0][0]]
    a1, a2 = a
    return [
        a1[1] * a2[2] - a1[2] * a2[1],
        a1[2] * a2[0] - a1[0] * a2[2],
        a1[0] * a2[1] - a1[1] * a2[0],
    ]


def _directions(gdim: int) -> FloatArray:
    """Unit directions of the normal bins: 8 on the circle, 32 on the sphere (Fibonacci)."""
    if gdim == 2:
        t = np.arange(_DIRECTIONS[2]) * (2.0 * np.pi / _DIRECTIONS[2])
        return np.stack([np.cos(t), np.sin(t)], axis=1)
    n = _DIRECTIONS[3]
    z = 1.0 - (2.0 * np.arange(n) + 1.0) / n
    t = np.arange(n) * np.pi * (3.0 - np.sqrt(5.0))
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(t), r * np.sin(t), z], axis=1)


def _bins(normals: FloatArray, directions: FloatArray) -> tuple[IntArray, FloatArray]:
    """The bin (nearest direction) of each normal, and the largest angle between a bin's
    direction and its normals (a zero normal counts as at a right angle)."""
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    unit = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    cos = unit @ directions.T
    b = np.argmax(cos, axis=1)
    angle = np.arccos(np.clip(cos[np.arange(len(b)), b], -1.0, 1.0))
    spread = np.zeros(len(directions))
    np.maximum.at(spread, b, angle)
    return b, spread


def _by_direction(
    points: FloatArray,
    nodes: FloatArray,
    radius: float,
    rule: SelfContact,
    out: Projection,
    trees: TreeCache,
) -> None:
    """Self-contact search by normal bins: the points of a bin are searched against the
    facets of the bins that may face them only.

    A pair is admissible only if ``n_f . n_p < 0``. The normals are sorted into bins by the
    nearest of a few fixed directions; with ``theta`` a bin's largest angle between its
    direction and its normals, every pair of a point bin ``A`` and a facet bin ``B`` has
    ``n_f . n_p >= 0`` when ``angle(u_A, u_B) + theta_A + theta_B <= pi / 2``: the facets of
    such bins are inadmissible for those points and skipped (the facets around a point on its
    own side, which otherwise fill every query up to the partner across the gap). The
    admissible pairs are all kept (facets in their given order): the same closest points.
    The search trees of each point bin are kept in ``trees`` (its part of that bin) for the
    next call.
    """
    g = points.shape[1]
    X = [[np.ascontiguousarray(nodes[:, a, k]) for k in range(g)] for a in range(nodes.shape[1])]
    axis = np.stack(_centre_normal(X, nodes.shape[1], g), axis=1)
    u = _directions(g)
    facet_bin, facet_spread = _bins(axis, u)
    point_bin, point_spread = _bins(np.asarray(rule.point_normals, dtype=np.float64), u)
    between = np.arccos(np.clip(u @ u.T, -1.0, 1.0))
    for A in np.unique(point_bin):
        p = np.flatnonzero(point_bin == A)
        same_side = between[A] + point_spread[A] + facet_spread <= 0.5 * np.pi - 1e-6
        f = np.flatnonzero(~same_side[facet_bin])
        if f.size == 0:
            continue
        part = Projection(*(getattr(out, k)[p] for k in _FIELDS))
        sub = SelfContact(rule.point_nodes[p], rule.facet_nodes[f], rule.point_normals[p])
        _search(points[p], nodes[f], radius, trees.part(("bin", int(A))), sub, part)
        part.facet[part.facet >= 0] = f[part.facet[part.facet >= 0]]
        for k in _FIELDS:
            getattr(out, k)[p] = getattr(part, k)


@dataclass
class _TreeLevel:
    """The facets of one size class of a master surface and the KD-tree of their centroids.

    Attributes
    ----------
    facets : ndarray of int64 or None
        Indices of the facets of the level (``None``: all the facets, in order).
    n : int
        Number of facets of the level.
    R : float
        Largest facet radius ``R_f`` of the level.
    tree : cKDTree
        KD-tree of the level's centroids (indices local to the level).
    slack : float
        Largest node movement since the tree was built.
    """

    facets: IntArray | None
    n: int
    R: float
    tree: cKDTree
    slack: float

    def facet(self, local: IntArray) -> IntArray:
        """Master facet indices of the level's facets ``local``."""
        return local if self.facets is None else self.facets[local]


def _tree_levels(
    nodes: FloatArray, centroid: FloatArray, size: FloatArray, trees: TreeCache
) -> list[_TreeLevel]:
    """The facets by size class, each with a KD-tree of its centroids: level ``l`` holds the
    facets of radius ``R_f`` in ``(R0 4^(l-1), R0 4^l]`` (level 0: ``R_f <= R0``), ``R0 =
    2 median(R_f)``. The candidates of a point are the centroids within ``r + R`` of it, with
    ``R`` the largest radius *of the level*: a few large facets do not widen the queries among
    the many small ones. A master of even facet size has one level (all its facets)."""
    if len(nodes) == 0:
        return []
    level = np.zeros(len(nodes), dtype=np.int64)
    base = _LEVEL_RADIUS * float(np.median(size))
    large = size > base
    if base > 0.0 and large.any():
        level[large] = np.ceil(np.log(size[large] / base) / np.log(_LEVEL_RATIO))
    kinds = np.unique(level)
    levels = []
    for k in kinds:
        f = None if kinds.size == 1 else np.flatnonzero(level == k)
        sub = (lambda a: a) if f is None else (lambda a, f=f: a[f])
        R = float(sub(size).max())
        tree, slack = trees.tree(sub(nodes), sub(centroid), R, int(k))
        levels.append(_TreeLevel(f, len(sub(size)), R, tree, slack))
    return levels


def _centroid_radius(
    X: list[list[FloatArray]],
) -> tuple[list[FloatArray], list[list[FloatArray]], FloatArray]:
    """Centroid columns (the mean of the points), the offsets of the points from it and the
    radius ``R_f`` (largest offset) of each facet from the coordinate columns ``X[a][k]`` of
    its hull points: every point of a facet is a convex combination of its hull points (also
    for the bilinear quadrilateral), so it lies within ``R_f`` of the centroid."""
    nn, g = len(X), len(X[0])
    c = []
    for k in range(g):
        ck = X[0][k] + X[1][k]
        for a in range(2, nn):
            ck += X[a][k]
        c.append(ck / nn)
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


class _Hierarchy:
    """A bounding-volume hierarchy (axis-aligned boxes) over master facets, in C.

    Built once over the facets' centroids (median splits on the longest axis, two to four
    facets a leaf: ``O(n log n)``), its boxes refitted over the current nodes at every search
    whose nodes differ from the last one's (``O(n)``: a pass over the facets writing each
    one's record in the order of the leaves, its nodes, box and chord deviation, then the
    rows from the leaves' boxes; an unchanged master costs one comparison with the nodes of
    the records, a moved one a facet of it): exact however far the nodes moved since the
    build (only slower once they moved far). The walk reads rows of four children (two
    levels of the binary tree) with their boxes in single precision, rounded outwards, and
    the records of the facets it meets.
    """

    def __init__(self, nodes: FloatArray) -> None:
        self.ffi, self.lib = compiled.kernel()
        nf, self.nn, self.gdim = nodes.shape
        self.kind = _COMPILED_KINDS[facet_kind(self.nn, self.gdim)]
        centroid = np.ascontiguousarray(nodes.mean(axis=1))
        if not np.isfinite(centroid).all():
            raise ValueError(non_finite("the master nodes", nodes))
        self.perm = np.empty(nf, dtype=np.int64)
        self.a = np.empty(nf + 2, dtype=np.int64)  # leaves of 2 to 4 facets: < nf tree nodes
        self.b = np.empty(nf + 2, dtype=np.int64)
        p = self._pointers
        self.m = int(self.lib.bvh_build(self.gdim, nf, *p(centroid, self.perm, self.a, self.b)))
        # the rows of the walk: 128 bytes a tree node at most, one more, 128 to align them
        self.tree = np.empty((self.m + 2) * 128, dtype=np.uint8)
        #: the facets' records in the order of the leaves (nodes, box, chord deviation)
        self.leaves = np.empty((nf, int(self.lib.bvh_record(self.gdim, self.nn))))
        self.leaf_boxes = np.empty((nf, 2 * self.gdim))  # the refit's scratch: <= nf leaves
        self.is_fitted = False
        #: a bound of the largest node movement since the build (the sum of the largest
        #: movements from one refit to the next)
        self.moved = 0.0
        self.R_max = 0.0
        self.projections = 0

    def _pointers(self, *arrays: np.ndarray) -> list:
        return [_ptr(self, a) for a in arrays]

    def fitted(self, nodes: FloatArray) -> bool:
        """Whether the boxes are those of ``nodes`` (C-contiguous): the nodes of the last
        (successful) refit, to the last bit."""
        p = self._pointers
        return self.is_fitted and bool(
            self.lib.same_nodes(self.gdim, self.nn, len(nodes), *p(nodes, self.perm, self.leaves))
        )

    def refit(self, nodes: FloatArray) -> float:
        """The boxes, largest facet radius and leaf-ordered facet records of the current
        ``nodes`` (C-contiguous), with the nodes' largest coordinate change since the last
        refit (against the records' copy), which it returns (meaningless after none); a
        ``ValueError`` if a coordinate is not finite."""
        nf, nn, g = nodes.shape
        p = self._pointers
        change = np.zeros(1)
        self.is_fitted = False
        R_max = float(
            self.lib.bvh_refit(
                g, nn, nf, *p(nodes, self.perm), self.m,
                *p(self.a, self.b, self.tree, self.leaves, self.leaf_boxes, change),
            )
        )  # fmt: skip
        if R_max == -2.0:
            raise ValueError(non_finite("the master nodes", nodes))
        self.R_max = R_max
        self.is_fitted = True
        return float(change[0])

    def order(self, points: FloatArray) -> IntArray:
        """An order of the points along a Z-order (Morton) curve through the cells of a
        ``1024^gdim`` grid over their bounding box, by a radix sort in C: the points of a
        cell, then of its neighbours, come one after the other (they walk the same branches
        of the tree while it is in cache). Stable: equal keys in the given order."""
        order = np.empty(len(points), dtype=np.int64)
        x = np.ascontiguousarray(points)
        if self.lib.morton_order(x.shape[1], len(x), *self._pointers(x, order)) != 0:
            raise MemoryError("the compiled closest-point search ran out of memory")
        return order

    def query(
        self,
        x: FloatArray,
        radius: float,
        out: Projection,
        rule: tuple | None = None,
        index: IntArray | None = None,
    ) -> None:
        """The closest point of each point ``x`` (C-contiguous) written to ``out`` (a
        :class:`Projection` of C-contiguous fields) at its row of ``index`` (its own row
        without): of the facets whose exact distance is within the tie reach of the smallest
        one, the one of the tie-break of :func:`_select` (in C); the placeholders where that
        point is beyond ``radius``, the row left as it is where no facet is within it.
        ``rule``: the arrays of a self-contact search (point nodes, point normals, facet
        nodes, facet centre normals)."""
        p = self._pointers
        null = self.ffi.NULL
        rows = null if index is None else _ptr(self, index)
        fields = p(out.facet, out.xi, out.y, out.normal, out.gap, out.distance, out.sliding)
        contact = [0, null, null, 0, null, null]
        if rule is not None:
            pn, pnormal, fn, axis = rule
            contact = [pn.shape[1], *p(pn, pnormal), fn.shape[1], *p(fn, axis)]
        status = self.lib.bvh_query(
            self.kind, self.gdim, self.nn, *p(self.leaves, self.perm), self.m,
            _ptr(self, self.tree), self.R_max, len(x), _ptr(self, x), radius, rows, *fields,
            *contact,
        )  # fmt: skip
        if status == -1:
            raise MemoryError("the compiled closest-point search ran out of memory")
        if status == -3:
            raise RuntimeError(
                f"the compiled closest-point search's tree walk overflowed its stack (a tree "
                f"of {self.m} rows deeper than a balanced one: please report the master)"
            )
        if status < 0:
            raise ValueError(f"no compiled search for {self.nn}-node facets in {self.gdim}D")
        #: exact projections made by the last query (the work of its pruning)
        self.projections = int(status)


def _ptr(h: _Hierarchy, array: np.ndarray):
    """A cffi pointer to the data of a C-contiguous ``array``."""
    kind = {
        np.dtype(np.float64): "double[]",
        np.dtype(np.int64): "i64[]",
        np.dtype(np.uint8): "unsigned char[]",
    }[array.dtype]
    return h.ffi.from_buffer(kind, array, require_writable=False)


class _Master:
    """Master facets with the per-facet data of the search and the projections.

    The facets are sorted by their radius ``R_f`` into levels (:func:`_tree_levels`), each
    with a KD-tree of its centroids, taken from ``trees`` (a :class:`TreeCache`, if given)
    when a master surface of the same shape was searched before and no node of the level has
    moved more than ``_MOVE R`` (``R`` the largest radius of the level) since that tree was
    built: the level's ``slack`` is then that movement, a bound of how far every centroid is
    from the one the tree holds, and the search widens its bounds by it.
    """

    def __init__(self, nodes: FloatArray, trees: TreeCache | None = None) -> None:
        self.nodes = nodes
        self.nf, self.nn, self.gdim = nodes.shape
        self.fdim = self.gdim - 1
        self.kind = facet_kind(self.nn, self.gdim)
        g = self.gdim
        # the points whose convex hull holds the facet: its nodes, or the Bernstein control
        # points of a quadratic facet (which is not in the convex hull of its nodes)
        hull = bernstein_hull(self.kind, nodes) if self.kind in QUADRATIC else nodes
        # per-facet data from the coordinate columns of the nodes (a loop over the few nodes
        # and coordinates of a facet: reductions over such short axes are slow in NumPy)
        X = [[np.ascontiguousarray(nodes[:, a, k]) for k in range(g)] for a in range(self.nn)]
        if hull is not nodes:
            X_nodes = X
            X = [[np.ascontiguousarray(hull[:, a, k]) for k in range(g)] for a in range(self.nn)]
        c, offsets, self.size = _centroid_radius(X)
        self.centroid = np.stack(c, axis=1)
        self.R_max = float(self.size.max()) if self.nf else 0.0
        trees = trees if trees is not None else TreeCache()
        self.levels = _tree_levels(hull, self.centroid, self.size, trees)
        # slab of the facet: unit normal at the centre, largest hull offset along it
        n = _normalise(_centre_normal(X if hull is nodes else X_nodes, self.nn, g))
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

    def project(self, x: FloatArray, f: IntArray, pid: IntArray, npts: int) -> _Pairs:
        """Project the points ``x`` (P, gdim) on the facets ``f`` (P,).

        ``pid`` (P,) numbers the points of the pairs (``0 <= pid < npts``); the quadrilateral
        projection uses it to skip the facets that cannot hold the closest point.
        """
        # coordinate columns of the pairs' nodes and points (cheaper than rows of 2 or 3)
        if self.kind in QUADRATIC:
            return self._project_quadratic(x, self.nodes[f])
        g = self.gdim
        X = [[self.nodes[:, a, k][f] for k in range(g)] for a in range(self.nn)]
        xs = [x[:, k] for k in range(g)]
        pairs = self._edges(xs, X)
        if self.kind == "segment":
            pairs.edge[:] = -1
        elif self.kind == "triangle":
            self._triangle_interior(xs, X, f, pairs)
        else:
            self._quadrilateral_interior(x, f, pid, npts, pairs)
        return pairs

    def _project_quadratic(self, x: FloatArray, nodes: FloatArray) -> _Pairs:
        """Project the points ``x`` (P, gdim) on the quadratic facets ``nodes`` (P, nn, gdim):
        the closest point on the (curved) edges, replaced by an interior minimum of a
        6-node triangle or 9-node quadrilateral where that is closer (:mod:`.curved`)."""
        if self.kind == "segment3":
            u, dist = curve_closest(x, nodes[:, 0], nodes[:, 1], nodes[:, 2])
            edge = np.full(len(u), -1, dtype=np.int64)
            return _Pairs(xi=u[:, None], dist=dist, edge=edge, vertex=(u == 0.0) | (u == 1.0))
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
        starts = np.array([s for _, _, s, _ in _EDGES[self.kind]])
        ends = np.array([e for _, _, _, e in _EDGES[self.kind]])
        xi = starts[best_k] + best_u[:, None] * (ends[best_k] - starts[best_k])
        pairs = _Pairs(xi=xi, dist=best_d, edge=best_k, vertex=(best_u == 0.0) | (best_u == 1.0))
        interior = triangle_interior if self.kind == "triangle6" else quadrilateral_interior
        xi_in, dist_in, inner = interior(x, nodes)
        take = np.flatnonzero(inner & (dist_in < pairs.dist))
        pairs.xi[take] = xi_in[take]
        pairs.dist[take] = dist_in[take]
        pairs.edge[take] = -1
        pairs.vertex[take] = False
        return pairs

    def _edges(self, xs: list[FloatArray], X: list[list[FloatArray]]) -> _Pairs:
        """Closest point on the straight edges of each facet (a segment is its own edge).

        ``xs``: coordinate columns of the points; ``X[a][k]``: coordinate ``k`` of node ``a``
        of the facet of each pair.
        """
        g = len(xs)
        edges = _EDGES.get(self.kind, ((0, 1, (0.0,), (1.0,)),))
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
        return _Pairs(xi=xi, dist=best_d, edge=best_k, vertex=(best_u == 0.0) | (best_u == 1.0))

    def _triangle_interior(
        self, xs: list[FloatArray], X: list[list[FloatArray]], f: IntArray, pairs: _Pairs
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
        self, x: FloatArray, f: IntArray, pid: IntArray, npts: int, pairs: _Pairs
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


class TreeCache:
    """Search trees of a master surface, reused while it has barely moved: KD-trees of facet
    centroids (the NumPy search, :meth:`tree`) and bounding-volume hierarchies (the compiled
    search, :meth:`hierarchy`).

    Held by whoever searches the same master surface again and again (a
    :class:`~contact_ufl.contact.search.ClosestPointSearch`) and passed to
    :func:`closest_points`.

    One entry per shape ``(nf, nn, gdim)`` of the node array and KD-tree level or hierarchy (the
    ``_TREES`` most recent): the nodes the tree was built from (``None`` for a hierarchy, which
    keeps the nodes of its last refit) and the tree. A search in parts (the normal bins of a
    self-contact search) keeps the trees of each part in a cache of its own (:meth:`part`).
    """

    def __init__(self) -> None:
        self.entries: OrderedDict[tuple, tuple[FloatArray | None, cKDTree | _Hierarchy]] = (
            OrderedDict()
        )
        #: the caches of the parts of a search (a self-contact search's normal bins)
        self.parts: dict[object, TreeCache] = {}

    def part(self, key: object) -> TreeCache:
        """The cache of the part ``key`` of a search (made on first use)."""
        return self.parts.setdefault(key, TreeCache())

    def tree(
        self, nodes: FloatArray, centroid: FloatArray, R_max: float, level: int = 0
    ) -> tuple[cKDTree | None, float]:
        """A KD-tree of centroids within ``slack`` of ``centroid`` and that slack.

        The centroid is the mean of the nodes, so it moves at most as far as the farthest
        node: a tree of earlier centroids serves with ``slack`` the largest node movement.
        """
        if len(nodes) == 0:
            return None, 0.0
        key = (*nodes.shape, level)
        entry = self.entries.get(key)
        if entry is not None:
            built, tree = entry
            # largest node movement (bounded by the largest coordinate change times sqrt(gdim))
            move = float(np.max(np.abs(nodes - built))) * np.sqrt(nodes.shape[2])
            if move <= _MOVE * R_max:
                self.entries.move_to_end(key)
                return tree, move
        tree = cKDTree(centroid)
        self._keep(key, nodes, tree)
        return tree, 0.0

    def hierarchy(self, nodes: FloatArray) -> _Hierarchy:
        """The bounding-volume hierarchy of the facets ``nodes`` (C-contiguous), refitted
        to them: the one of an earlier call on a master of the same shape while no node has
        moved more than ``_MOVE R_max`` since it was built (a tree of the earlier order stays
        exact once refitted, and stays good while the facets barely moved; not refitted if
        no node moved since the last call), else a new one. The movement since the build is
        bounded by the sum of the largest movements from one refit to the next (the hierarchy
        keeps the nodes of its last refit only), each measured by the refit itself: a tree
        found to have moved too far is refitted once more, then replaced."""
        key = (*nodes.shape, "hierarchy")
        entry = self.entries.get(key)
        if entry is not None:
            tree = entry[1]
            if tree.fitted(nodes):  # the master has not moved since the last search
                self.entries.move_to_end(key)
                return tree
            if tree.is_fitted:
                R_max = tree.R_max
                tree.moved += tree.refit(nodes) * np.sqrt(nodes.shape[2])
                if tree.moved <= _MOVE * R_max:
                    self.entries.move_to_end(key)
                    return tree
        tree = _Hierarchy(nodes)
        self._keep(key, None, tree)
        tree.refit(nodes)
        return tree

    def _keep(self, key: tuple, nodes: FloatArray | None, tree: object) -> None:
        """Keep ``tree``, built over ``nodes`` (a copy kept; ``None``: a hierarchy, which
        keeps its own), as the most recent entry."""
        self.entries[key] = (None if nodes is None else nodes.copy(), tree)
        self.entries.move_to_end(key)
        while len(self.entries) > _TREES:
            self.entries.popitem(last=False)


def _candidates(
    level: _TreeLevel, x: FloatArray, bound: FloatArray, active: IntArray
) -> tuple[IntArray, IntArray]:
    """All (point, facet) pairs with a centroid of the ``level`` within ``bound`` of the point.

    One ball query of the KD-tree per point, with the point's own bound (widened by the
    slack of a reused tree): no repeated K-nearest queries.
    """
    if active.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    lists = level.tree.query_ball_point(x[active], bound[active] + level.slack, return_sorted=False)
    count = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
    fid = np.fromiter(itertools.chain.from_iterable(lists), dtype=np.int64, count=count.sum())
    return np.repeat(active, count), level.facet(fid)


def _sliding(
    master: _Master,
    xi: FloatArray,
    a: FloatArray,
    r: FloatArray,
    d2N: FloatArray,
    f: IntArray,
    edge: IntArray,
    vertex: npt.NDArray[np.bool_],
) -> FloatArray:
    """Linearisation matrix ``M`` of the closest points (see the module docstring)."""
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
    M = np.zeros((P, fdim, fdim))
    if fdim == 1:
        A11 = sum(c * c for c in col[0])
        if curvature is not None:
            A11 = A11 - curvature[:, 0, 0]
        ok = ~vertex & (A11 != 0)
        M[:, 0, 0] = np.where(ok, 1.0 / np.where(ok, A11, 1.0), 0.0)
        return M
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
    M[:, 0, 0] = A11 * inv
    M[:, 1, 1] = A00 * inv
    M[:, 0, 1] = M[:, 1, 0] = -A01 * inv
    on_edge = (edge >= 0) & ~vertex
    if on_edge.any():
        tangents = np.array([np.subtract(e, s) for _, _, s, e in _EDGES[master.kind]])
        i = np.flatnonzero(on_edge)
        t0, t1 = tangents[edge[i], 0], tangents[edge[i], 1]
        tAt = t0 * (A00[i] * t0 + A01[i] * t1) + t1 * (A01[i] * t0 + A11[i] * t1)
        tAt = np.where(tAt != 0, tAt, np.inf)
        M[i, 0, 0] = t0 * t0 / tAt
        M[i, 0, 1] = M[i, 1, 0] = t0 * t1 / tAt
        M[i, 1, 1] = t1 * t1 / tAt
    return M


def _concatenate(a: _Pairs, b: _Pairs) -> _Pairs:
    """The pairs of ``a`` followed by those of ``b``."""
    return _Pairs(
        xi=np.concatenate([a.xi, b.xi]),
        dist=np.concatenate([a.dist, b.dist]),
        edge=np.concatenate([a.edge, b.edge]),
        vertex=np.concatenate([a.vertex, b.vertex]),
    )


def _nearest_admissible(
    level: _TreeLevel,
    x: FloatArray,
    active: IntArray,
    d: FloatArray,
    near: IntArray,
    reach0: float,
    admit: Admit,
) -> tuple[IntArray, BoolArray]:
    """The admissible facet of the nearest centroid of the ``level`` of each point
    ``x[active]``, and whether there is one within ``reach0`` (the K nearest ``d, near``
    first, then queries of twice as many neighbours for the points that have none among
    them)."""
    nearest = np.zeros(active.size, dtype=np.int64)
    found = np.zeros(active.size, dtype=bool)
    rows = np.arange(active.size)
    start, k = 0, d.shape[1]
    while True:
        # the neighbours start .. k-1 (the nearer ones were tested by the previous query; a
        # tie reordered between two queries at worst gives a farther admissible facet: the
        # bound stays valid)
        d, near = d[:, start:], near[:, start:].astype(np.int64)
        valid = d <= reach0
        r, c = np.nonzero(valid)
        ok = np.zeros(d.shape, dtype=bool)
        ok[r, c] = admit(active[rows[r]], level.facet(near[r, c]))
        has = ok.any(axis=1)
        nearest[rows[has]] = level.facet(near[has, ok[has].argmax(axis=1)])
        found[rows[has]] = True
        # the points with no admissible facet among k neighbours all within reach0
        more = ~has & valid[:, -1]
        if k >= level.n or not more.any():
            return nearest, found
        rows, start, k = rows[more], k, min(2 * k, level.n)
        d, near = level.tree.query(x[active[rows]], k=k, distance_upper_bound=reach0)
        d, near = d.reshape(rows.size, k), near.reshape(rows.size, k)


def _nearest(
    master: _Master,
    x: FloatArray,
    queries: list[tuple[FloatArray, IntArray, float]],
    admit: Admit | None,
) -> tuple[IntArray, IntArray]:
    """The points with a (admissible) centroid within the first bound of some level, and
    the facet of the nearest such centroid (over the levels) of each.

    ``queries``: per level of ``master.levels``, the distances and indices of the K nearest
    centroids of each point and the bound of that query."""
    npts = x.shape[0]
    best = np.full(npts, np.inf)
    nearest = np.full(npts, -1, dtype=np.int64)
    for level, (d, near, reach0) in zip(master.levels, queries, strict=True):
        rows = np.flatnonzero(d[:, 0] <= reach0)
        if rows.size == 0:
            continue
        if admit is None:
            facet = level.facet(near[rows, 0].astype(np.int64))
            dist = d[rows, 0]
        else:
            # the bound d1 must come from an admissible facet (a point's own facet is at 0)
            facet, found = _nearest_admissible(level, x, rows, d[rows], near[rows], reach0, admit)
            rows, facet = rows[found], facet[found]
            dist = np.linalg.norm(x[rows] - master.centroid[facet], axis=1)
        closer = dist < best[rows]
        best[rows[closer]] = dist[closer]
        nearest[rows[closer]] = facet[closer]
    active = np.flatnonzero(nearest >= 0)
    return active, nearest[active]


def _closest_block(
    master: _Master, x: FloatArray, radius: float, out: Projection, admit: Admit | None = None
) -> None:
    """Fill ``out`` (arrays of this block of points) with the closest points of ``x``, over
    the pairs that ``admit`` (block point indices, facets) accepts if it is given."""
    npts = x.shape[0]
    # per level, the K nearest centroids, where they can hold a facet point within the radius
    queries = []
    for level in master.levels:
        reach0 = (radius + level.R + 2.0 * level.slack) * (1 + 1e-12)
        K = min(_K[master.gdim], level.n)
        d, near = level.tree.query(x, k=K, distance_upper_bound=reach0)
        queries.append((d.reshape(npts, K), near.reshape(npts, K), reach0))
    active, nearest = _nearest(master, x, queries, admit)
    if active.size == 0:
        return
    # an upper bound of the distance: the exact distance to the facet of the nearest centroid
    first = master.project(x[active], nearest, np.arange(active.size), active.size)
    d1 = np.full(npts, np.inf)
    d1[active] = first.dist
    reach = np.minimum(d1, radius)
    # candidates: per level, the centroids within reach + R, from the K found (a ball query
    # for the points whose K-th neighbour is within it: they may have more)
    pid, fid = [], []
    for level, (d, near, _) in zip(master.levels, queries, strict=True):
        bound = (reach + level.R) * (1 + 1e-12)
        within = d[active] <= (bound[active] + level.slack)[:, None]
        cut = within[:, -1] if d.shape[1] < level.n else np.zeros(active.size, dtype=bool)
        rows, cols = np.nonzero(within & ~cut[:, None])
        pid_ball, fid_ball = _candidates(level, x, bound, active[cut])
        pid += [active[rows], pid_ball]
        fid += [level.facet(near[active[rows], cols].astype(np.int64)), fid_ball]
    pid, fid = np.concatenate(pid), np.concatenate(fid)
    lower = master.lower_bound(x, fid, pid)
    keep = lower - 1e-9 * master.size[fid] <= reach[pid] * (1 + 1e-9)
    if admit is not None:
        keep[keep] = admit(pid[keep], fid[keep])
    # the pair of the nearest centroid is projected already
    done = np.full(npts, -1, dtype=np.int64)
    done[active] = nearest
    keep &= fid != done[pid]
    pid, fid = pid[keep], fid[keep]
    pairs = _concatenate(master.project(x[pid], fid, pid, npts), first)
    pid, fid = np.concatenate([pid, active]), np.concatenate([fid, nearest])
    _select(master, x, radius, out, pid, fid, pairs)


def _select(
    master: _Master,
    x: FloatArray,
    radius: float,
    out: Projection,
    pid: IntArray,
    fid: IntArray,
    pairs: _Pairs,
) -> None:
    """Fill ``out`` with the closest point of each point ``x[pid]`` among its projected pairs
    ``(pid, fid)`` (their projections ``pairs``), with the tie-break of :func:`closest_points`;
    the points farther than ``radius`` from all their pairs are left unpaired."""
    npts = x.shape[0]
    # minimum per point; ties (shared edges and vertices) go to the best-aligned normal
    dmin = np.full(npts, np.inf)
    np.minimum.at(dmin, pid, pairs.dist)
    tie = pairs.dist <= dmin[pid] + _TIE * (dmin[pid] + 2.0 * master.size[fid])
    e = np.flatnonzero(tie)
    pe = pid[e]
    # a point with one pair within the tie tolerance takes it; the others break the tie
    several = np.bincount(pe, minlength=npts)[pe] > 1
    k = np.flatnonzero(~several)
    if several.any():
        tied = np.flatnonzero(several)
        k = np.concatenate([k, tied[_tie_break(master, x, e[tied], pe[tied], fid, pairs)]])
    e, pe = e[k], pe[k]
    fe, xi = fid[e], pairs.xi[e]
    N, dN, d2N = shape_functions(master.nn, master.gdim, xi)
    X = master.nodes[fe]
    y = np.einsum("pn,png->pg", N, X)
    r = x[pe] - y
    a = _tangents(dN, X)
    nu = _unit_normal(a)
    dist = np.linalg.norm(r, axis=1)
    k = np.flatnonzero(dist <= radius)
    p, f = pe[k], fe[k]
    out.facet[p] = f
    out.xi[p] = xi[k]
    out.y[p] = y[k]
    out.normal[p] = nu[k]
    out.gap[p] = -_dot(nu[k], r[k])
    out.distance[p] = dist[k]
    best = e[k]
    out.sliding[p] = _sliding(
        master, xi[k], a[k], r[k], d2N[k], f, pairs.edge[best], pairs.vertex[best]
    )


def _tie_break(
    master: _Master,
    x: FloatArray,
    e: IntArray,
    pe: IntArray,
    fid: IntArray,
    pairs: _Pairs,
) -> IntArray:
    """Positions in ``e`` of the winners among the tied pairs ``e`` (of the points ``pe``,
    several per point): the normal most aligned with ``x - y``, then the nearer centroid,
    then the lower facet index, alignments within ``_ALIGN`` and squared centroid distances
    within ``_ALIGN`` of each other counting as equal (a tie of the geometry is broken by the
    geometry, not by the round-off of two implementations)."""
    fe, xi = fid[e], pairs.xi[e]
    N, dN, _ = shape_functions(master.nn, master.gdim, xi)
    X = master.nodes[fe]
    r = x[pe] - np.einsum("pn,png->pg", N, X)
    nu = _unit_normal(_tangents(dN, X))
    dist = np.linalg.norm(r, axis=1)
    align = np.divide(np.abs(_dot(nu, r)), dist, out=np.zeros_like(dist), where=dist > 0)
    c = x[pe] - master.centroid[fe]
    c2 = _dot(c, c)
    npts = x.shape[0]  # per point, as _select: the largest alignment, the nearest centroid
    best = np.full(npts, -np.inf)
    np.maximum.at(best, pe, align)
    keep = align >= best[pe] - _ALIGN
    nearest = np.full(npts, np.inf)
    np.minimum.at(nearest, pe[keep], c2[keep])
    keep &= c2 <= nearest[pe] * (1.0 + _ALIGN)
    lowest = np.full(npts, np.iinfo(np.int64).max)
    np.minimum.at(lowest, pe[keep], fe[keep])
    return np.flatnonzero(keep & (fe == lowest[pe]))


def _check_self_contact(self_contact: SelfContact, npts: int, nf: int, gdim: int) -> None:
    """Raise if the arrays of ``self_contact`` do not match the points and facets."""
    shapes = (
        np.shape(self_contact.point_nodes)[:1],
        np.shape(self_contact.facet_nodes)[:1],
        np.shape(self_contact.point_normals),
    )
    if shapes != ((npts,), (nf,), (npts, gdim)):
        raise ValueError(
            f"self_contact must hold the nodes of {npts} points' facets, of {nf} facets and "
            f"{npts} normals in {gdim}D, got shapes {shapes}"
        )


def _admission(self_contact: SelfContact, master: _Master, index: IntArray) -> Admit:
    """The admissibility test of a block of points (``index``: their indices in the call)."""

    def admit(pid: IntArray, fid: IntArray) -> npt.NDArray[np.bool_]:
        return self_contact.admissible(index[pid], fid, master.axis[fid])

    return admit


def _spatial_order(points: FloatArray) -> IntArray:
    """An order of the points by the cells of a ``_CELLS^gdim`` grid over their bounding
    box (lexicographic in the cell coordinates)."""
    lo = points.min(axis=0)
    span = float((points.max(axis=0) - lo).max())
    if not (np.isfinite(span) and span > 0.0):
        return np.arange(points.shape[0])
    cell = np.minimum((points - lo) * (_CELLS / span), _CELLS - 1).astype(np.int64)
    key = cell[:, 0]
    for k in range(1, points.shape[1]):
        key = key * _CELLS + cell[:, k]
    return np.argsort(key, kind="stable")


def closest_points(
    points: npt.ArrayLike,
    nodes: npt.ArrayLike,
    radius: float = np.inf,
    trees: TreeCache | None = None,
    self_contact: SelfContact | None = None,
) -> Projection:
    """Closest points of slave points on a master surface, in the current configuration.

    Parameters
    ----------
    points : array_like, shape (np, gdim)
        Current positions of the slave points.
    nodes : array_like, shape (nf, nn, gdim)
        Current node positions of the master facets, oriented (see the module docstring for
        the facet kinds and their normals).
    radius : float, optional
        Search radius: a point with no facet point within ``radius`` gets ``facet = -1``.
    trees : TreeCache, optional
        KD-trees of earlier calls on the same master surface, reused while it has barely
        moved (and updated); without it the tree is built anew.
    self_contact : SelfContact, optional
        For a surface searched against itself: only the admissible (point, facet) pairs of
        :class:`SelfContact` are considered (the facet holding the point, its neighbours and
        the facets that do not face the point are skipped).

    Returns
    -------
    Projection
        Closest facet, reference coordinates, closest point, normal, proximity, distance and
        linearisation matrix of every point; placeholders where ``facet == -1`` (see
        :class:`Projection`).

    Notes
    -----
    Every facet kind (unless ``CONTACT_UFL_SEARCH=numpy``): a bounding-volume hierarchy of
    axis-aligned boxes over the facets' nodes (of a quadratic facet, its Bernstein control
    points; median splits, 2 to 4 facets a leaf; built once per master shape and
    kept in ``trees`` while no node has moved more than ``0.25 R_max``, its boxes refitted
    to the current nodes at every call where they changed; walked four children a step,
    their boxes in single precision rounded outwards) is walked per point in C, nearest
    child first, skipping every box (and facet box; of a quadrilateral, also the slab
    between its corners' heights along its centre normal) farther than ``r = min(d,
    radius)`` with ``d`` the smallest exact distance met so far (widened by ``1e-9 (r + 2
    R_max)``, beyond the tie tolerance): the work follows the point's distance to the
    surface, not the radius. On a surface four points are walked by turns, a step of each
    (the memory loads of one under way while the others work; each walk, so its result, as
    alone).
    The exact projections are those of the NumPy kernels, in the same operations (of the
    quadratic kinds, those of :mod:`.curved` to round-off). A quadratic facet is projected
    when the walk is done, and only if the bounds of its distance from its chord facet (the
    straight facet of its vertices, within a distance fixed by its midpoint nodes of it)
    do not rule it out: by increasing lower bound, the bound tightened by the distances
    found; its walk's bound starts from the upper bound of the facet of the point before (a
    neighbour in the points' order; not in a self-contact search). Of the facets within
    that reach the tie-break below picks one (in C, in the operations of the NumPy search),
    and its closest point, normal, proximity and ``M`` come from C too. Self-contact: the
    inadmissible facets are skipped in the walk (the same rule).

    Candidate search with ``CONTACT_UFL_SEARCH=numpy``:
    KD-trees of the facet centroids (the mean of the nodes; of a quadratic facet, of its
    Bernstein control points, whose convex hull holds it). Every facet point is
    within ``R_f`` (the largest node, or control point, distance from the centroid) of it.
    The facets are sorted by ``R_f`` into levels (radius ratio 4 between levels, the first up
    to twice the median ``R_f``; an even mesh has one level), each with its KD-tree and its
    largest radius ``R``. With ``d1 <= d0`` the exact distance of ``x`` to the facet of its
    nearest centroid (``d0`` away over the levels, queries bounded by ``radius + R``), the
    closest point is within ``r = min(d1, radius)`` of ``x``, so its facet has its centroid
    within ``r + R`` of it in its level (one ball query per point and level, with the point's
    own ``r``: the work follows ``r``, not the search radius, and a few large facets do not
    widen the queries among the small ones). The facets whose distance lower bound (node
    sphere and slab along the normal at the centre) exceeds ``r`` are dropped, the others
    projected exactly. Points with ``d0 > radius + R`` in every level get ``facet = -1`` at
    once. The KD-trees are reused from one call to the next while the master nodes (same
    array shape) have moved less than ``0.25 R``, the bounds being widened by that movement.
    On a master of over ``2^14`` facets the points are searched in the order of the cells of
    a ``64^gdim`` grid over them (the results are returned in the order given): neighbouring
    points query the same branches of the tree and gather the same facets' data while they
    are in cache.

    Self-contact on a surface of over 1024 facets: the points are searched by bins of their
    normal, each against the facets of the bins that may face it only (see
    :func:`_by_direction`); the admissible pairs, so the results, are those of one search.

    The work of a point grows with its distance ``D`` from the master surface, not with the
    search radius: its candidates are the facets with a centroid within ``min(D, radius) +
    R`` (about ``D R / h^2`` of them on a surface of facet size ``h``).

    When several facets are at the same distance up to ``1e-10 (distance + facet size)``
    (the point projects onto a shared edge or vertex), the facet whose normal is the most
    aligned with ``x - y`` wins; at equal alignment (to ``1e-12``) the one with the nearer
    centroid (its squared distance to ``1e-12`` relative), then the lower index (so that the
    order the caller gives the facets in decides exact ties, whatever the round-off of the
    closest points).

    Self-contact (``self_contact`` given): the inadmissible pairs are dropped before any
    distance bounds the search, so the bound ``d1`` is the distance of the facet of the
    nearest centroid *among the admissible ones* (found by K-nearest queries of doubling K);
    a point with no admissible facet within ``radius + R_max`` is unpaired. Without it the
    search is unchanged.

    Quadrilaterals: clamped Newton from the centre (restarted from four other points where it
    does not converge or stops at a saddle), compared with the projections on the four
    straight edges. A strongly warped quadrilateral seen from beyond its radius of curvature
    can have several interior local minima; the one found is then not guaranteed global.
    """
    nodes = np.asarray(nodes, dtype=np.float64)
    if nodes.ndim != 3:
        raise ValueError(f"nodes must have shape (nf, nn, gdim), got {nodes.shape}")
    nf, nn, gdim = nodes.shape
    facet_kind(nn, gdim)
    points = np.asarray(points, dtype=np.float64)
    if points.size == 0:
        points = points.reshape(0, gdim)
    if points.ndim != 2 or points.shape[1] != gdim:
        raise ValueError(f"points must have shape (np, {gdim}), got {points.shape}")
    radius = float(radius)
    if not radius >= 0.0:
        raise ValueError(f"radius must be non-negative, got {radius}")
    if not np.isfinite(points).all():
        raise ValueError(non_finite("the slave points", points))
    npts, fdim = points.shape[0], gdim - 1
    out = Projection(
        facet=np.full(npts, -1, dtype=np.int64),
        xi=np.zeros((npts, fdim)),
        y=points.copy(),
        normal=np.zeros((npts, gdim)),
        gap=np.full(npts, -np.inf),
        distance=np.full(npts, np.inf),
        sliding=np.zeros((npts, fdim, fdim)),
    )
    if npts == 0 or nf == 0:
        return out
    trees = trees if trees is not None else TreeCache()
    if self_contact is not None:
        _check_self_contact(self_contact, npts, nf, gdim)
        if nf > _DIRECTIONS_MIN:
            _by_direction(points, nodes, radius, self_contact, out, trees)
            return out
    _search(points, nodes, radius, trees, self_contact, out)
    return out


def _compiled(nn: int, gdim: int) -> bool:
    """Whether the facets of ``nn`` nodes in ``gdim`` go by the compiled search: the flat
    kinds, unless ``CONTACT_UFL_SEARCH=numpy`` asks for the NumPy search."""
    if os.environ.get("CONTACT_UFL_SEARCH", "compiled").lower() == "numpy":
        return False
    return facet_kind(nn, gdim) in _COMPILED_KINDS


def _search_compiled(
    points: FloatArray,
    nodes: FloatArray,
    radius: float,
    trees: TreeCache,
    self_contact: SelfContact | None,
    out: Projection,
) -> None:
    """Fill ``out`` with the closest points of :func:`closest_points` (checked input) by
    the compiled search: a branch-and-bound walk of a bounding-volume hierarchy per point
    (``search_kernel.c``) finds its closest facet and those within the tie reach of it (the
    exact projections of the NumPy kernels, in C), breaks the ties as :func:`_select` does
    and writes the closest point. On a master of over ``_SORT`` facets the points are walked
    in a Z-order of cells (:meth:`_Hierarchy.order`)."""
    nodes = np.ascontiguousarray(nodes)
    tree = trees.hierarchy(nodes)
    rule = None if self_contact is None else _self_contact_arrays(self_contact, nodes)
    order = tree.order(points) if nodes.shape[0] > _SORT else None
    x = np.ascontiguousarray(points if order is None else points[order])
    if rule is not None and order is not None:
        rule = (rule[0][order], rule[1][order], rule[2], rule[3])
    tree.query(x, radius, out, rule, order)


def _search(
    points: FloatArray,
    nodes: FloatArray,
    radius: float,
    trees: TreeCache,
    self_contact: SelfContact | None,
    out: Projection,
) -> None:
    """Fill ``out`` with the closest points of :func:`closest_points` (checked input): by
    the compiled search for the flat facet kinds (:func:`_compiled`), else in NumPy."""
    search = _search_compiled if _compiled(*nodes.shape[1:]) else _search_numpy
    search(points, nodes, radius, trees, self_contact, out)


def _search_numpy(
    points: FloatArray,
    nodes: FloatArray,
    radius: float,
    trees: TreeCache,
    self_contact: SelfContact | None,
    out: Projection,
) -> None:
    """Fill ``out`` with the closest points of :func:`closest_points` (checked input) by
    KD-trees of the facet centroids and the NumPy kernels."""
    npts, nf = points.shape[0], nodes.shape[0]
    if not np.isfinite(nodes).all():
        raise ValueError(non_finite("the master nodes", nodes))
    master = _Master(nodes, trees)
    # on a large master the points in the order of a grid of cells (neighbours searched
    # together: the KD-tree and the gathers of facet data stay in cache), results scattered
    order = _spatial_order(points) if nf > _SORT else None
    x = points if order is None else points[order]
    work = out if order is None else Projection(*(getattr(out, k)[order] for k in _FIELDS))
    for start in range(0, npts, _BLOCK):
        block = slice(start, min(start + _BLOCK, npts))
        view = Projection(*(getattr(work, k)[block] for k in _FIELDS))
        admit = None
        if self_contact is not None:
            index = (np.arange(npts) if order is None else order)[block]
            admit = _admission(self_contact, master, index)
        _closest_block(master, x[block], radius, view, admit)
    if order is not None:
        for k in _FIELDS:
            getattr(out, k)[order] = getattr(work, k)


def _self_contact_arrays(rule: SelfContact, nodes: FloatArray) -> tuple[np.ndarray, ...]:
    """The arrays of a compiled self-contact search: point nodes, point normals, facet nodes
    and the facets' unit normals at their centres (as :class:`_Master` ``.axis``)."""
    g, nn = nodes.shape[2], nodes.shape[1]
    X = [[np.ascontiguousarray(nodes[:, a, k]) for k in range(g)] for a in range(nn)]
    axis = np.stack(_normalise(_centre_normal(X, nn, g)), axis=1)
    return tuple(
        np.ascontiguousarray(a, dtype=dtype)
        for a, dtype in (
            (rule.point_nodes, np.int64),
            (rule.point_normals, np.float64),
            (rule.facet_nodes, np.int64),
            (axis, np.float64),
        )
    )
