"""Closest points of many slave points on a master surface made of facets: the search's
entry, :func:`closest_points`, and its choice of back end.

Every facet kind (:mod:`.kinds`) is searched by either back end:

* ``"compiled"`` (the default): a bounding-volume hierarchy over the facets walked by branch
  and bound per point in C (``search_kernel.c``, built on first use by :mod:`.compiled`;
  :mod:`.hierarchy`), with the exact projections and the tie-break of the NumPy back end in
  the same operations;
* ``"numpy"``: KD-trees of the facet centroids (:class:`scipy.spatial.cKDTree`) and
  vectorised NumPy kernels (:mod:`.numpy_search`, :mod:`.numpy_facets`, :mod:`.curved`): the
  only Python loops run over a fixed small number of items (nodes, edges and coordinates of
  a facet, Newton iterations, blocks of points, levels). It is the test oracle of the
  compiled one.

The back end is the ``backend`` argument of :func:`closest_points` (and of
:class:`~contact_ufl.contact.search.ClosestPointSearch`); without it, the environment
variable ``CONTACT_UFL_SEARCH`` (``compiled`` or ``numpy``), else ``"compiled"``.
Throughput: ``benchmarks/search.py``.
"""

from __future__ import annotations

import os

import numpy as np
import numpy.typing as npt

from contact_ufl.contact.search.hierarchy import search_compiled
from contact_ufl.contact.search.kinds import COMPILED_KINDS, FloatArray, IntArray, facet_kind
from contact_ufl.contact.search.numpy_search import search_numpy
from contact_ufl.contact.search.projection import FIELDS, Projection, SelfContact, non_finite
from contact_ufl.contact.search.shapes import centre_normal
from contact_ufl.contact.search.trees import TreeCache
from contact_ufl.errors import ContactInputError

#: The back ends of the search, by the name ``backend`` and ``CONTACT_UFL_SEARCH`` give.
BACKENDS = ("compiled", "numpy")
#: The environment variable that chooses the back end where the caller does not.
BACKEND_VARIABLE = "CONTACT_UFL_SEARCH"
_SORT = 1 << 14  # facets above which the points are ordered by cells


_DIRECTIONS = {2: 8, 3: 32}  # normal bins of a self-contact search, by dimension


_DIRECTIONS_MIN = 1 << 10  # facets above which a self-contact search goes by normal bins


def closest_points(
    points: npt.ArrayLike,
    nodes: npt.ArrayLike,
    radius: float = np.inf,
    trees: TreeCache | None = None,
    self_contact: SelfContact | None = None,
    backend: str | None = None,
) -> Projection:
    """Closest points of slave points on a master surface, in the current configuration.

    Parameters
    ----------
    points : array_like, shape (np, gdim)
        Current positions of the slave points.
    nodes : array_like, shape (nf, nodes_per_facet, gdim)
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
    backend : {"compiled", "numpy"}, optional
        The back end (:data:`BACKENDS`): the compiled search, or the NumPy one (its test
        oracle; the same closest points to round-off). Default: the environment variable
        ``CONTACT_UFL_SEARCH`` if set, else ``"compiled"``.

    Returns
    -------
    Projection
        Closest facet, reference coordinates, closest point, normal, proximity, distance and
        linearisation matrix of every point; placeholders where ``facet == -1`` (see
        :class:`Projection`).

    Notes
    -----
    The compiled back end, every facet kind: a bounding-volume hierarchy of
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

    The candidate search of the NumPy back end (``backend="numpy"``):
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
    nodes = _array("nodes", nodes)
    if nodes.ndim != 3:
        raise ContactInputError(
            f"nodes must have shape (nf, nodes_per_facet, gdim), got {nodes.shape}"
        )
    nf, nodes_per_facet, gdim = nodes.shape
    try:
        facet_kind(nodes_per_facet, gdim)
        resolve_backend(backend)
    except ValueError as error:
        raise ContactInputError(str(error)) from None
    points = _array("points", points)
    if points.size == 0:
        points = points.reshape(0, gdim)
    if points.ndim != 2 or points.shape[1] != gdim:
        raise ContactInputError(f"points must have shape (np, {gdim}), got {points.shape}")
    radius = float(radius)
    if not radius >= 0.0:
        raise ContactInputError(f"radius must be non-negative, got {radius}")
    for what, values in (("the slave points", points), ("the master nodes", nodes)):
        if not np.isfinite(values).all():
            raise ContactInputError(non_finite(what, values))
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
            _by_direction(points, nodes, radius, self_contact, out, trees, backend)
            return out
    _search(points, nodes, radius, trees, self_contact, out, backend)
    return out


def _array(name: str, values: npt.ArrayLike) -> FloatArray:
    """``values`` as an array of floats; a :class:`ContactInputError` naming ``name`` for
    what is not one (ragged rows, no numbers)."""
    try:
        return np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ContactInputError(f"{name} must be an array of numbers: {error}") from None


def resolve_backend(backend: str | None = None) -> str:
    """The back end of a search: ``backend`` if given, else the environment variable
    ``CONTACT_UFL_SEARCH`` if set, else ``"compiled"``; a ``ValueError`` for a name not in
    :data:`BACKENDS`."""
    if backend is None:
        backend = os.environ.get(BACKEND_VARIABLE, "compiled").lower()
    if backend not in BACKENDS:
        raise ValueError(
            f"unknown closest-point search back end {backend!r} (the backend argument or "
            f"{BACKEND_VARIABLE}): one of {', '.join(BACKENDS)}"
        )
    return backend


def compiled_backend(backend: str | None, nodes_per_facet: int, gdim: int) -> bool:
    """Whether facets of ``nodes_per_facet`` nodes in ``gdim`` go by the compiled search
    with the choice ``backend`` (:func:`resolve_backend`)."""
    if resolve_backend(backend) == "numpy":
        return False
    return facet_kind(nodes_per_facet, gdim) in COMPILED_KINDS


def _search(
    points: FloatArray,
    nodes: FloatArray,
    radius: float,
    trees: TreeCache,
    self_contact: SelfContact | None,
    out: Projection,
    backend: str | None = None,
) -> None:
    """Fill ``out`` with the closest points of :func:`closest_points` (checked input) by
    the back end of ``backend`` (:func:`compiled_backend`). On a master of over ``_SORT``
    facets the points are searched in an order of cells (neighbours one after the other)."""
    ordered = nodes.shape[0] > _SORT
    if compiled_backend(backend, *nodes.shape[1:]):
        nodes = np.ascontiguousarray(nodes)
        tree = trees.hierarchy(nodes)
        search_compiled(points, nodes, radius, tree, ordered, self_contact, out)
    else:
        search_numpy(points, nodes, radius, trees, ordered, self_contact, out)


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
    backend: str | None = None,
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
    axis = np.stack(centre_normal(X, nodes.shape[1], g), axis=1)
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
        part = Projection(*(getattr(out, k)[p] for k in FIELDS))
        sub = SelfContact(rule.point_nodes[p], rule.facet_nodes[f], rule.point_normals[p])
        _search(points[p], nodes[f], radius, trees.part(("bin", int(A))), sub, part, backend)
        part.facet[part.facet >= 0] = f[part.facet[part.facet >= 0]]
        for k in FIELDS:
            getattr(out, k)[p] = getattr(part, k)
