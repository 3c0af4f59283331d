"""Follower loads: a slender cantilever under a follower and a dead tip force against the
elastica, a block under follower pressure against the homogeneous Neo-Hookean solution,
resultants in a rotated configuration, and the consistency of the tangent (load stiffness)."""

import dolfinx
import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from conftest import symmetric_square, tagged_unit_square
from mpi4py import MPI

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
    ELASTICA_DEAD_TIP,
    ELASTICA_FOLLOWER_TIP,
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
REL_TOL = 0.02
MAX_NEWTON = 6


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


def test_elastica_tables():
    """The tabulated tip displacements are those of the elastica integrated here."""
    for table, follower in ((ELASTICA_FOLLOWER_TIP, True), (ELASTICA_DEAD_TIP, False)):
        for k, uv in table.items():
            assert cantilever_elastica(k, follower)[:2] == pytest.approx(uv, abs=1e-5)


@pytest.mark.parametrize("k", [1.0, 2.0])
def test_follower_tip_force(follower_beam, k):
    """Tip displacement under a follower force (perpendicular to the deformed axis)."""
    problem, _, tips, _ = follower_beam
    assert tips[k] == pytest.approx(ELASTICA_FOLLOWER_TIP[k], rel=REL_TOL)


def test_follower_newton(follower_beam):
    """Few Newton iterations per step and quadratic convergence: the tangent contains the
    (non-symmetric) load stiffness."""
    problem, _, _, residuals = follower_beam
    history = problem.history
    assert len(history.steps) == 20 and not history.cutbacks
    assert max(s.newton_iterations for s in history.steps) <= MAX_NEWTON
    assert newton_order(residuals) > 1.5


def test_follower_reaction(follower_beam):
    """The clamp holds the force at its final direction, perpendicular to the tip at
    the elastica's tip rotation theta_L: reaction ``P (-sin theta_L, cos theta_L)``."""
    problem, P, _, _ = follower_beam
    theta = cantilever_elastica(2.0, follower=True)[2]
    expected = P * np.array([-np.sin(theta), np.cos(theta)])
    assert problem.reaction(CLAMP) == pytest.approx(expected, abs=REL_TOL * P)


def test_follower_tangent_taylor(follower_beam):
    """Taylor test of the whole Jacobian at the deformed beam: the remainder falls as h^2."""
    problem, _, _, _ = follower_beam
    du = dolfinx.fem.Function(problem.V)
    du.interpolate(lambda x: smooth_field(x, 0.01, 2))
    direction = problem.solver.x.duplicate()
    dolfinx.fem.petsc.assign([du], direction)
    # steps small enough for a missing load stiffness to show (slope -> 1 from h ~ 1e-3)
    result = taylor_test(problem, direction, [1e-3 * 2.0**-j for j in range(4)])
    assert np.all(result.slopes > 1.9), result.slopes


def test_dead_tip_force():
    """The same resultant fixed in -y (a dead traction P / H): Bisshopp & Drucker."""
    k = 1.0
    P = k * EI / L**2
    scene = cantilever_scene(DeadTraction(TIP, lambda t: (0.0, -P * t / H)))
    problem = ContactProblem(scene, degree=2, verbose=False)
    problem.solve(num_steps=10)
    tip = point_displacement(problem, (L, 0.0)) / L
    assert tip == pytest.approx(ELASTICA_DEAD_TIP[k], rel=REL_TOL)
    assert max(s.newton_iterations for s in problem.history.steps) <= MAX_NEWTON
    # the follower force of the same magnitude bends the beam further
    assert abs(tip[1]) < abs(ELASTICA_FOLLOWER_TIP[k][1]) * (1.0 - 2.0 * REL_TOL)


def unit_square(n: int = 2):
    """The unit square of quadrilaterals; sides left 1, right 2, bottom 3, top 4."""
    return tagged_unit_square(n, dolfinx.mesh.CellType.quadrilateral)


@pytest.mark.parametrize("follower", [True, False])
def test_pressure_homogeneous_compression(follower):
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
    assert stretch == pytest.approx([expected, expected], rel=1e-9)
    other = neo_hookean_pressure_stretch(material.mu, material.lmbda, p, not follower)
    assert abs(expected - other) > 0.01  # the J F^-T factor matters at this pressure
    assert max(s.newton_iterations for s in problem.history.steps) <= MAX_NEWTON


def test_resultants_rotated():
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
        (FollowerPressure(2, p), -p * stretch * R @ [1.0, 0.0]),
        (FollowerForce(2, P, tuple(d0)), P * R @ d0),
        (DeadTraction(2, (-p, 0.0)), np.array([-p, 0.0])),
    ]
    for load, expected in cases:
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
        assert resultant == pytest.approx(expected, abs=1e-12), type(load).__name__


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
