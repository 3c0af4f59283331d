"""Tests of the closest-point projection (`contact_ufl.contact.search.closest_points`)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.optimize import minimize

from contact_ufl.contact.search import closest_points, shape_functions

#: rank-local NumPy and C kernels on arrays made here: the 2-rank run would repeat them
#: on each rank
pytestmark = pytest.mark.serial

#: The bound of a closed form evaluated on data of size ~1 (hand-picked facets and points):
#: round-off, a few units in the last place (measured: exact, or 1 ulp).
EXACT = 1e-15
#: The bound of the flat facets' projections against the brute force (random facets of size
#: ~0.3, distances ~1): round-off, measured <= 5e-16; the margin allows another compiler's
#: or BLAS's order of the same operations.
FLAT = 1e-14
#: The bilinear quadrilaterals' brute force stops where L-BFGS-B does: its distances agree
#: to 7e-13 and its closest points (where the distance is stationary) to 1.1e-9, measured.
QUAD_DISTANCE, QUAD_POINT = 2e-12, 3e-9
#: Central differences with h = 1e-6 of quantities of size ~1 are exact for these
#: polynomials up to round-off, eps / h ~ 1e-10 (measured <= 9.3e-11).
CENTRAL = 3e-10
#: the source of the brute-force references
BRUTE_FORCE = (
    "a brute force written in the test: every facet, its vertices, edges and interior "
    "enumerated (bilinear quadrilaterals: L-BFGS-B from five starts)"
)
#: the surfaces of :func:`test_matches_brute_force`, by the id of their maker
SURFACES = {
    "segments": "a random polyline of 40 segments (2D)",
    "triangles": "60 random triangles (3D)",
    "quadrilaterals": "25 random warped bilinear quadrilaterals (3D)",
    "quad-grid": "a randomly warped grid of 36 bilinear quadrilaterals (3D)",
}

# -- random master surfaces ------------------------------------------------------------------


def segment_polyline(rng: np.random.Generator, n: int) -> np.ndarray:
    """A random open polyline of ``n`` segments, (n, 2, 2)."""
    steps = rng.normal(size=(n, 2)) * 0.3
    vertices = np.concatenate([[[0.0, 0.0]], np.cumsum(steps, axis=0)])
    return np.stack([vertices[:-1], vertices[1:]], axis=1)


def triangle_soup(rng: np.random.Generator, n: int) -> np.ndarray:
    """Random triangles of size ~0.3 scattered in the unit cube, (n, 3, 3)."""
    centres = rng.uniform(size=(n, 1, 3))
    return centres + rng.normal(size=(n, 3, 3)) * 0.15


def warped_quads(rng: np.random.Generator, n: int, warp: float = 0.25) -> np.ndarray:
    """Random non-planar bilinear quadrilaterals (basix order), (n, 4, 3)."""
    square = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    out = np.empty((n, 4, 3))
    for i in range(n):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        local = square + rng.uniform(-0.15, 0.15, size=(4, 3))
        local[:, 2] += rng.uniform(-warp, warp, size=4)
        out[i] = 0.3 * local @ q.T + rng.uniform(size=3)
    return out


# -- brute-force references: a plain loop over facets, active sets enumerated ------------------


def _point_on_segment(x, p, q):
    """Closest point on the segment pq by enumerating its end points and its interior."""
    options = [p, q]
    e = q - p
    u = np.dot(x - p, e) / np.dot(e, e)
    if 0.0 <= u <= 1.0:
        options.append(p + u * e)
    return min(options, key=lambda y: np.linalg.norm(x - y))


def _point_on_triangle(x, x0, x1, x2):
    """Closest point on a triangle: interior stationary point if feasible, else edges."""
    A = np.stack([x1 - x0, x2 - x0], axis=1)
    xi = np.linalg.solve(A.T @ A, A.T @ (x - x0))
    options = [_point_on_segment(x, p, q) for p, q in ((x0, x1), (x1, x2), (x2, x0))]
    if xi.min() >= 0 and xi.sum() <= 1:
        options.append(x0 + A @ xi)
    return min(options, key=lambda y: np.linalg.norm(x - y))


def _bilinear(X, s, t):
    return (1 - s) * (1 - t) * X[0] + s * (1 - t) * X[1] + (1 - s) * t * X[2] + s * t * X[3]


def _point_on_quad(x, X):
    """Closest point on a bilinear quadrilateral by L-BFGS-B from a grid of starts."""
    best = None

    def fun(z):
        r = x - _bilinear(X, *z)
        a1 = (1 - z[1]) * (X[1] - X[0]) + z[1] * (X[3] - X[2])
        a2 = (1 - z[0]) * (X[2] - X[0]) + z[0] * (X[3] - X[1])
        return r @ r, np.array([-2 * r @ a1, -2 * r @ a2])

    for s0, t0 in [(0.5, 0.5), *itertools.product((0.15, 0.85), repeat=2)]:
        res = minimize(
            fun,
            [s0, t0],
            jac=True,
            method="L-BFGS-B",
            bounds=[(0, 1), (0, 1)],
            options={"ftol": 1e-16, "gtol": 1e-14, "maxiter": 1000},
        )
        y = _bilinear(X, *res.x)
        if best is None or np.linalg.norm(x - y) < np.linalg.norm(x - best):
            best = y
    return best


def brute_force(points, nodes):
    """Per point: (distance, closest point, facet, margin to the second-best facet).

    A plain loop over the facets; a facet is skipped only when it is surely more than 1e-5
    farther than the best one so far (its node sphere around its centroid is).
    """
    nn = nodes.shape[1]
    project = {2: _point_on_segment, 3: _point_on_triangle, 4: _point_on_quad}[nn]
    centroids = nodes.mean(axis=1)
    radii = np.linalg.norm(nodes - centroids[:, None], axis=2).max(axis=1)
    out = []
    for x in points:
        best = (np.inf, None, -1)
        second = np.inf
        for f in np.argsort(np.linalg.norm(centroids - x, axis=1)):
            if np.linalg.norm(x - centroids[f]) - radii[f] > best[0] + 1e-5:
                continue
            y = project(x, *nodes[f]) if nn != 4 else project(x, nodes[f])
            d = np.linalg.norm(x - y)
            if d < best[0]:
                best, second = (d, y, f), best[0]
            else:
                second = min(second, d)
        out.append((best[0], best[1], best[2], second - best[0]))
    return out


def wavy_quads(rng: np.random.Generator, n: int) -> np.ndarray:
    """A connected, randomly warped grid of about ``n`` bilinear quadrilaterals."""
    m = int(np.sqrt(n))
    s = np.linspace(0.0, 1.0, m + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    V = np.stack([X, Y, rng.uniform(-0.6, 0.6, size=X.shape) / m], axis=-1)
    return np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:], V[1:, 1:]], axis=-2).reshape(-1, 4, 3)


@pytest.mark.parametrize(
    ("surface", "make", "nf", "tol", "point_tol"),
    [
        ("segments", segment_polyline, 40, FLAT, FLAT),
        ("triangles", triangle_soup, 60, FLAT, FLAT),
        ("quadrilaterals", warped_quads, 25, QUAD_DISTANCE, QUAD_POINT),
        ("quad-grid", wavy_quads, 36, QUAD_DISTANCE, QUAD_POINT),
    ],
    ids=list(SURFACES),
)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_matches_brute_force(surface, make, nf, tol, point_tol, seed, verification):
    """Verification: the closest points of random points (some on and near the surface)
    are those of a brute force over every facet: the same distance, and where one facet
    is closest by a margin, the same facet and point. The fields returned with them are
    consistent (the point is the facet at ``xi``, the normal a unit normal of the facet,
    the gap ``-n . (x - y)``)."""
    rng = np.random.default_rng(seed)
    nodes = make(rng, nf)
    gdim = nodes.shape[2]
    lo, hi = nodes.reshape(-1, gdim).min(axis=0), nodes.reshape(-1, gdim).max(axis=0)
    points = rng.uniform(lo - 0.2, hi + 0.2, size=(15, gdim))
    # a few points right on the surface, and a few near it
    n0 = min(5, nf)
    N, _, _ = shape_functions(nodes.shape[1], gdim, rng.uniform(0, 0.5, size=(n0, gdim - 1)))
    on = np.einsum("pn,png->pg", N, nodes[:n0])
    points = np.concatenate([points, on, on + rng.normal(size=on.shape) * 0.02])

    proj = closest_points(points, nodes)
    ref = brute_force(points, nodes)
    assert np.all(proj.facet >= 0)
    d = np.array([r[0] for r in ref])
    unique = np.array([r[3] > 1e-6 for r in ref])  # one closest facet by a margin
    distance_error = np.abs(proj.distance - d).max()
    point_error = max(np.abs(proj.y[i] - ref[i][1]).max() for i in np.flatnonzero(unique))
    case = f"closest points: {SURFACES[surface]}, seed {seed}"
    verification(case, "max |distance - brute force|", distance_error, 0.0, tol, BRUTE_FORCE)
    quantity = "max |y - brute force| (one closest facet)"
    verification(case, quantity, point_error, 0.0, point_tol, BRUTE_FORCE)
    assert distance_error <= tol
    assert np.abs(np.linalg.norm(points - proj.y, axis=1) - d).max() <= tol
    assert point_error <= point_tol
    facet = np.array([r[2] for r in ref])
    np.testing.assert_array_equal(proj.facet[unique], facet[unique])
    # the returned point is the interpolation of the facet at xi, the normal is a unit normal
    N, dN, _ = shape_functions(nodes.shape[1], gdim, proj.xi)
    X = nodes[proj.facet]
    np.testing.assert_allclose(np.einsum("pn,png->pg", N, X), proj.y, rtol=0, atol=EXACT)
    np.testing.assert_allclose(np.linalg.norm(proj.normal, axis=1), 1.0, rtol=0, atol=EXACT)
    a = np.einsum("pna,png->pag", dN, X)
    np.testing.assert_allclose(np.einsum("pag,pg->pa", a, proj.normal), 0.0, atol=EXACT)
    np.testing.assert_allclose(
        proj.gap, -np.einsum("pg,pg->p", proj.normal, points - proj.y), atol=1e-15
    )


def test_shape_function_derivatives():
    rng = np.random.default_rng(3)
    h = 1e-6
    for nn, gdim in ((2, 2), (3, 3), (4, 3)):
        fdim = gdim - 1
        xi = rng.uniform(0.1, 0.9, size=(5, fdim))
        N, dN, d2N = shape_functions(nn, gdim, xi)
        np.testing.assert_allclose(N.sum(axis=1), 1.0, rtol=0, atol=EXACT)
        for alpha in range(fdim):
            e = np.zeros(fdim)
            e[alpha] = h
            Np, dNp, _ = shape_functions(nn, gdim, xi + e)
            Nm, dNm, _ = shape_functions(nn, gdim, xi - e)
            np.testing.assert_allclose((Np - Nm) / (2 * h), dN[:, :, alpha], atol=CENTRAL)
            np.testing.assert_allclose((dNp - dNm) / (2 * h), d2N[:, :, :, alpha], atol=CENTRAL)


# -- edges and vertices -------------------------------------------------------------------------


def test_segment_end_points(verification):
    """Verification: the closest points of the segment (0, 0)-(2, 0), its two end points and
    its interior, and their distances, are the closed form's; ``M`` is zero at an end point
    and ``1 / |a1|^2`` inside."""
    nodes = np.array([[[0.0, 0.0], [2.0, 0.0]]])
    points = np.array([[-0.5, 0.2], [2.5, -0.3], [1.0, 0.4]])
    proj = closest_points(points, nodes)
    distance = [np.hypot(0.5, 0.2), np.hypot(0.5, 0.3), 0.4]
    error = max(
        np.abs(proj.y - [[0, 0], [2, 0], [1, 0]]).max(), np.abs(proj.distance - distance).max()
    )
    case = "closest points on the segment (0, 0)-(2, 0)"
    closed_form = "closed form: the end points, the foot of the perpendicular"
    verification(case, "max error of y and of the distance", error, 0.0, EXACT, closed_form)
    assert error <= EXACT
    np.testing.assert_allclose(proj.xi[:, 0], [0.0, 1.0, 0.5], rtol=0, atol=EXACT)
    np.testing.assert_array_equal(proj.sliding[:2], 0.0)  # vertex
    assert proj.sliding[2, 0, 0] == pytest.approx(1 / 4, rel=EXACT)  # interior: 1 / |a1|^2


def test_triangle_edges_and_vertices(verification):
    """Verification: the closest points on the unit right triangle from points beyond each
    edge, beyond two vertices and above its interior, and the linearisation ``M`` (the
    inverse metric in the interior, its restriction to the edge on an edge, zero at a
    vertex) are the closed form's."""
    nodes = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    points = np.array(
        [
            [0.5, -0.3, 0.2],  # edge xi2 = 0
            [0.8, 0.8, -0.1],  # hypotenuse
            [-0.4, 0.3, 0.1],  # edge xi1 = 0
            [-0.3, -0.2, 0.5],  # vertex 0
            [1.5, -0.1, 0.0],  # vertex 1
            [0.2, 0.3, 0.4],  # interior
        ]
    )
    proj = closest_points(points, nodes)
    y = [[0.5, 0, 0], [0.5, 0.5, 0], [0, 0.3, 0], [0, 0, 0], [1, 0, 0], [0.2, 0.3, 0]]
    M = proj.sliding
    edges = [[[1, 0], [0, 0]], [[0.5, -0.5], [-0.5, 0.5]], [[0, 0], [0, 1]]]
    M_exact = [*edges, np.zeros((2, 2)), np.zeros((2, 2)), np.eye(2)]
    case = "closest points on the unit right triangle (edges, vertices, interior)"
    closed_form = "closed form: the foot of the perpendicular on the face or edge, the vertex"
    y_error, M_error = np.abs(proj.y - y).max(), np.abs(M - M_exact).max()
    verification(case, "max |y - closed form|", y_error, 0.0, EXACT, closed_form)
    verification(case, "max |M - closed form|", M_error, 0.0, EXACT, closed_form)
    assert y_error <= EXACT and M_error <= EXACT
    np.testing.assert_array_equal(M[3:5], 0.0)
    assert [np.linalg.matrix_rank(m) for m in M] == [1, 1, 1, 0, 0, 2]


def test_quadrilateral_edge_and_vertex(verification):
    """Verification: on the flat 2 x 1 rectangle, the closest points beyond an edge, beyond
    a vertex and above the interior, and ``M``, are the closed form's."""
    nodes = np.array([[[0.0, 0, 0], [2, 0, 0], [0, 1, 0], [2, 1, 0]]])
    points = np.array([[1.0, -0.5, 0.3], [2.5, 0.5, 0.0], [3.0, 2.0, 1.0], [1.0, 0.5, 0.2]])
    proj = closest_points(points, nodes)
    y = [[1, 0, 0], [2, 0.5, 0], [2, 1, 0], [1, 0.5, 0]]
    M_exact = [[[0.25, 0], [0, 0]], [[0, 0], [0, 1]], np.zeros((2, 2)), [[0.25, 0], [0, 1]]]
    case = "closest points on the flat 2 x 1 bilinear quadrilateral (edges, vertex, interior)"
    closed_form = "closed form: the foot of the perpendicular on the face or edge, the vertex"
    y_error, M_error = np.abs(proj.y - y).max(), np.abs(proj.sliding - M_exact).max()
    verification(case, "max |y - closed form|", y_error, 0.0, EXACT, closed_form)
    verification(case, "max |M - closed form|", M_error, 0.0, EXACT, closed_form)
    assert y_error <= EXACT and M_error <= EXACT
    np.testing.assert_allclose(proj.xi, [[0.5, 0], [1, 0.5], [1, 1], [0.5, 0.5]], atol=EXACT)
    np.testing.assert_array_equal(proj.sliding[2], 0.0)


def test_quadrilateral_saddle_centre(verification):
    """Verification: hyperbolic paraboloid z = x y over [-1, 1]^2: seen from (0, 0, 1.5), the
    centre of the patch is a stationary point of the distance (a saddle) where Newton from the
    centre stops; the closest points are (+-1/sqrt 2, +-1/sqrt 2, 1/2), at distance sqrt 2
    (edges: sqrt 2.125)."""
    quad = np.array([[[-1.0, -1, 1], [1, -1, -1], [-1, 1, -1], [1, 1, 1]]])
    proj = closest_points([[0.0, 0.0, 1.5]], quad)
    error = abs(proj.distance[0] / np.sqrt(2.0) - 1.0)
    case = "closest point on z = x y over [-1, 1]^2 from (0, 0, 1.5)"
    closed_form = "closed form: y = (+-1/sqrt 2, +-1/sqrt 2, 1/2), distance sqrt 2"
    verification(case, "relative error of the distance", error, 0.0, EXACT, closed_form)
    assert error <= EXACT  # Newton converged to round-off (measured 1 ulp)
    y = proj.y[0]
    np.testing.assert_allclose(np.abs(y[:2]), np.sqrt(0.5), rtol=EXACT)
    assert y[0] * y[1] == pytest.approx(y[2], abs=EXACT) and y[2] == pytest.approx(0.5, abs=EXACT)
    assert np.all((proj.xi > 0) & (proj.xi < 1))


def test_tie_break_prefers_aligned_normal():
    # two segments sharing the vertex (1, 0); the point sees that vertex from both
    a = [[0.0, 0.0], [1.0, 0.0]]  # normal (0, -1)
    b = [[1.0, 0.0], [1.0, 1.0]]  # normal (1, 0)
    x = np.array([[1.5, -0.1]])  # x - y = (0.5, -0.1): aligned with b's normal
    for nodes, expected in (([a, b], 1), ([b, a], 0)):
        proj = closest_points(x, np.array(nodes))
        assert proj.facet[0] == expected
        np.testing.assert_array_equal(proj.normal[0], [1.0, 0.0])
        np.testing.assert_array_equal(proj.y[0], [1.0, 0.0])


# -- finite-difference check of the linearisation matrix --------------------------------------


def _check_sliding(nodes, x, rng, h=1e-6, expect_edge=False):
    """Central differences of xi against M b, for moves of the slave point and of each node;
    returns the largest difference."""
    nn, gdim = nodes.shape[1:]
    x = np.atleast_2d(x)
    proj = closest_points(x, nodes)
    f = proj.facet[0]
    N, dN, _ = shape_functions(nn, gdim, proj.xi)
    X = nodes[f]
    a = np.einsum("na,ng->ag", dN[0], X)
    r = x[0] - proj.y[0]
    M = proj.sliding[0]
    if expect_edge:
        assert np.linalg.matrix_rank(M) == 1
    else:
        assert np.linalg.matrix_rank(M) == gdim - 1

    errors = []

    def check(xp, xm, nodes_p, nodes_m, b):
        pp, pm = closest_points(xp, nodes_p), closest_points(xm, nodes_m)
        assert pp.facet[0] == pm.facet[0] == f
        fd = (pp.xi[0] - pm.xi[0]) / (2 * h)
        errors.append(np.abs(fd - M @ b).max())

    for _ in range(2):
        d = rng.normal(size=gdim)
        check(x + h * d, x - h * d, nodes, nodes, a @ d)
        for node in range(nn):
            d = rng.normal(size=gdim)
            nodes_p, nodes_m = nodes.copy(), nodes.copy()
            nodes_p[f, node] += h * d
            nodes_m[f, node] -= h * d
            b = a @ (-N[0, node] * d) + dN[0, node] * (r @ d)
            check(x, x, nodes_p, nodes_m, b)
    return max(errors)


#: the reference of the linearisation checks
CENTRAL_DIFFERENCES = "central differences of xi, h = 1e-6 (moves of the point and of each node)"


def record_sliding(verification, case, error):
    """Record and check the largest difference of the central differences of ``xi`` and
    ``M b`` (verification: the derivative of the projection against finite differences)."""
    quantity = "max |FD(xi) - M b|"
    verification(case, quantity, error, 0.0, CENTRAL, CENTRAL_DIFFERENCES)
    assert error <= CENTRAL


def test_sliding_finite_differences_segment(verification):
    rng = np.random.default_rng(10)
    nodes = np.array([[[0.1, 0.2], [1.3, 0.7]]])
    error = _check_sliding(nodes, [0.5, 0.9], rng)
    record_sliding(verification, "linearisation M of the projection on a segment", error)


def test_sliding_finite_differences_triangle(verification):
    rng = np.random.default_rng(11)
    nodes = np.array([[[0.1, 0.2, 0.0], [1.3, 0.4, 0.3], [0.2, 1.1, -0.2]]])
    error = _check_sliding(nodes, [0.5, 0.5, 0.6], rng)
    record_sliding(verification, "linearisation M of the projection inside a triangle", error)


def test_sliding_finite_differences_triangle_edge(verification):
    rng = np.random.default_rng(12)
    nodes = np.array([[[0.1, 0.2, 0.0], [1.3, 0.4, 0.3], [0.2, 1.1, -0.2]]])
    errors = []
    for x in ([0.6, -0.2, 0.4], [1.0, 1.0, 0.5], [-0.3, 0.6, 0.2]):  # three different edges
        proj = closest_points([x], nodes)
        assert np.linalg.matrix_rank(proj.sliding[0]) == 1
        errors.append(_check_sliding(nodes, x, rng, expect_edge=True))
    case = "linearisation M of the projection on a triangle's edges"
    record_sliding(verification, case, max(errors))


def test_sliding_finite_differences_warped_quadrilateral(verification):
    rng = np.random.default_rng(13)
    nodes = np.array([[[0.0, 0, 0], [1, 0.1, 0.3], [0.1, 1, -0.2], [1.1, 1.2, 0.4]]])
    errors = []
    for x in ([0.5, 0.5, 0.6], [0.4, 0.6, -0.5], [0.7, 0.3, 0.2]):
        proj = closest_points([x], nodes)
        assert np.all((proj.xi > 0) & (proj.xi < 1))
        errors.append(_check_sliding(nodes, x, rng))
    case = "linearisation M of the projection on a warped bilinear quadrilateral"
    record_sliding(verification, case, max(errors))
    # the curvature term matters: M differs from the inverse metric
    N, dN, _ = shape_functions(4, 3, proj.xi)
    a = np.einsum("na,ng->ag", dN[0], nodes[0])
    assert not np.allclose(proj.sliding[0], np.linalg.inv(a @ a.T), rtol=1e-3)


# -- radius and empty inputs -------------------------------------------------------------------


def test_radius():
    nodes = np.array([[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, 0.0]]])
    points = np.array([[0.5, 0.2], [1.5, -0.5], [5.0, 0.0], [0.5, 0.3]])
    proj = closest_points(points, nodes, radius=0.3)
    np.testing.assert_array_equal(proj.facet, [0, -1, -1, 0])
    np.testing.assert_allclose(proj.distance[[0, 3]], [0.2, 0.3], rtol=0, atol=EXACT)
    far = proj.facet < 0
    np.testing.assert_array_equal(proj.y[far], points[far])
    np.testing.assert_array_equal(proj.xi[far], 0.0)
    np.testing.assert_array_equal(proj.normal[far], 0.0)
    np.testing.assert_array_equal(proj.sliding[far], 0.0)
    assert np.all(proj.distance[far] == np.inf) and np.all(proj.gap[far] == -np.inf)
    # radius 0: only points on the surface
    proj = closest_points([[0.5, 0.0], [0.5, 1e-3]], nodes, radius=0.0)
    np.testing.assert_array_equal(proj.facet, [0, -1])
    # a point close to the centroid sphere but 0.424 from the triangle
    tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    assert closest_points([[0.8, 0.8, 0.0]], tri, radius=0.4).facet[0] == -1
    assert closest_points([[0.8, 0.8, 0.0]], tri, radius=0.43).facet[0] == 0
    with pytest.raises(ValueError):
        closest_points(points, nodes, radius=-1.0)


@pytest.mark.parametrize(("nn", "gdim"), [(2, 2), (3, 3), (4, 3)])
def test_empty_inputs(nn, gdim):
    fdim = gdim - 1
    nodes = np.random.default_rng(0).uniform(size=(3, nn, gdim))
    proj = closest_points(np.zeros((0, gdim)), nodes)
    shapes = [(0,), (0, fdim), (0, gdim), (0, gdim), (0,), (0,), (0, fdim, fdim)]
    fields = ("facet", "xi", "y", "normal", "gap", "distance", "sliding")
    assert [getattr(proj, k).shape for k in fields] == shapes
    points = np.ones((4, gdim))
    proj = closest_points(points, np.zeros((0, nn, gdim)))
    np.testing.assert_array_equal(proj.facet, -1)
    np.testing.assert_array_equal(proj.y, points)
    assert proj.sliding.shape == (4, fdim, fdim) and proj.facet.dtype == np.int64


def test_bad_shapes():
    with pytest.raises(ValueError):
        closest_points(np.zeros((2, 3)), np.zeros((1, 2, 3)))  # segment in 3D
    with pytest.raises(ValueError):
        closest_points(np.zeros((2, 2)), np.zeros((1, 3, 3)))  # point dimension


# -- size and speed ------------------------------------------------------------------------------


def wavy_triangles(n: int) -> np.ndarray:
    """2 n^2 triangles of the surface z = 0.1 sin(2 pi x) cos(2 pi y) over [0, 1]^2."""
    s = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    V = np.stack([X, Y, 0.1 * np.sin(2 * np.pi * X) * np.cos(2 * np.pi * Y)], axis=-1)
    v00, v10, v01, v11 = V[:-1, :-1], V[1:, :-1], V[:-1, 1:], V[1:, 1:]
    lower = np.stack([v00, v10, v11], axis=-2).reshape(-1, 3, 3)
    upper = np.stack([v00, v11, v01], axis=-2).reshape(-1, 3, 3)
    return np.concatenate([lower, upper])


def test_many_points_many_triangles(verification):
    """Verification: 1e5 points within 0.05 of a wavy surface of 2e4 triangles are all
    paired, and a sample of 20 has the distances of the brute force over the triangles
    near it."""
    nodes = wavy_triangles(100)  # 2e4 triangles
    assert nodes.shape == (20000, 3, 3)
    rng = np.random.default_rng(5)
    xy = rng.uniform(-0.05, 1.05, size=(100_000, 2))
    z = 0.1 * np.sin(2 * np.pi * xy[:, 0]) * np.cos(2 * np.pi * xy[:, 1])
    points = np.column_stack([xy, z + rng.uniform(-0.05, 0.05, size=z.size)])
    proj = closest_points(points, nodes)
    assert np.all(proj.facet >= 0)
    # a sample against the brute force over the triangles within 0.15 (centroids)
    sample = rng.choice(points.shape[0], 20, replace=False)
    near = np.linalg.norm(nodes.mean(axis=1)[None] - points[sample, None], axis=2) < 0.15
    d = [brute_force(points[i : i + 1], nodes[near[k]])[0][0] for k, i in enumerate(sample)]
    error = np.abs(proj.distance[sample] - d).max()
    case = "closest points: 1e5 points near a wavy surface of 2e4 triangles"
    quantity = "max |distance - brute force| (a sample of 20)"
    verification(case, quantity, error, 0.0, FLAT, BRUTE_FORCE)
    assert error <= FLAT


# -- orientation -------------------------------------------------------------------------------


def test_orientation_segment(verification):
    """Segment (0,0) -> (1,0) of a counter-clockwise boundary: the body lies above it.

    nu = (a1[1], -a1[0]) / |a1| = (0, -1), the outward normal. With g = -nu . (x - y) the
    point (0.5, 0.1) inside the body has g = +0.1 (penetration) and the point (0.5, -0.1)
    outside it has g = -0.1 (the formulation's property (c), the gap function's sign).
    """
    nodes = np.array([[[0.0, 0.0], [1.0, 0.0]]])
    proj = closest_points([[0.5, -0.1], [0.5, 0.1]], nodes)
    np.testing.assert_array_equal(proj.normal, [[0.0, -1.0], [0.0, -1.0]])
    error = np.abs(proj.gap - [-0.1, 0.1]).max()
    case = "gap of (0.5, -+0.1) from the segment (0, 0)-(1, 0), body above"
    source = "the formulation's property (c): g = -nu . (x - y), positive in penetration"
    verification(case, "max |g - closed form|", error, [-0.1, 0.1], EXACT, source)
    assert error <= EXACT


def test_orientation_triangle_and_quadrilateral(verification):
    """The normals of a counter-clockwise triangle and quadrilateral in z = 0 are +z, and
    the gap of a point at z = +-0.5 is -+0.5 (the formulation's property (c))."""
    tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    proj = closest_points([[0.2, 0.2, 0.5], [0.2, 0.2, -0.5]], tri)
    np.testing.assert_array_equal(proj.normal, [[0, 0, 1], [0, 0, 1]])
    errors = [np.abs(proj.gap - [-0.5, 0.5]).max()]
    quad = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]])
    proj = closest_points([[0.3, 0.6, 0.5]], quad)
    np.testing.assert_array_equal(proj.normal, [[0, 0, 1]])
    errors.append(abs(proj.gap[0] + 0.5))
    case = "gap of points at z = +-0.5 from a triangle and a quadrilateral in z = 0"
    source = "the formulation's property (c): g = -nu . (x - y), positive in penetration"
    verification(case, "max |g - closed form|", max(errors), [-0.5, 0.5], EXACT, source)
    assert max(errors) <= EXACT
