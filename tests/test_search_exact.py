"""The pruned closest-point search against a projection onto every facet.

The reference projects each point onto each facet alone (one facet per call, so no candidate
search is involved) and picks the closest with the documented tie-break: among the facets
within ``1e-10 (distance + facet size)`` of the smallest distance, the normal most aligned
with ``x - y``, then the nearer centroid, then the lower facet index. The search must return
the same facet and, to round-off, the same closest point, reference coordinates, normal, gap
and linearisation. The reference uses the package's own projection of a point onto a facet:
these are consistency checks of the search (its pruning, ordering and tie-break), not of the
projection (``test_projection.py`` compares that with a brute force of its own).
"""

from __future__ import annotations

import numpy as np
import pytest
from test_projection import segment_polyline, triangle_soup, warped_quads, wavy_quads

from contact_ufl.contact.search import TreeCache, closest_points, fan_columns, shape_functions
from contact_ufl.contact.search import closest as closest_module
from contact_ufl.contact.search.numpy_facets import MasterFacets
from contact_ufl.contact.search.numpy_search import spatial_order

#: rank-local NumPy and C kernels on arrays made here: the 2-rank run would repeat them
#: on each rank
pytestmark = pytest.mark.serial

FIELDS = ("xi", "y", "normal", "gap", "distance", "sliding")
#: The fields' bound, relative to each field's size (absolute below size 1): round-off. The
#: search calls the same projection as the reference, and is measured equal to the last bit.
ROUND_OFF = 1e-14
#: the reference of the records
FACET_BY_FACET = (
    "this code's projection onto each facet alone, the closest picked with the documented "
    "tie-break in the test"
)
QUANTITY = "max field difference (xi, y, n, g, distance, M), relative to size"


def reference(points: np.ndarray, nodes: np.ndarray, radius: float = np.inf):
    """Facet index and the fields of the closest point of every point, facet by facet."""
    centroid = nodes.mean(axis=1)
    size = np.linalg.norm(nodes - centroid[:, None], axis=2).max(axis=1)
    facet = np.full(len(points), -1)
    fields = {k: [] for k in FIELDS}
    for i, x in enumerate(points):
        each = [closest_points(x[None], nodes[f : f + 1]) for f in range(len(nodes))]
        dist = np.array([p.distance[0] for p in each])
        tied = np.flatnonzero(dist <= dist.min() + 1e-10 * (dist.min() + 2 * size))
        r = [x - each[f].y[0] for f in tied]
        align = [
            abs(each[f].normal[0] @ rf) / np.linalg.norm(rf) if rf.any() else 0.0
            for f, rf in zip(tied, r, strict=True)
        ]
        near = np.array([np.sum((x - centroid[f]) ** 2) for f in tied])
        # the most aligned, then the nearest centroid, then the lowest index (alignments and
        # relative squared centroid distances within 1e-12 are equal)
        aligned = np.asarray(align) >= max(align) - 1e-12
        nearest = aligned & (near <= near[aligned].min() * (1 + 1e-12))
        best = tied[nearest].min()
        if each[best].distance[0] <= radius:
            facet[i] = best
        for k in FIELDS:
            fields[k].append(getattr(each[best], k)[0])
    return facet, {k: np.array(v) for k, v in fields.items()}


def check(points, nodes, radius=np.inf, trees=None):
    """Check the search of ``points`` against :func:`reference`: the same facets, the same
    fields within :data:`ROUND_OFF`; return the search's projection and the largest field
    difference (relative to the field's size, absolute below 1)."""
    proj = closest_points(points, nodes, radius, trees)
    facet, fields = reference(points, nodes, radius)
    np.testing.assert_array_equal(proj.facet, facet)
    found = facet >= 0
    error = 0.0
    for k in FIELDS:
        a, b = getattr(proj, k)[found], fields[k][found]
        if b.size:
            error = max(error, np.abs(a - b).max() / max(1.0, np.abs(b).max()))
    assert error <= ROUND_OFF
    assert np.all(proj.distance[~found] == np.inf)
    return proj, error


def near_and_far(rng, nodes, n):
    """Points on the surface moved by 1e-3 to 1 (log-uniform), and uniform points around."""
    nf, nn, gdim = nodes.shape
    f = rng.integers(nf, size=n)
    N, _, _ = shape_functions(nn, gdim, rng.uniform(0, 0.5, size=(n, gdim - 1)))
    on = np.einsum("pn,png->pg", N, nodes[f])
    direction = rng.normal(size=(n, gdim))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    near = on + direction * 10.0 ** rng.uniform(-3, 0, size=(n, 1))
    lo, hi = nodes.reshape(-1, gdim).min(axis=0), nodes.reshape(-1, gdim).max(axis=0)
    return np.concatenate([near, rng.uniform(lo - 0.5, hi + 0.5, size=(n // 2, gdim))])


def record(verification, case, error):
    """Record the largest field difference of a test's checks (consistency)."""
    verification(case, QUANTITY, error, 0.0, ROUND_OFF, FACET_BY_FACET, kind="consistency")


#: the random surfaces of the tests: (maker, number of facets, description)
SEGMENTS = (segment_polyline, 50, "a random polyline of 50 segments (2D)")
TRIANGLES = (triangle_soup, 40, "40 random triangles (3D)")
QUADRILATERALS = (warped_quads, 20, "20 random warped bilinear quadrilaterals (3D)")
QUAD_GRID = (wavy_quads, 36, "a randomly warped grid of 36 bilinear quadrilaterals (3D)")


@pytest.mark.parametrize(
    ("make", "nf", "surface"),
    [SEGMENTS, TRIANGLES, QUADRILATERALS, QUAD_GRID],
    ids=["segments", "triangles", "quadrilaterals", "quad-grid"],
)
@pytest.mark.parametrize("radius", [np.inf, 0.05, 0.3])
def test_random_against_every_facet(make, nf, surface, radius, verification):
    rng = np.random.default_rng(nf)
    nodes = make(rng, nf)
    points = near_and_far(rng, nodes, 30)
    proj, error = check(points, nodes, radius)
    record(verification, f"pruned search: {surface}, radius {radius}", error)
    if np.isfinite(radius):  # some points are beyond the radius, some within
        assert 0 < np.count_nonzero(proj.facet < 0) < len(points)


def test_equidistant_segments(verification):
    """Exact ties: a vertex seen from the bisector (equal alignment, equal centroid
    distance: the lower index) and two parallel segments (the nearer centroid)."""
    v = np.array([[[0.0, 1.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, 1.0]]])
    errors = []
    for nodes in (v, v[::-1]):
        proj, error = check(np.array([[1.0, -1.0], [1.0, -0.25]]), nodes)
        np.testing.assert_array_equal(proj.facet, [0, 0])
        errors.append(error)
    parallel = np.array([[[0.0, 0.0], [1.0, 0.0]], [[0.25, 1.0], [2.25, 1.0]]])
    proj, error = check(np.array([[0.5, 0.5], [1.25, 0.5]]), parallel)
    np.testing.assert_array_equal(proj.facet, [0, 1])
    record(verification, "pruned search: equidistant segments (exact ties)", max(*errors, error))


def test_equidistant_grid_facets(verification):
    """Points above shared edges and vertices of flat unit grids of quadrilaterals and
    triangles, where several facets are at exactly the same distance and alignment."""
    s = np.arange(4.0)
    X, Y = np.meshgrid(s, s, indexing="ij")
    V = np.stack([X, Y, np.zeros_like(X)], axis=-1)
    quads = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:], V[1:, 1:]], axis=2).reshape(-1, 4, 3)
    lower = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:]], axis=2).reshape(-1, 3, 3)
    upper = np.stack([V[1:, :-1], V[1:, 1:], V[:-1, 1:]], axis=2).reshape(-1, 3, 3)
    points = np.array(
        [[1.0, 1.0, 0.5], [2.0, 1.0, -0.25], [1.0, 0.3, 0.5], [1.5, 2.0, 0.125], [0.5, 0.5, 1.0]]
    )
    errors = []
    for nodes in (quads, np.concatenate([lower, upper])):
        rng = np.random.default_rng(0)
        for order in (np.arange(len(nodes)), rng.permutation(len(nodes))):
            errors.append(check(points, nodes[order])[1])
            errors.append(check(points, nodes[order], radius=0.3)[1])
    case = "pruned search: flat grids of quadrilaterals and triangles (exact ties)"
    record(verification, case, max(errors))


def test_reused_tree_after_the_master_moves(verification):
    """The search tree (here the compiled search's hierarchy) of a master of the same shape
    is reused while its nodes move little: the results after small and large movements are
    those of a fresh projection."""
    rng = np.random.default_rng(7)
    nodes = wavy_quads(rng, 36)
    points = near_and_far(rng, nodes, 30)
    trees = TreeCache()
    errors = [check(points, nodes, trees=trees)[1]]

    def tree():
        (entry,) = trees.entries.values()
        return entry[1]

    first = tree()
    size = np.linalg.norm(nodes - nodes.mean(axis=1, keepdims=True), axis=2).max()
    for move, reused in ((1e-3 * size, True), (0.2 * size, True), (2.0 * size, False)):
        moved = nodes + rng.uniform(-move, move, size=nodes.shape) / np.sqrt(3.0)
        errors.append(check(points, moved, radius=0.2, trees=trees)[1])
        assert (tree() is first) == reused
        errors.append(check(points, moved, trees=trees)[1])
    case = "pruned search: a warped quadrilateral grid moved, its tree reused"
    record(verification, case, max(errors))


@pytest.mark.parametrize(
    ("make", "nf", "surface"),
    [SEGMENTS, TRIANGLES, QUAD_GRID],
    ids=["segments", "triangles", "quad-grid"],
)
def test_points_searched_in_cell_order(make, nf, surface, monkeypatch, verification):
    """The points ordered by cells before the search (as on a large master surface): the
    results come back in the order of the points given."""
    monkeypatch.setattr(closest_module, "_SORT", 0)
    rng = np.random.default_rng(nf + 2)
    nodes = make(rng, nf)
    points = near_and_far(rng, nodes, 30)
    order = spatial_order(points)
    assert not np.array_equal(order, np.arange(len(points)))  # the order changes
    error = check(points, nodes, 0.3)[1]
    record(verification, f"pruned search: {surface}, points in cell order", error)


def test_fan_columns_are_the_facets_beside():
    """The solver pattern's neighbourhood of a facet: its own columns and those of the
    facets sharing a side with it (a node of a segment, an edge of a triangle), not those
    sharing only a vertex in 3D; -1 pads the shorter rows."""
    chain = np.array([[0, 2], [2, 4], [4, 6], [6, 8]])
    fans = fan_columns(chain, 2, np.array([1, 0]))
    assert fans.tolist() == [[0, 2, 4, 6], [0, 2, 4, -1]]
    # triangles: 0 = (0, 1, 2); 1 shares the edge (1, 2); 2 shares only the vertex 0
    triangles = np.array([[0, 3, 6], [3, 6, 9], [0, 12, 15]])
    fans = fan_columns(triangles, 3, np.array([0, 2]))
    assert fans.tolist() == [[0, 3, 6, 9], [0, 12, 15, -1]]
    assert fan_columns(triangles, 3, np.zeros(0, dtype=int)).shape == (0, 0)


def _graded_master() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """5,000 segments 0.004 long on a gentle wave, the same with two segments 0.6 long
    beyond their end, and 2,000 points over the small ones."""
    x = np.linspace(0.0, 20.0, 5001)
    v = np.stack([x, 0.01 * np.sin(x)], axis=1)
    fine = np.stack([v[:-1], v[1:]], axis=1)
    end = v[-1]
    large = np.array([[end, end + [0.6, 0.0]], [end + [0.6, 0.0], end + [1.2, 0.0]]])
    rng = np.random.default_rng(3)
    u = rng.uniform(0.0, 19.0, 2000)
    offset = rng.choice([-1.0, 1.0], 2000) * 0.004 * 10.0 ** rng.uniform(-2.0, 1.0, 2000)
    points = np.stack([u, 0.01 * np.sin(u) + offset], axis=1)
    return fine, np.concatenate([fine, large]), points


def test_graded_master_candidates(monkeypatch):
    """NumPy search: two large facets beside many small ones (a graded master) leave the
    number of candidate pairs of the points near the small ones as it is without them: the
    large facets have KD-trees of their own instead of widening every query."""
    monkeypatch.setenv("CONTACT_UFL_SEARCH", "numpy")
    fine, graded, points = _graded_master()
    pairs = []
    lower_bound = MasterFacets.lower_bound

    def counted(self, x, f, pid=None):
        pairs.append(len(f))
        return lower_bound(self, x, f, pid)

    monkeypatch.setattr(MasterFacets, "lower_bound", counted)
    for radius in (0.04, np.inf):
        counts = []
        for nodes in (fine, graded):
            trees = TreeCache()
            for _ in range(2):  # KD-trees built, then reused
                pairs.clear()
                proj = closest_points(points, nodes, radius, trees)
                counts.append(sum(pairs))
            assert np.all(proj.facet < len(fine))
        # at most the K = 2 nearest centroids of the large facets' level more per point
        assert counts[2] <= counts[0] + 2 * len(points)
        assert counts[3] <= counts[1] + 2 * len(points)
        assert counts[0] < 4 * len(points)  # a few per point (measured 2.2)


def test_graded_master_projections_compiled(monkeypatch):
    """Compiled search: the two large facets of the graded master add almost no exact
    projections to the points over the small ones (the branch and bound prunes them by
    distance, whatever their size), at a finite and an infinite radius."""
    monkeypatch.delenv("CONTACT_UFL_SEARCH", raising=False)
    fine, graded, points = _graded_master()
    for radius in (0.04, np.inf):
        work = []
        for nodes in (fine, graded):
            trees = TreeCache()
            proj = closest_points(points, nodes, radius, trees)
            assert np.all(proj.facet < len(fine))
            (entry,) = trees.entries.values()
            work.append(entry[1].projections)
        assert work[1] <= work[0] + 0.01 * len(points)  # measured 0.006 per point
        assert work[0] < 3 * len(points)  # a few per point (measured 1.95)
