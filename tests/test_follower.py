"""Follower loads: a slender cantilever under a follower and a dead tip force against the
elastica in closed form (itself checked against a separate numerical solution), a block
under follower pressure against the homogeneous Neo-Hookean solution, resultants in a
rotated configuration, and the consistency of the tangent (load stiffness)."""

import dolfinx
import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from conftest import symmetric_square, tagged_unit_square
from mpi4py import MPI
from scipy.integrate import solve_bvp

from contact_ufl.errors import ContactInputError
from contact_ufl.loads import (
    DeadTraction,
    Dirichlet,
    FollowerForce,
    FollowerPressure,
    load_constant,
)
from contact_ufl.materials import NeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Scene
from contact_ufl.taylor import taylor_test
from contact_ufl.verification.analytic import (
    bending_stiffness_plane_strain,
    cantilever_elastica,
    neo_hookean_pressure_stretch,
)
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.taylor_cases import smooth_field

# the cantilever: L / h = 40, Q2 quadrilaterals 80 x 2 (square cells, the node (L, 0) on the
# mid-line), Neo-Hookean with nu = 0 (plane strain E' = E)
L, H, NX, NY = 1.0, 0.025, 80, 2
E, NU = 1.0, 0.0
EI = bending_stiffness_plane_strain(E, NU, H)
CLAMP, TIP = 1, 2
#: Newton iterations per load step (4 measured; a tangent without the load stiffness
#: converges linearly and takes many more)
MAX_NEWTON = 6
#: closed form against collocation (measured 2.4e-13 at most)
ELASTICA_BVP_TOL = 5e-13
#: the closed form at small load against linear beam theory: the O(k^2) large-deflection
#: terms (measured 1.1e-5 at k = 0.01)
LINEAR_TOL = 2e-5
#: relative error of each tip displacement component against the elastica, follower
#: (measured 9.1e-4) and dead (4.2e-4) force: the continuum beam's shear and stretch,
#: O((h/L)^2), and the mesh
FOLLOWER_TOL, DEAD_TOL = 2e-3, 1e-3
#: the clamp reaction: magnitude against P, to the Newton tolerance (measured 1.0e-8), and
#: the tip rotation of its direction against the elastica's (measured 2.2e-4)
REACTION_TOL, ROTATION_TOL = 3e-8, 5e-4
#: homogeneous stretch under pressure, to the Newton tolerance (measured 1.2e-12)
PRESSURE_TOL = 3e-12
#: load resultants at a given deformation, to round-off (measured 1.1e-16)
RESULTANT_TOL = 5e-16
#: Taylor slopes of the tangent at the deformed beam: |slope - 2| (measured 1.7e-4)
TAYLOR_TOL = 5e-4

ELASTICA = "the Euler elastica in closed form (elliptic integrals, cantilever_elastica)"
FOLLOWER_CASE = "cantilever L/h = 40 under a follower tip force, Q2 80 x 2"
DEAD_CASE = "cantilever L/h = 40 under a dead tip force, Q2 80 x 2"


def elastica_bvp(k: float, follower: bool) -> np.ndarray:
    """The elastica's tip ``(u/L, v/L, theta_L)`` by ``scipy.integrate.solve_bvp``: a
    computation apart from the closed form. The moment of the tip force about the point at
    ``s`` gives the curvature, ``theta' = -k ((x_L - x) cos b + (y_L - y) sin b)`` with the
    force ``P (sin b, -cos b)`` (``b = theta_L``, follower; ``b = 0``, dead), ``x' = cos
    theta``, ``y' = sin theta``; the unknown tip ``(theta_L, x_L, y_L)`` are parameters,
    closed by the clamp at ``s = 0`` and the tip's values at ``s = 1``."""

    def rhs(s, z, p):
        theta, x, y = z
        b = p[0] if follower else 0.0
        curvature = -k * ((p[1] - x) * np.cos(b) + (p[2] - y) * np.sin(b))
        return np.vstack([curvature, np.cos(theta), np.sin(theta)])

    def bc(z0, z1, p):
        return np.array([z0[0], z0[1], z0[2], z1[0] - p[0], z1[1] - p[1], z1[2] - p[2]])

    s = np.linspace(0.0, 1.0, 41)
    guess = np.vstack([-k * (s - s**2 / 2), s, -k * (s**2 / 2 - s**3 / 6)])  # linear beam
    solution = solve_bvp(rhs, bc, s, guess, p=[-k / 2, 1.0, -k / 3], tol=1e-10, max_nodes=100000)
    assert solution.success, solution.message
    theta_L, x_L, y_L = solution.p
    return np.array([x_L - 1.0, y_L, theta_L])


def cantilever_scene(load) -> Scene:
    """The beam ``[0, L] x [-H/2, H/2]`` clamped at x = 0 (tag 1), ``load`` on x = L (tag 2)."""
    mesh = dolfinx.mesh.create_rectangle(
        MPI.COMM_WORLD,
        [np.array([0.0, -H / 2]), np.array([L, H / 2])],
        [NX, NY],
        dolfinx.mesh.CellType.quadrilateral,
    )
    cells, facets = tag_single_body(
        mesh, [lambda x: np.isclose(x[0], 0.0), lambda x: np.isclose(x[0], L)]
    )
    return Scene(
        mesh,
        cells,
        facets,
        [Body(1, NeoHookean(E, NU), "beam")],
        dirichlet=[Dirichlet(CLAMP, (0.0, 0.0))],
        loads=[load],
    )


def point_displacement(problem: ContactProblem, point) -> np.ndarray:
    """Displacement at a node of ``problem.V`` (owned by one rank), on every rank."""
    owned = problem.V.dofmap.index_map.size_local
    x = problem.V.tabulate_dof_coordinates()[:owned, : len(point)]
    hit = np.all(np.isclose(x, point, atol=1e-10), axis=1)
    u = problem.u.x.array.reshape(-1, len(point))[:owned]
    count = problem.comm.allreduce(int(hit.sum()), MPI.SUM)
    assert count == 1, f"the point {point} is {count} owned nodes"
    return problem.comm.allreduce(u[hit].sum(axis=0), MPI.SUM)


def newton_order(residuals: np.ndarray) -> float:
    """Observed order of the last Newton iteration, ``log(r3/r2) / log(r2/r1)``."""
    r1, r2, r3 = residuals[-3:]
    return float(np.log(r3 / r2) / np.log(r2 / r1))


@pytest.fixture(scope="module")
def follower_beam():
    """The cantilever under a follower tip force up to P L^2 / EI = 2, in 2 x 10 steps; the
    tip displacement at P L^2 / EI = 1 and 2, Newton residuals of the last step."""
    k_max = 2.0
    P = k_max * EI / L**2
    scene = cantilever_scene(FollowerForce(TIP, lambda t: P * t, (0.0, -1.0)))
    problem = ContactProblem(scene, degree=2, verbose=False)
    tips = {}
    problem.solve(num_steps=10, t_end=0.5)
    tips[1.0] = point_displacement(problem, (L, 0.0)) / L
    problem.solver.snes.setConvergenceHistory(length=100, reset=True)
    problem.solve(num_steps=10, t_end=1.0)
    tips[2.0] = point_displacement(problem, (L, 0.0)) / L
    residuals = problem.solver.snes.getConvergenceHistory()[0]
    return problem, P, tips, residuals


@pytest.mark.parametrize("k", [0.5, 1.0, 2.0, 5.0, 10.0])
@pytest.mark.parametrize("follower", [True, False], ids=["follower", "dead"])
def test_elastica_closed_form(k, follower, verification):
    """The closed form of the elastica (elliptic integrals) equals the boundary value
    problem solved by collocation, up to tip rotations of 171 degrees."""
    closed = np.array(cantilever_elastica(k, follower))
    difference = np.abs(closed - elastica_bvp(k, follower)).max()
    load = "follower" if follower else "dead"
    verification(
        f"Euler elastica of a cantilever, {load} tip force, P L^2 / EI = {k:g}",
        "max |closed form - collocation| of (u/L, v/L, theta_L)",
        difference,
        "scipy.integrate.solve_bvp of the moment-arm form",
        f"< {ELASTICA_BVP_TOL:g}",
        "a separate numerical solution of the elastica (scipy collocation, tol 1e-10)",
    )
    assert difference < ELASTICA_BVP_TOL


@pytest.mark.parametrize("follower", [True, False], ids=["follower", "dead"])
def test_elastica_small_load(follower, verification):
    """At P L^2 / EI = 0.01 the closed form is linear beam theory's tip deflection ``P L^3 /
    (3 EI)`` and rotation ``P L^2 / (2 EI)`` up to the large-deflection terms, O(k^2)."""
    k = 0.01
    _, v, theta = cantilever_elastica(k, follower)
    errors = np.abs([v / (-k / 3.0) - 1.0, theta / (-k / 2.0) - 1.0])
    load = "follower" if follower else "dead"
    verification(
        f"Euler elastica of a cantilever, {load} tip force, P L^2 / EI = 0.01",
        "relative difference of (v/L, theta_L) from linear beam theory",
        errors,
        [-k / 3.0, -k / 2.0],
        f"< {LINEAR_TOL:g}",
        "Euler-Bernoulli beam theory: v = -P L^3 / (3 EI), theta = -P L^2 / (2 EI)",
    )
    assert np.all(errors < LINEAR_TOL), errors


def tip_errors(tip: np.ndarray, k: float, follower: bool) -> np.ndarray:
    """Relative errors of the tip displacement ``(u/L, v/L)`` against the elastica."""
    reference = np.array(cantilever_elastica(k, follower)[:2])
    return np.abs(tip / reference - 1.0)


@pytest.mark.parametrize("k", [1.0, 2.0])
def test_follower_tip_force(follower_beam, k, verification):
    """Tip displacement under a follower force (perpendicular to the deformed axis) against
    the elastica, to FOLLOWER_TOL in each component."""
    problem, _, tips, _ = follower_beam
    errors = tip_errors(tips[k], k, True)
    verification(
        f"{FOLLOWER_CASE}, P L^2 / EI = {k:g}",
        "relative error of the tip displacement (u, v)",
        errors,
        np.array(cantilever_elastica(k, True)[:2]),
        f"< {FOLLOWER_TOL:g}",
        ELASTICA,
    )
    assert np.all(errors < FOLLOWER_TOL), errors


def test_follower_newton(follower_beam, verification):
    """Few Newton iterations per step and quadratic convergence: the tangent contains the
    (non-symmetric) load stiffness."""
    problem, _, _, residuals = follower_beam
    history = problem.history
    assert len(history.steps) == 20 and not history.cutbacks
    assert max(s.newton_iterations for s in history.steps) <= MAX_NEWTON
    order = newton_order(residuals)
    verification(
        f"{FOLLOWER_CASE}, P L^2 / EI = 2",
        "observed order of the last Newton iteration",
        order,
        2.0,
        "> 1.5",
        "Newton's quadratic convergence with the exact tangent",
    )
    assert order > 1.5


def test_follower_reaction(follower_beam, verification):
    """The clamp holds the force at its final direction, perpendicular to the tip at the
    tip rotation theta_L: the reaction ``P (-sin theta_L, cos theta_L)``. Its magnitude is
    the applied force (equilibrium, a consistency check); its direction is the tip rotation,
    against the elastica's."""
    problem, P, _, _ = follower_beam
    theta = cantilever_elastica(2.0, follower=True)[2]
    reaction = problem.reaction(CLAMP)
    magnitude = abs(np.linalg.norm(reaction) / P - 1.0)
    angle = np.arctan2(-reaction[0], reaction[1])
    case = f"{FOLLOWER_CASE}, P L^2 / EI = 2"
    verification(
        case,
        "| |clamp reaction| / P - 1 |",
        magnitude,
        0.0,
        f"< {REACTION_TOL:g}",
        "equilibrium of the converged solve",
        kind="consistency",
    )
    verification(
        case,
        "relative error of the tip rotation from the reaction's direction",
        abs(angle / theta - 1.0),
        theta,
        f"< {ROTATION_TOL:g}",
        ELASTICA,
    )
    assert magnitude < REACTION_TOL
    assert abs(angle / theta - 1.0) < ROTATION_TOL


def test_follower_tangent_taylor(follower_beam, verification):
    """Taylor test of the whole Jacobian at the deformed beam: the remainder falls as h^2."""
    problem, _, _, _ = follower_beam
    du = dolfinx.fem.Function(problem.V)
    du.interpolate(lambda x: smooth_field(x, 0.01, 2))
    direction = problem.solver.x.duplicate()
    dolfinx.fem.petsc.assign([du], direction)
    # steps small enough for a missing load stiffness to show (slope -> 1 from h ~ 1e-3)
    result = taylor_test(problem, direction, [1e-3 * 2.0**-j for j in range(4)])
    verification(
        f"{FOLLOWER_CASE}, P L^2 / EI = 2",
        "Taylor slopes of the residual's remainder",
        result.slopes,
        2.0,
        f"|slope - 2| < {TAYLOR_TOL:g}",
        "Taylor test: the remainder of an exact tangent falls as h^2",
    )
    assert np.all(np.abs(result.slopes - 2.0) < TAYLOR_TOL), result.slopes


def test_dead_tip_force(verification):
    """The same resultant fixed in -y (a dead traction P / H): Bisshopp & Drucker's
    elastica; the follower force of the same magnitude bends the beam further."""
    k = 1.0
    P = k * EI / L**2
    scene = cantilever_scene(DeadTraction(TIP, lambda t: (0.0, -P * t / H)))
    problem = ContactProblem(scene, degree=2, verbose=False)
    problem.solve(num_steps=10)
    tip = point_displacement(problem, (L, 0.0)) / L
    errors = tip_errors(tip, k, False)
    verification(
        f"{DEAD_CASE}, P L^2 / EI = 1",
        "relative error of the tip displacement (u, v)",
        errors,
        np.array(cantilever_elastica(k, False)[:2]),
        f"< {DEAD_TOL:g}",
        ELASTICA,
    )
    assert np.all(errors < DEAD_TOL), errors
    assert max(s.newton_iterations for s in problem.history.steps) <= MAX_NEWTON
    follower_v = cantilever_elastica(k, True)[1]
    assert abs(tip[1]) < abs(follower_v) * (1.0 - 2.0 * DEAD_TOL)


def unit_square(n: int = 2):
    """The unit square of quadrilaterals; sides left 1, right 2, bottom 3, top 4."""
    return tagged_unit_square(n, dolfinx.mesh.CellType.quadrilateral)


@pytest.mark.parametrize("follower", [True, False])
def test_pressure_homogeneous_compression(follower, verification):
    """A pressure p on all sides (symmetry on the left and bottom sides): ``F = l I`` with
    ``P_11(l, l) = -p l`` for the follower pressure (``-p J F^-T N = -p l N``) and ``-p``
    for a dead traction of the same reference value."""
    material = NeoHookean(1.0, 0.3)
    p = 0.25
    if follower:
        loads = [FollowerPressure(tag, lambda t: p * t) for tag in (2, 4)]
    else:
        loads = [DeadTraction(2, lambda t: (-p * t, 0.0)), DeadTraction(4, lambda t: (0.0, -p * t))]
    scene = symmetric_square(material, loads, n=2, cell_type=dolfinx.mesh.CellType.quadrilateral)
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=4)
    stretch = 1.0 + point_displacement(problem, (1.0, 1.0))
    expected = neo_hookean_pressure_stretch(material.mu, material.lmbda, p, follower)
    error = np.abs(stretch / expected - 1.0)
    load = "follower pressure" if follower else "dead traction"
    verification(
        f"Neo-Hookean square under a {load} p = 0.25 mu on all sides",
        "relative error of the stretches (l1, l2)",
        error,
        expected,
        f"< {PRESSURE_TOL:g}",
        "closed form of the homogeneous plane-strain Neo-Hookean stretch",
    )
    assert np.all(error < PRESSURE_TOL), error
    other = neo_hookean_pressure_stretch(material.mu, material.lmbda, p, not follower)
    assert abs(expected - other) > 0.01  # the J F^-T factor matters at this pressure
    assert max(s.newton_iterations for s in problem.history.steps) <= MAX_NEWTON


def test_resultants_rotated(verification):
    """At ``F = l R`` (stretch l, rotation a), the resultants on the right side (N = (1, 0),
    unit reference length): follower pressure ``-p l R N``, follower force ``P R d0``, dead
    traction unchanged."""
    mesh, _, facets = unit_square()
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (2,)))
    u = dolfinx.fem.Function(V)
    stretch, angle = 0.9, 0.6
    R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    u.interpolate(lambda x: (stretch * R - np.eye(2)) @ x[:2])
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facets)
    p, P, d0 = 0.3, 0.7, np.array([0.0, -1.0])
    cases = [
        (FollowerPressure(2, p), -p * stretch * R @ [1.0, 0.0], "Nanson's formula, -p cof(F) N"),
        (FollowerForce(2, P, tuple(d0)), P * R @ d0, "the direction F d0 / |F d0|"),
        (DeadTraction(2, (-p, 0.0)), np.array([-p, 0.0]), "the dead traction's definition"),
    ]
    for load, expected, source in cases:
        constant = load_constant(mesh, load)
        constant.value = load.value
        resultant = [
            mesh.comm.allreduce(
                dolfinx.fem.assemble_scalar(
                    dolfinx.fem.form(load.virtual_work(u, ufl.unit_vector(i, 2), ds, constant))
                ),
                MPI.SUM,
            )
            for i in range(2)
        ]
        error = np.abs(np.array(resultant) - expected).max()
        verification(
            f"{type(load).__name__} on a unit side at stretch 0.9 and rotation 0.6",
            "max |resultant - closed form|",
            error,
            expected,
            f"< {RESULTANT_TOL:g}",
            f"closed form: {source}",
        )
        assert error < RESULTANT_TOL, type(load).__name__


@pytest.mark.parametrize(
    "load, message",
    [
        (FollowerPressure(99, 1.0), "FollowerPressure: facet tag 99 does not exist"),
        (FollowerForce(98, 1.0, (0.0, -1.0)), "FollowerForce: facet tag 98 does not exist"),
        (FollowerPressure(2, (1.0, 0.0)), "the value is a scalar magnitude"),
        (FollowerForce(2, 1.0, (0.0, 0.0)), "direction must be a nonzero vector of dimension 2"),
        (FollowerForce(2, 1.0, (0.0, 0.0, 1.0)), "direction must be a nonzero vector"),
    ],
)
def test_bad_follower_loads(load, message):
    mesh, cells, facets = unit_square()
    scene = Scene(mesh, cells, facets, [Body(1, NeoHookean(1.0, 0.3))], loads=[load])
    with pytest.raises(ContactInputError, match=message):
        scene.validate()
