"""Quadratic elements in contact: degree-2 displacement on straight and curved geometry.

The master facets are then quadratic (3-node segments in 2D, 6-node triangles in 3D): the
closest point on them is found by Newton (:mod:`contact_ufl.contact.search.curved`), its
linearisation has the facet's curvature, and the tangent stays the derivative of the
residual (Taylor remainders of order 2), frictionless and in slip.
"""

import dataclasses

import basix
import dolfinx
import numpy as np
import pytest
import ufl
from conftest import assert_taylor_slopes
from mpi4py import MPI
from test_self_contact import _slot_scene
from test_taylor import SLOPE_TOL, check_zeroth_slopes, record_slopes

from contact_ufl.contact.interface import ContactInterface
from contact_ufl.contact.obstacles import RigidPlane
from contact_ufl.contact.quadrature import composite_quadrature, iso_subdivisions
from contact_ufl.contact.search import closest_points, curved, shape_functions
from contact_ufl.contact.slave import SlaveSurface
from contact_ufl.errors import ContactInputError
from contact_ufl.materials import LinearElastic
from contact_ufl.membranes import MembraneNeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import Hertz2D, fit_elliptic_profile
from contact_ufl.verification.scenes import curved_pair, patch, with_membrane
from contact_ufl.verification.taylor_cases import curved_case

RNG_SEED = 7
#: the bound on |slope - 1| of the zeroth-order Taylor remainders (8.8e-4 measured, 2D P2)
ZEROTH_TOL = 2e-3
JOHNSON = "Johnson, Contact Mechanics (1985), 4.2: closed form at the computed force"
UNIFORM = "the applied pressure: the patch test's exact solution is uniform"
EQUILIBRIUM = "the equilibrium of a converged solve: the test functions sum to one"


def random_segments(rng, n):
    """Curved 3-node segments (ends, midpoint) of length about 1, bent both ways."""
    a = rng.uniform(-1, 1, (n, 2))
    angle = rng.uniform(0, 2 * np.pi, n)
    b = a + np.stack([np.cos(angle), np.sin(angle)], axis=1)
    normal = np.stack([np.sin(angle), -np.cos(angle)], axis=1)
    mid = 0.5 * (a + b) + rng.uniform(-0.15, 0.15, (n, 1)) * normal
    mid += rng.uniform(-0.1, 0.1, (n, 1)) * (b - a)  # not at the middle of the arc
    return np.stack([a, b, mid], axis=1)


def random_triangles(rng, n):
    """Curved 6-node triangles (vertices, then midpoints of edges 01, 12, 02)."""
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    v = v + rng.uniform(-0.2, 0.2, (n, 3, 3))
    mids = [0.5 * (v[:, i] + v[:, j]) for i, j in ((0, 1), (1, 2), (0, 2))]
    mids = np.stack(mids, axis=1) + rng.uniform(-0.12, 0.12, (n, 3, 3))
    return np.concatenate([v, mids], axis=1)


def random_quadrilaterals(rng, n):
    """Curved 9-node quadrilaterals (basix vertices, midpoints of edges 01, 13, 23, 02,
    centre)."""
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]])
    v = v + rng.uniform(-0.2, 0.2, (n, 4, 3))
    mids = [0.5 * (v[:, i] + v[:, j]) for i, j in ((0, 1), (1, 3), (2, 3), (0, 2))]
    mids.append(v.mean(axis=1))
    mids = np.stack(mids, axis=1) + rng.uniform(-0.12, 0.12, (n, 5, 3))
    return np.concatenate([v, mids], axis=1)


def sampled_distance(points, nodes, xi):
    """The smallest distance of each point to its facet over the samples ``xi`` (brute
    force)."""
    N = shape_functions(nodes.shape[1], nodes.shape[2], xi)[0]
    out = []
    for k in range(0, len(points), 20):  # in chunks: (points, samples, gdim) arrays
        y = np.einsum("sn,fnd->fsd", N, nodes[k : k + 20])
        out.append(np.linalg.norm(points[k : k + 20, None, :] - y, axis=2).min(axis=1))
    return np.concatenate(out)


@pytest.mark.parametrize("kind", ["segment3", "triangle6", "quadrilateral9"])
def test_closest_point_on_quadratic_facets(kind):
    """One facet per point: the distance found is never above the sampled minimum (no
    wrong local minimum), and below it by at most the sampling's resolution; ``y`` is on
    the facet at ``xi``, and ``xi`` is inside."""
    rng = np.random.default_rng(RNG_SEED)
    gdim = 2 if kind == "segment3" else 3
    n = 200 if gdim == 2 else 100
    if gdim == 2:
        nodes = random_segments(rng, n)
        xi = np.linspace(0, 1, 4001)[:, None]
        resolution = 2.0 / 4000  # sample spacing times the largest |dy/dxi|
    else:
        make = random_triangles if kind == "triangle6" else random_quadrilaterals
        nodes = make(rng, n)
        s, t = np.meshgrid(np.linspace(0, 1, 201), np.linspace(0, 1, 201))
        xi = np.stack([s.ravel(), t.ravel()], axis=1)
        xi = xi[xi.sum(axis=1) <= 1.0] if kind == "triangle6" else xi
        resolution = 2.0 / 200
    centre = nodes.mean(axis=1)
    points = centre + rng.uniform(-0.6, 0.6, (n, gdim))
    brute = sampled_distance(points, nodes, xi)
    for f in range(0, n, 50):  # one facet at a time: each point pairs with its own facet
        rows = slice(f, f + 50)
        proj = [closest_points(points[k : k + 1], nodes[k : k + 1]) for k in range(f, f + 50)]
        dist = np.array([p.distance[0] for p in proj])
        assert np.all(dist <= brute[rows] + 1e-12)
        assert np.all(dist >= brute[rows] - resolution)
        xis = np.array([p.xi[0] for p in proj])
        assert np.all(xis >= 0.0)
        assert np.all(xis.sum(axis=1) <= 1.0 if kind == "triangle6" else xis <= 1.0)
        N = shape_functions(nodes.shape[1], gdim, xis)[0]
        y = np.einsum("pn,pnd->pd", N, nodes[rows])
        assert np.allclose(y, np.array([p.y[0] for p in proj]), atol=1e-14)


@pytest.mark.parametrize("search", ["compiled", "numpy"])
def test_restart_finds_the_interior_minimum_the_first_newton_misses(search, monkeypatch):
    """A point farther than a fifth of a saddle-shaped 9-node facet's radius of curvature:
    Newton from the centre settles at a minimum of the facet's extension outside it, and a
    restart finds the interior minimum, which is the closest point (brute force) and closer
    than every edge."""
    monkeypatch.setenv("CONTACT_UFL_SEARCH", search)
    nodes = np.array(
        [
            [[0.052, 0.012, -0.095], [1.002, -0.03, 0.057], [-0.008, 0.997, 0.103]],
            [[0.981, 0.971, -0.12], [0.495, -0.024, -0.089], [0.978, 0.523, -0.095]],
            [[0.486, 1.023, 0.113], [0.038, 0.542, -0.026], [0.515, 0.459, -0.135]],
        ]
    ).reshape(1, 9, 3)
    x = np.array([[0.914, 0.623, 0.671]])
    kind = "quadrilateral9"
    xi0, dist0, good0, settled0 = curved._newton(kind, x, nodes, np.full((1, 2), 0.5))
    assert settled0[0] and not good0[0] and np.any(xi0 > 1.0)
    assert dist0[0] * curved.curvature(kind, nodes)[0] > curved.RESTART_CURVATURE
    edges = [
        curved.curve_closest(x, *nodes[0, list(e)][:, None])[1][0]
        for e in curved.QUADRILATERAL9_EDGES
    ]
    proj = closest_points(x, nodes)
    assert np.all((proj.xi > 0.0) & (proj.xi < 1.0))
    assert proj.distance[0] < min(edges) - 1e-3
    s, t = np.meshgrid(np.linspace(0, 1, 401), np.linspace(0, 1, 401))
    brute = sampled_distance(x, nodes, np.stack([s.ravel(), t.ravel()], axis=1))[0]
    assert brute - 2.0 / 400 <= proj.distance[0] <= brute + 1e-12


@pytest.mark.parametrize("kind", ["segment3", "triangle6", "quadrilateral9"])
def test_sliding_matrix_is_the_derivative_of_xi(kind):
    """``M b`` is the derivative of the closest point's ``xi`` along a move of the slave
    point (curved facet: ``A`` has the curvature term): finite differences agree."""
    rng = np.random.default_rng(RNG_SEED + len(kind))
    make = {
        "segment3": random_segments,
        "triangle6": random_triangles,
        "quadrilateral9": random_quadrilaterals,
    }
    nodes = make[kind](rng, 1)
    gdim = nodes.shape[2]
    centroid_xi = np.full((1, gdim - 1), 0.5 if kind == "quadrilateral9" else 1.0 / gdim)
    N, dN, _ = shape_functions(nodes.shape[1], gdim, centroid_xi)
    y = N @ nodes[0]
    a = np.einsum("pna,nd->pad", dN, nodes[0])[0]
    normal = np.cross(a[0], a[1]) if gdim == 3 else np.array([a[0, 1], -a[0, 0]])
    x = y[0] + 0.3 * normal / np.linalg.norm(normal)
    proj = closest_points(x[None], nodes)
    assert proj.xi[0].min() > 0.05  # interior
    dx = rng.normal(size=gdim)
    h = 1e-6
    xi_h = closest_points((x + h * dx)[None], nodes).xi[0]
    xi_m = closest_points((x - h * dx)[None], nodes).xi[0]
    _, dN, _ = shape_functions(nodes.shape[1], gdim, proj.xi)
    a = np.einsum("pna,nd->pad", dN, nodes[0])[0]
    b = a @ dx  # b_alpha = a_alpha . dx (the master fixed)
    predicted = proj.sliding[0] @ b
    assert np.allclose((xi_h - xi_m) / (2 * h), predicted, rtol=1e-6, atol=1e-9)
    # the metric alone (a flat facet's M) is off: the curvature matters
    assert not np.allclose(np.linalg.solve(a @ a.T, b), predicted, rtol=1e-3)


def check_taylor(problem, dz, steps, verification, case):
    """Slopes 2 of the first-order remainders and 1 of the zeroth-order ones (the bounds of
    tests/test_taylor.py), recorded as ``case``."""
    assert problem.active_points() > 10
    result = assert_taylor_slopes(problem, dz, steps, tol=SLOPE_TOL)
    record_slopes(verification, case, result, tol=SLOPE_TOL)
    check_zeroth_slopes(verification, case, result, tol=ZEROTH_TOL)


@pytest.mark.parametrize("order", [1, 2])
def test_taylor_quadratic_2d(order, verification):
    """P2 displacement on straight (order 1) and curved (order 2) triangles: 3-node master
    segments, the tangent exact."""
    problem, dz, steps = curved_case(2, degree=2, order=order)
    assert problem.contacts[0].kinematics.nn == 3
    shape = "curved" if order == 2 else "straight"
    check_taylor(problem, dz, steps, verification, f"Taylor test 2D, P2, {shape} triangles")


@pytest.mark.parametrize(
    "dim, order, cell",
    [
        pytest.param(2, 2, "triangle", marks=pytest.mark.serial),  # 2 ranks: 3D
        (3, 1, "tetrahedron"),
        pytest.param(3, 1, "hexahedron", marks=pytest.mark.slow),
    ],
)
def test_taylor_quadratic_slip(dim, order, cell, verification):
    """With friction, every contact point in slip on the quadratic master (2D: curved
    geometry): the slip reference ``y_n`` on the last step's quadratic facet, chained
    through its gathered nodes; the tangent exact."""
    problem, dz, steps = curved_case(dim, mu=0.05, degree=2, order=order, cell=cell)
    c = problem.contacts[0]
    active = problem.comm.allreduce(int(c.active().sum()))
    assert active > 10 and problem.comm.allreduce(int(c.stick().sum())) == 0
    case = f"Taylor test {dim}D, P2, {cell}, slip (mu = 0.05)"
    check_taylor(problem, dz, steps, verification, case)


@pytest.mark.parametrize(
    "cell, nn",
    # 2 ranks: tetrahedra (the hexahedra's gathers are the same code)
    [("tetrahedron", 6), pytest.param("hexahedron", 9, marks=pytest.mark.serial)],
)
def test_taylor_quadratic_3d(cell, nn, verification):
    """P2 tetrahedra (6-node triangles as master facets) and Q2 hexahedra (9-node
    quadrilaterals, on the saddle of :func:`~contact_ufl.verification.scenes.warp_saddle`),
    frictionless."""
    problem, dz, steps = curved_case(3, degree=2, cell=cell)
    assert problem.contacts[0].kinematics.nn == nn
    check_taylor(problem, dz, steps, verification, f"Taylor test 3D, degree 2, {cell}")


# -- bad input: a clear error naming what is supported, on every rank ----------------------


@pytest.fixture(scope="module")
def scene():
    return curved_pair(2)


def with_pair(scene, **changes):
    return dataclasses.replace(scene, contacts=[dataclasses.replace(scene.contacts[0], **changes)])


@pytest.mark.parametrize(
    "degree, changes, message",
    [
        (3, {}, "degree-3 displacement on a degree-1 geometry: contact supports a degree-1"),
        (2, dict(master_normal="smoothed"), 'master_normal="smoothed".*needs a degree-1'),
        (1, dict(multiplier_degree=2), "multiplier_degree=2 .* needs a displacement of that"),
        (2, dict(multiplier_degree=3), "multiplier_degree must be 1 or 2"),
        (1, dict(multiplier_degree="iso"), "'iso' \\(P1-iso-P2\\) .* needs a degree-2 displace"),
        (2, dict(multiplier_degree="P1-iso-P2"), "must be 1 or 2 \\(Lagrange\\) or 'iso'"),
    ],
)
def test_unsupported_pairs(scene, degree, changes, message):
    with pytest.raises(ContactInputError, match=message):
        ContactProblem(with_pair(scene, **changes), degree=degree, verbose=False)


def test_default_master_normal_with_degree_2_is_the_facet_normal(scene):
    """With a degree-2 displacement the default master normal is the quadratic facet's (the
    smoothed one would be refused): the 2D pair builds."""
    assert scene.contacts[0].master_normal is None
    problem = ContactProblem(scene, degree=2, verbose=False)
    assert problem.contacts[0].pair.master_normal == "facet"


def test_linear_displacement_on_curved_geometry_is_rejected():
    """A degree-1 displacement on a degree-2 (curved) mesh: its facets are not given by
    displacement dofs."""
    with pytest.raises(ContactInputError, match="degree-1 displacement on a degree-2 geometry"):
        ContactProblem(curved_pair(2, order=2), degree=1, verbose=False)


def test_quadratic_membrane_is_rejected(scene):
    membrane = with_membrane(scene, "master", MembraneNeoHookean(1.0, 0.05), np.array([0, 1.0]))
    with pytest.raises(ContactInputError, match="membranes in contact need a degree-1"):
        ContactProblem(membrane, degree=2, verbose=False)


def test_serendipity_is_rejected():
    """8-node serendipity quadrilateral facets are not implemented: the family is named."""
    scene = curved_pair(3, cell="hexahedron")
    mesh = scene.parts[0].mesh
    u = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, ("S", 2, (3,))))
    tags = scene.parts[0].surface_tags
    with pytest.raises(ContactInputError, match="serendipity family: contact supports Lagrange"):
        ContactInterface(u, tags, scene.contacts[0], 1.0)


def test_mixed_degrees_are_rejected(scene):
    """A pair whose slave and master displacements differ in degree."""
    mesh = scene.parts[0].mesh
    u1 = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (2,))))
    u2 = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, ("Lagrange", 2, (2,))))
    tags = scene.parts[0].surface_tags
    message = "degree-1 displacement and the master surface .* a degree-2 one"
    with pytest.raises(ContactInputError, match=message):
        ContactInterface(u1, tags, scene.contacts[0], 1.0, master_u=u2)


# -- the multipliers with a degree-2 displacement: patch test and Hertz --------------------

PRESSURE = 0.01
TIGHT = {"snes_rtol": 1e-13, "snes_atol": 1e-15}
#: test_hertz_quadratic_2d's bounds: p0 of the nominal pressure, p0 of the Cauchy pressure
#: (relative errors), the largest nodal deviation from Hertz's profile over p0
HERTZ_P2 = (2e-4, 0.01, 0.05)
#: test_self_contact_quadratic's bound on the top reaction against the two-surface pair's
SLOT_Q2 = 1e-5


def solve_patch(dim, multiplier_degree, quadrature_degree, subdivisions, cell=None):
    scene = patch(
        dim, PRESSURE, quadrature_degree=quadrature_degree, subdivisions=subdivisions, cell=cell
    )
    scene = with_pair(scene, multiplier_degree=multiplier_degree)
    problem = ContactProblem(scene, degree=2, verbose=False, petsc_options=TIGHT)
    problem.solve(num_steps=1)
    lam = problem.contacts[0].lambda_N.x.array
    deviation = problem.comm.allreduce(np.abs(lam / PRESSURE - 1.0).max(initial=0.0), MPI.MAX)
    return problem, deviation


def record_patch(verification, case, problem, deviation, bounds):
    """Record the patch test's nodal deviation (within the ``bounds`` text) and the normal
    contact force against the applied load (consistency: to 1e-12)."""
    quantity = "largest |lambda_N / p - 1| over the nodes"
    verification(case, quantity, deviation, "lambda_N = p", bounds, UNIFORM)
    dim = problem.gdim
    force = abs(problem.contact_force()[dim - 1] / PRESSURE - 1.0)
    quantity = "|F_normal / (p A) - 1|"
    verification(case, quantity, force, 0.0, "< 1e-12", EQUILIBRIUM, kind="consistency")
    return force


@pytest.mark.parametrize("cell", ["triangle", "quadrilateral"])
def test_patch_quadratic_2d(cell, verification):
    """P2 (Q2) displacement, P1 multipliers (the default), the composite rule of the P1
    patch test: the pressure uniform to 1e-3 (3.4e-4 measured, 3.8e-4 on Q2; P1
    displacement: 4.8e-4), the force exact."""
    problem, deviation = solve_patch(2, 1, 5, 8, cell)
    case = f"patch test 2D, degree 2 {cell}s, P1 multipliers, degree 5 rule on 8 sub-segments"
    force = record_patch(verification, case, problem, deviation, "< 1e-3")
    assert deviation < 1e-3
    assert force < 1e-12


@pytest.mark.slow  # 10 s (a minute to compile the Q2 hexahedron's forms)
@pytest.mark.parametrize(
    "multiplier_degree, low, high",
    [
        (1, 2e-3, 5e-3),  # measured 3.1e-3 (P2 tetrahedra: 7.0e-3)
        (2, 2e-2, 1e-1),  # measured 4.2e-2: the P2 multipliers oscillate (tetrahedra: 5.0e-2)
    ],
)
def test_patch_quadratic_hexahedra(multiplier_degree, low, high, verification):
    """Q2 hexahedra (9-node quadrilateral facets), the 3D composite rule of degree 4 x 2:
    P1 multipliers give the pressure uniform to 3.1e-3, P2 multipliers 13 times less
    uniform, as on P2 tetrahedra; the force exact with either. Both bounds are asserted,
    so that a change shows."""
    problem, deviation = solve_patch(3, multiplier_degree, 4, 2, "hexahedron")
    assert problem.contacts[0].kinematics.nn == 9
    case = f"patch test 3D, Q2 hexahedra, P{multiplier_degree} multipliers, rule 4 x 2"
    force = record_patch(verification, case, problem, deviation, f"in ({low:g}, {high:g})")
    assert low < deviation < high
    assert force < 1e-12


@pytest.mark.slow
@pytest.mark.parametrize(
    "dim, multiplier_degree, quadrature_degree, subdivisions, low, high",
    [
        (2, 2, 5, 8, 1e-3, 2e-3),  # measured 1.24e-3 (P1 multipliers: 3.4e-4)
        (3, 1, 4, 2, 5e-3, 1e-2),  # measured 7.0e-3
        (3, 2, 4, 2, 3e-2, 1e-1),  # measured 5.0e-2: the P2 multipliers oscillate
    ],
)
def test_patch_quadratic_multipliers(
    dim, multiplier_degree, quadrature_degree, subdivisions, low, high, verification
):
    """The evidence for P1 multipliers with a P2 displacement: P2 multipliers make the patch
    test's pressure 4 (2D) to 7 (3D: the vertex functions of a 6-node triangle integrate to
    zero) times less uniform. Both bounds are asserted, so that a change shows."""
    problem, deviation = solve_patch(dim, multiplier_degree, quadrature_degree, subdivisions)
    case = (
        f"patch test {dim}D, P2 displacement, P{multiplier_degree} multipliers, "
        f"degree {quadrature_degree} rule on {subdivisions} sub-facets"
    )
    quantity = "largest |lambda_N / p - 1| over the nodes"
    verification(case, quantity, deviation, "lambda_N = p", f"in ({low:g}, {high:g})", UNIFORM)
    assert low < deviation < high


def _nodal_profile(comm, f) -> tuple[np.ndarray, np.ndarray]:
    """The x coordinates and values of a scalar field's nodes on all ranks, each node once
    (the owned dofs: the coordinates of a shared node tabulated by two ranks' cells can
    differ by round-off), sorted by x."""
    owned = f.function_space.dofmap.index_map.size_local
    x = np.concatenate(comm.allgather(f.function_space.tabulate_dof_coordinates()[:owned, 0]))
    values = np.concatenate(comm.allgather(f.x.array[:owned]))
    order = np.argsort(x)
    return x[order], values[order]


@pytest.mark.serial  # 2 ranks: the 3D variants (the same gathers)
def test_hertz_quadratic_2d(verification):
    """P2 on the curved (degree-2) mesh, P1 multipliers, linear elastic, one load step,
    h = 0.02 (12,613 unknowns, a / h = 2.5), the default contact rule: p0 of the nominal
    pressure at the reference positions within 2e-4 of Hertz (+8.3e-5 measured: on this
    mesh; the next ones are off by up to 2%, see docs/quadratic-contact.md), the Cauchy
    pressure's within 1% (+0.65%: it has a floor of about +0.7%) and a smooth multiplier:
    within 5% of the Hertz profile inside 0.8 a (4.4%), no zig-zag between neighbouring
    nodes."""
    hertz = scenes.hertz_2d(h_contact=0.02, depth=0.005, order=2)
    scene = hertz.scene
    scene.bodies = [
        dataclasses.replace(b, material=LinearElastic(b.material.E, b.material.nu))
        for b in scene.bodies
    ]
    problem = ContactProblem(scene, degree=2, verbose=False)
    problem.solve(num_steps=1)
    samples = contact_samples(problem)
    exact = Hertz2D(problem.contact_force()[1], hertz.radius, hertz.E_star)
    c = problem.contacts[0]
    X = np.concatenate(problem.comm.allgather(c.slave.X.reshape(-1, 2)))
    _, p0_nominal, _ = fit_elliptic_profile(X[:, 0], samples.lambda_N)
    _, p0, _ = fit_elliptic_profile(samples.x[:, 0], samples.pressure)
    x, lam = _nodal_profile(problem.comm, c.lambda_N)
    lam = lam / exact.p0
    inside = np.abs(x) < 0.8 * exact.a
    hertz_profile = np.sqrt(1.0 - (x[inside] / exact.a) ** 2)
    profile = np.abs(lam[inside] - hertz_profile).max()
    case = "Hertz 2D, P2 on the curved mesh, P1 multipliers, linear elastic, a/h = 2.5"
    for quantity, value, bound in (
        ("relative error of p0, nominal pressure at the reference positions", p0_nominal, 0),
        ("relative error of p0, Cauchy pressure", p0, 1),
    ):
        error = value / exact.p0 - 1.0
        verification(
            case, quantity, error, "p0 = 2 P / (pi a)", f"|error| < {HERTZ_P2[bound]:g}", JOHNSON
        )
        assert abs(error) < HERTZ_P2[bound]
    quantity = "largest nodal |lambda_N / p0 - sqrt(1 - x^2 / a^2)| in |x| < 0.8 a"
    tolerance = f"< {HERTZ_P2[2]:g}"
    verification(case, quantity, profile, "p(x) = p0 sqrt(1 - x^2 / a^2)", tolerance, JOHNSON)
    assert profile < HERTZ_P2[2]
    # no oscillation: the second differences of a concave profile are all negative
    assert np.all(np.diff(lam[inside], 2) < 0.0)


def test_self_contact_quadratic(verification):
    """The slot of tests/test_self_contact.py pressed shut with Q2: self-contact of its
    surface (3-node segments, keyed by their vertices) gives the classical pair's
    reaction (to SLOT_Q2) and Newton iterations (a consistency check of the self-contact
    search against the two-surface one)."""
    results = []
    for self_contact in (True, False):
        problem = ContactProblem(_slot_scene(MPI.COMM_WORLD, self_contact), degree=2, verbose=False)
        problem.solve(num_steps=4)
        assert problem.contacts[0].kinematics.nn == 3 and problem.active_points() >= 12
        results.append((problem.reaction(2), [s.newton_iterations for s in problem.history.steps]))
    (a, steps_a), (b, steps_b) = results
    assert steps_a == steps_b and a[1] < -0.2
    difference = np.linalg.norm(a - b) / np.linalg.norm(b)
    case = "slot closing on itself, 2D, Q2, self-contact against a two-surface pair"
    quantity = "|top reaction difference| / |top reaction|"
    source = "the same slot with a two-surface pair (lower face slave, upper face master)"
    verification(case, quantity, difference, 0.0, f"< {SLOT_Q2:g}", source, kind="consistency")
    assert difference < SLOT_Q2


# -- P1-iso-P2 multipliers (multiplier_degree="iso") ---------------------------------------


@pytest.mark.parametrize("cell", ["interval", "triangle", "quadrilateral"])
def test_iso_rule_is_composite_over_the_refined_cells(cell):
    """With P1-iso-P2 multipliers the contact rule is composite over the once-refined cells
    (its subdivisions rounded up to an even number): it integrates the products of their
    piecewise-linear functions exactly; the rule of 1 or 3 subdivisions, across their
    kinks, does not."""
    cell_type = getattr(basix.CellType, cell)
    iso = basix.create_element(basix.ElementFamily.iso, cell_type, 1)

    def mass(points, weights):
        phi = iso.tabulate(0, points)[0, :, :, 0]
        return np.einsum("q,qi,qj->ij", weights, phi, phi)

    exact = mass(*composite_quadrature(cell_type, 2, 4))  # degree 2 on each refined cell
    for m in (1, 3):
        assert iso_subdivisions(m) == m + 1
        assert np.allclose(mass(*composite_quadrature(cell_type, 5, iso_subdivisions(m))), exact)
        assert not np.allclose(mass(*composite_quadrature(cell_type, 5, m)), exact, atol=1e-4)


def test_iso_multipliers_of_a_pair(scene):
    """``multiplier_degree="iso"`` on the 2D curved pair: one multiplier node per node of
    the P2 trace (vertices and midpoints), the contact rule doubled (2 subdivisions), and
    the nodal masses of the contact measure exact also in forms without point data (the
    custom rule of the slave points): ``h / 4`` per segment at a vertex, ``h / 2`` at a
    midpoint (one Gauss rule per segment would give 0.215 h at a vertex)."""
    problem = ContactProblem(with_pair(scene, multiplier_degree="iso"), degree=2, verbose=False)
    c = problem.contacts[0]
    slave = c.slave
    assert slave.subdivisions == 2 and slave.num_points == 6
    space = c.lambda_N.function_space
    assert space.ufl_element().basix_element.family == basix.ElementFamily.iso
    assert c.friction is None
    nc = slave.num_cells
    x = slave.submesh.geometry.x[slave.submesh.geometry.dofmaps[0][:nc, :2], :2]
    length = np.linalg.norm(x[:, 1] - x[:, 0], axis=1)
    expected = dolfinx.fem.Function(space)
    np.add.at(expected.x.array, space.dofmap.list[:nc], length[:, None] * [0.25, 0.25, 0.5])
    expected.x.scatter_reverse(dolfinx.la.InsertMode.add)
    owned = space.dofmap.index_map.size_local
    assert np.allclose(slave.nodal_mass, expected.x.array[:owned], rtol=1e-12, atol=0.0)
    # as many nodes as the P2 trace: 2 per slave segment (+ 1 at the surface's end)
    nodes = space.dofmap.index_map.size_global
    segments = problem.comm.allreduce(nc)
    assert nodes == 2 * segments + 1


@pytest.mark.serial  # 2 ranks: the 3D variants (the same gathers)
def test_patch_iso_2d(verification):
    """P2 displacement, P1-iso-P2 multipliers, 2D: the force exact, the pressure uniform
    to 1.1e-3 with the composite rule of 8 subdivisions (P1 multipliers: 3.4e-4, each
    multiplier's support is half as long, so the master's kinks weigh twice as much), and
    the deviation falls with the rule (16 subdivisions: 1.4e-4, 0.13 times): a quadrature
    error, no instability."""
    deviations = []
    for subdivisions, bounds in ((8, "in (5e-4, 2e-3)"), (16, "< 0.25 times that on 8")):
        problem, deviation = solve_patch(2, "iso", 5, subdivisions)
        case = f"patch test 2D, P2, P1-iso-P2 multipliers, degree 5 rule on {subdivisions}"
        force = record_patch(verification, case, problem, deviation, bounds)
        assert force < 1e-12
        deviations.append(deviation)
    assert 5e-4 < deviations[0] < 2e-3
    assert deviations[1] < 0.25 * deviations[0]


@pytest.mark.slow
def test_patch_iso_3d(verification):
    """3D tetrahedra, P1-iso-P2 multipliers (rule of degree 4 x 2): the pressure uniform to
    4.9e-2 only (P1: 7.0e-3, P2: 5.0e-2); 4 subdivisions, 1.2e-2 (measured; 10 minutes on
    the shared machine, not run here)."""
    problem, deviation = solve_patch(3, "iso", 4, 2)
    case = "patch test 3D, P2 tetrahedra, P1-iso-P2 multipliers, degree 4 rule on 2"
    quantity = "largest |lambda_N / p - 1| over the nodes"
    verification(case, quantity, deviation, "lambda_N = p", "in (3e-2, 7e-2)", UNIFORM)
    force = abs(problem.contact_force()[2] / PRESSURE - 1.0)
    quantity = "|F_normal / (p A) - 1|"
    verification(case, quantity, force, 0.0, "< 1e-10", EQUILIBRIUM, kind="consistency")
    assert 3e-2 < deviation < 7e-2
    assert force < 1e-10


@pytest.mark.serial  # 2 ranks: the 3D variants (the same gathers)
@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_iso_2d(mu, verification):
    """P1-iso-P2 multipliers on the curved 2D pair (curved geometry), frictionless and in
    slip: the tangent exact (the multipliers enter the forms like any other)."""
    problem, dz, steps = curved_case(2, mu=mu, degree=2, order=2, multiplier_degree="iso")
    c = problem.contacts[0]
    assert c.lambda_N.function_space.ufl_element().basix_element.family == basix.ElementFamily.iso
    if mu > 0:
        assert problem.comm.allreduce(int(c.stick().sum())) == 0
    case = f"Taylor test 2D, P2, curved, P1-iso-P2 multipliers, mu = {mu:g}"
    check_taylor(problem, dz, steps, verification, case)


@pytest.mark.slow
@pytest.mark.parametrize(
    "cell, mu", [("tetrahedron", 0.0), ("tetrahedron", 0.05), ("hexahedron", 0.0)]
)
def test_taylor_iso_3d(cell, mu, verification):
    """P1-iso-P2 multipliers on 6-node triangles and 9-node quadrilaterals (basix's iso
    element on triangles and quadrilaterals), frictionless and in slip."""
    problem, dz, steps = curved_case(3, mu=mu, degree=2, cell=cell, multiplier_degree="iso")
    if mu > 0:
        assert problem.comm.allreduce(int(problem.contacts[0].stick().sum())) == 0
    case = f"Taylor test 3D, degree 2 {cell}, P1-iso-P2 multipliers, mu = {mu:g}"
    check_taylor(problem, dz, steps, verification, case)


@pytest.mark.slow
@pytest.mark.serial
def test_friction_iso_as_p1(verification):
    """The pushed block (stick, then slip) with a P2 displacement: P1-iso-P2 multipliers
    give the tangential force of P1 multipliers at every step (to 3e-4 of the normal one,
    1.5e-4 measured: a consistency check of two multiplier spaces), all points stuck in the
    first pushed steps and none in the last, the force ratio never above mu (the Coulomb
    law) and near it once no point sticks (0.94 mu; consistency)."""
    mu = 0.3
    ratios, sticks = {}, {}
    for degree in (1, "iso"):
        scene = scenes.pushed_block(mu=mu, push=0.03)
        problem = ContactProblem(
            with_pair(scene, multiplier_degree=degree), degree=2, verbose=False
        )
        c = problem.contacts[0]
        log = []

        def record(problem, step, c=c, log=log):
            active = c.active()
            stick = int((c.friction.last_stick & active).sum())
            log.append((abs(step.contact_force[0]) / step.contact_force[1], stick, active.sum()))

        problem.solve(num_steps=2, t_end=1.0, callback=record)
        problem.solve(num_steps=6, t_end=2.0, callback=record)
        ratios[degree] = np.array([r[0] for r in log])
        sticks[degree] = [(r[1], r[2]) for r in log]
    case = "pushed block, P2, P1-iso-P2 multipliers, mu = 0.3, stick then slip"
    excess = ratios["iso"].max() / mu - 1.0
    coulomb = "the Coulomb law: |F_T| <= mu F_N"
    verification(case, "largest |F_x / F_y| / mu - 1", excess, 0.0, "<= 1e-8", coulomb)
    difference = np.abs(ratios["iso"] - ratios[1]).max()
    quantity = "largest |F_x / F_y| difference from P1 multipliers over the steps"
    source = "the same scene with P1 multipliers"
    verification(case, quantity, difference, 0.0, "< 3e-4", source, kind="consistency")
    slip = ratios["iso"][-1] / mu
    quantity = "|F_x / F_y| / mu at the last step (no point sticks)"
    source = "|F_T| = mu F_N under full slip"
    verification(case, quantity, slip, 1.0, "> 0.9", source, kind="consistency")
    assert excess <= 1e-8
    assert difference < 3e-4
    assert slip > 0.9
    assert all(s == a > 0 for s, a in sticks["iso"][:4])
    assert sticks["iso"][-1][0] == 0 < sticks["iso"][-1][1]


def solve_hertz_2d(h, multiplier_degree, refine_radius=0.3, rigid_flat=False):
    """The 2D Hertz scene, P2 on the curved mesh, linear elastic, one step, the library's
    default eps: the error of the fitted p0 (nominal pressure at the reference positions)
    and the nodal multipliers over p0 against ``x / a`` (one per position). With
    ``rigid_flat`` the master is the rigid plane y = 0 instead of the block's top."""
    hertz = scenes.hertz_2d(h_contact=h, depth=0.005, order=2, refine_radius=refine_radius)
    changes = {"master": RigidPlane((0.0, 0.0), (0.0, 1.0))} if rigid_flat else {}
    scene = with_pair(hertz.scene, eps_N=None, multiplier_degree=multiplier_degree, **changes)
    E_star = hertz.E_star
    if rigid_flat:  # E* of an elastic disc on a rigid flat (Johnson 1985, 4.2)
        material = scene.bodies[0].material
        E_star = material.E / (1.0 - material.nu**2)
    scene.bodies = [
        dataclasses.replace(b, material=LinearElastic(b.material.E, b.material.nu))
        for b in scene.bodies
    ]
    problem = ContactProblem(scene, degree=2, verbose=False)
    problem.solve(num_steps=1)
    exact = Hertz2D(problem.contact_force()[1], hertz.radius, E_star)
    c = problem.contacts[0]
    X = np.concatenate(problem.comm.allgather(c.slave.X.reshape(-1, 2)))
    _, p0, _ = fit_elliptic_profile(X[:, 0], contact_samples(problem).lambda_N)
    x, lam = _nodal_profile(problem.comm, c.lambda_N)
    return p0 / exact.p0 - 1.0, x / exact.a, lam / exact.p0


@pytest.mark.slow
def test_hertz_iso_removes_the_edge_overshoot_but_zigzags(verification):
    """The evidence for keeping P1 multipliers as the default (docs/quadratic-contact.md):
    at h = 0.025 (a / h = 2.03, a slave vertex just inside the contact edge) the fitted p0
    of P1 multipliers overshoots by 6.8%, that of P1-iso-P2 by 0.95% (both bounds
    asserted); but the iso multipliers zig-zag between vertex and midpoint nodes: the
    nodal values inside 0.8 a are not concave (second differences up to 0.93 p0), the node
    at 0.73 a 0.33 p0 above Hertz (1.017 against 0.687; P1: its nodes within 16%)."""
    p0_p1, x1, lam1 = solve_hertz_2d(0.025, 1)
    p0_iso, x, lam = solve_hertz_2d(0.025, "iso")
    inside = (x >= 0.0) & (x < 0.8)
    assert len(x[inside]) == 2 * len(x1[(x1 >= 0.0) & (x1 < 0.8)])  # and the midpoints
    deviation = lam[inside] - np.sqrt(1.0 - x[inside] ** 2)
    zigzag = np.diff(lam[inside], 2).max()
    case = "Hertz 2D, P2 on the curved mesh, linear elastic, a/h = 2.03"
    p0 = "p0 = 2 P / (pi a)"
    for quantity, value, reference, tolerance in (
        ("relative error of p0, P1 multipliers", p0_p1, p0, "in (0.05, 0.09)"),
        ("relative error of p0, P1-iso-P2 multipliers", p0_iso, p0, "|error| < 0.02"),
        ("largest second difference of the iso nodal lambda_N / p0", zigzag, "< 0", "> 0.5"),
        ("largest iso nodal lambda_N / p0 above Hertz in 0.8 a", deviation.max(), 0.0, "> 0.2"),
    ):
        verification(case, quantity, value, reference, tolerance, JOHNSON)
    assert 0.05 < p0_p1 < 0.09
    assert abs(p0_iso) < 0.02
    assert zigzag > 0.5  # a zig-zag, not a concave profile
    assert deviation.max() > 0.2


@pytest.mark.parametrize("dim, cell", [(2, "triangle"), (3, "tetrahedron"), (3, "hexahedron")])
def test_iso_multiplier_at_points_is_that_of_the_forms(dim, cell):
    """The P1-iso-P2 multiplier at the slave points as NumPy evaluates it (the laws' point
    data) equals the one FFCx evaluates in the contact forms, on the curved slave facets of
    segments, 6-node triangles and 9-node quadrilaterals: the submesh cells and the
    parent facets number the refined cells alike, whatever their orientation."""
    scene = curved_pair(dim, cell=cell)
    pair = scene.contacts[0]
    domain = scene.parts[0]
    mesh = domain.mesh
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 2, (dim,)))
    slave = SlaveSurface(V, domain.surface_tags, pair.slave, 3, 1, "gauss", "iso")
    assert slave.subdivisions == 2
    lam = dolfinx.fem.Function(slave.multiplier_space)
    rng = np.random.default_rng(RNG_SEED)
    lam.x.array[:] = rng.uniform(1.0, 2.0, lam.x.array.size)
    lam.x.scatter_forward()
    Q = slave.point_space(())
    q = ufl.TestFunction(Q)
    entity_maps = [slave.entity_map]
    weighted = dolfinx.fem.assemble_vector(
        dolfinx.fem.form(lam * q * slave.ds, entity_maps=entity_maps)
    )
    weights = dolfinx.fem.assemble_vector(dolfinx.fem.form(q * slave.ds, entity_maps=entity_maps))
    owned = Q.dofmap.list[: slave.num_cells].ravel()
    in_forms = weighted.array[owned] / weights.array[owned]
    assert np.allclose(in_forms, slave.p1_at_points(lam), rtol=1e-12, atol=0.0)
    # the values differ between the halves of a facet (a check that could fail)
    per_cell = in_forms.reshape(slave.num_cells, slave.num_points)
    assert slave.num_cells == 0 or np.ptp(per_cell, axis=1).min() > 1e-3


@pytest.mark.slow
def test_hertz_iso_on_a_rigid_flat(verification):
    """Where the iso zig-zag comes from (docs/quadratic-contact.md): against a rigid flat
    (an exact master) at h = 0.0075 (a / h = 7) the iso nodes are within 1% of Hertz up to
    0.72 a (1.0% measured), against the meshed block 5.9% inside 0.8 a (both bounds
    asserted)."""
    _, x, lam = solve_hertz_2d(0.0075, "iso", rigid_flat=True)
    inside = (x >= 0.0) & (x < 0.75)
    assert inside.sum() >= 10
    flat = np.abs(lam[inside] - np.sqrt(1.0 - x[inside] ** 2)).max()
    _, x, lam = solve_hertz_2d(0.0075, "iso")
    inside = (x >= 0.0) & (x < 0.8)
    block = np.abs(lam[inside] - np.sqrt(1.0 - x[inside] ** 2)).max()
    profile = "p(x) = p0 sqrt(1 - x^2 / a^2)"
    for case, limit, value, tolerance in (
        ("on a RigidPlane", "0.75 a", flat, "< 0.015"),
        ("on the meshed block", "0.8 a", block, "> 0.04"),
    ):
        case = f"Hertz 2D {case}, P2, P1-iso-P2 multipliers, linear elastic, a/h = 7"
        quantity = f"largest nodal |lambda_N / p0 - Hertz| inside {limit}"
        verification(case, quantity, value, profile, tolerance, JOHNSON)
    assert flat < 0.015
    assert block > 0.04
