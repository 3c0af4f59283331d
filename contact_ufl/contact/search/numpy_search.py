"""The NumPy back end of the closest-point search: KD-trees of the facet centroids by size
class (:mod:`.trees`) give each point its candidate facets, bounded by the exact distance to
the facet of its nearest centroid; the exact projections of :mod:`.numpy_facets` and the
tie-break between equidistant facets pick its closest point. The test oracle of the compiled
back end (:mod:`.hierarchy`), which repeats its operations.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from contact_ufl.contact.search.kinds import BoolArray, FloatArray, IntArray
from contact_ufl.contact.search.numpy_facets import MasterFacets, Pairs, concatenate, sliding_matrix
from contact_ufl.contact.search.projection import FIELDS, Projection, SelfContact, non_finite
from contact_ufl.contact.search.shapes import dot, shape_functions, tangent_vectors, unit_normal
from contact_ufl.contact.search.trees import TreeCache, TreeLevel, ball_candidates

_K = {2: 8, 3: 16}  # neighbours of the first KD-tree query, by dimension


_BLOCK = 1 << 12  # points processed at once (keeps the arrays of the candidate pairs in cache)


_TIE = 1e-10  # relative distance tolerance of the tie-break


_ALIGN = 1e-12  # alignments (and relative squared centroid distances) equal in the tie-break


_CELLS = 64  # cells per dimension of the grid that orders the points

#: An admissibility test of (point, facet) pairs: point and facet indices in, mask out.
Admit = Callable[[IntArray, IntArray], npt.NDArray[np.bool_]]


def search_numpy(
    points: FloatArray,
    nodes: FloatArray,
    radius: float,
    trees: TreeCache,
    ordered: bool,
    self_contact: SelfContact | None,
    out: Projection,
) -> None:
    """Fill ``out`` with the closest points of :func:`.closest.closest_points` (checked
    input) by KD-trees of the facet centroids and the NumPy kernels; ``ordered`` (a large
    master): the points searched in the order of a grid of cells (:func:`spatial_order`)."""
    npts = points.shape[0]
    if not np.isfinite(nodes).all():
        raise ValueError(non_finite("the master nodes", nodes))
    master = MasterFacets(nodes, trees)
    # on a large master the points in the order of a grid of cells (neighbours searched
    # together: the KD-tree and the gathers of facet data stay in cache), results scattered
    order = spatial_order(points) if ordered else None
    x = points if order is None else points[order]
    work = out if order is None else Projection(*(getattr(out, k)[order] for k in FIELDS))
    for start in range(0, npts, _BLOCK):
        block = slice(start, min(start + _BLOCK, npts))
        view = Projection(*(getattr(work, k)[block] for k in FIELDS))
        admit = None
        if self_contact is not None:
            index = (np.arange(npts) if order is None else order)[block]
            admit = _admission(self_contact, master, index)
        _closest_block(master, x[block], radius, view, admit)
    if order is not None:
        for k in FIELDS:
            getattr(out, k)[order] = getattr(work, k)


def _admission(self_contact: SelfContact, master: MasterFacets, index: IntArray) -> Admit:
    """The admissibility test of a block of points (``index``: their indices in the call)."""

    def admit(pid: IntArray, fid: IntArray) -> npt.NDArray[np.bool_]:
        return self_contact.admissible(index[pid], fid, master.axis[fid])

    return admit


def spatial_order(points: FloatArray) -> IntArray:
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


def _nearest_admissible(
    level: TreeLevel,
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
    master: MasterFacets,
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
    master: MasterFacets, x: FloatArray, radius: float, out: Projection, admit: Admit | None = None
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
        pid_ball, fid_ball = ball_candidates(level, x, bound, active[cut])
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
    pairs = concatenate(master.project(x[pid], fid, pid, npts), first)
    pid, fid = np.concatenate([pid, active]), np.concatenate([fid, nearest])
    select(master, x, radius, out, pid, fid, pairs)


def select(
    master: MasterFacets,
    x: FloatArray,
    radius: float,
    out: Projection,
    pid: IntArray,
    fid: IntArray,
    pairs: Pairs,
) -> None:
    """Fill ``out`` with the closest point of each point ``x[pid]`` among its projected pairs
    ``(pid, fid)`` (their projections ``pairs``), with the tie-break of
    :func:`.closest.closest_points`; the points farther than ``radius`` from all their pairs
    are left unpaired."""
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
    N, dN, d2N = shape_functions(master.nodes_per_facet, master.gdim, xi)
    X = master.nodes[fe]
    y = np.einsum("pn,png->pg", N, X)
    r = x[pe] - y
    a = tangent_vectors(dN, X)
    nu = unit_normal(a)
    dist = np.linalg.norm(r, axis=1)
    k = np.flatnonzero(dist <= radius)
    p, f = pe[k], fe[k]
    out.facet[p] = f
    out.xi[p] = xi[k]
    out.y[p] = y[k]
    out.normal[p] = nu[k]
    out.gap[p] = -dot(nu[k], r[k])
    out.distance[p] = dist[k]
    best = e[k]
    out.sliding[p] = sliding_matrix(
        master, xi[k], a[k], r[k], d2N[k], f, pairs.edge[best], pairs.vertex[best]
    )


def _tie_break(
    master: MasterFacets,
    x: FloatArray,
    e: IntArray,
    pe: IntArray,
    fid: IntArray,
    pairs: Pairs,
) -> IntArray:
    """Positions in ``e`` of the winners among the tied pairs ``e`` (of the points ``pe``,
    several per point): the normal most aligned with ``x - y``, then the nearer centroid,
    then the lower facet index, alignments within ``_ALIGN`` and squared centroid distances
    within ``_ALIGN`` of each other counting as equal (a tie of the geometry is broken by the
    geometry, not by the round-off of two implementations)."""
    fe, xi = fid[e], pairs.xi[e]
    N, dN, _ = shape_functions(master.nodes_per_facet, master.gdim, xi)
    X = master.nodes[fe]
    r = x[pe] - np.einsum("pn,png->pg", N, X)
    nu = unit_normal(tangent_vectors(dN, X))
    dist = np.linalg.norm(r, axis=1)
    align = np.divide(np.abs(dot(nu, r)), dist, out=np.zeros_like(dist), where=dist > 0)
    c = x[pe] - master.centroid[fe]
    c2 = dot(c, c)
    npts = x.shape[0]  # per point, as select: the largest alignment, the nearest centroid
    best = np.full(npts, -np.inf)
    np.maximum.at(best, pe, align)
    keep = align >= best[pe] - _ALIGN
    nearest = np.full(npts, np.inf)
    np.minimum.at(nearest, pe[keep], c2[keep])
    keep &= c2 <= nearest[pe] * (1.0 + _ALIGN)
    lowest = np.full(npts, np.iinfo(np.int64).max)
    np.minimum.at(lowest, pe[keep], fe[keep])
    return np.flatnonzero(keep & (fe == lowest[pe]))
