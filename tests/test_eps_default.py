"""The default augmentation eps_N = E / L (E of the softer body, L the slave surface's size):
a pair needs no eps_N, and the solution does not depend on it beyond the elements where the
contact zone ends."""

import dataclasses

import numpy as np
import pytest
from mpi4py import MPI

from contact_ufl.materials import LinearElastic
from contact_ufl.mpi import global_diameter
from contact_ufl.problem import ContactProblem
from contact_ufl.strategies import default_strategies
from contact_ufl.verification import scenes

INDEPENDENT = (
    "the augmented-Lagrangian solution does not depend on eps (Alart & Curnier 1991), "
    "up to the elements cut by the contact zone's edge"
)
SAME_EQUATIONS = "the same equations solved from another start (to solver tolerance)"


def solved(scene):
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=1)
    return problem


@pytest.mark.serial  # the default eps, not the partition
@pytest.mark.parametrize("E_flat", [1.0, 0.25])
def test_default_eps_is_softer_modulus_over_slave_size(E_flat):
    hertz = scenes.hertz_2d(h_contact=0.02, depth=0.02, E_flat=E_flat)
    scene = hertz.scene
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=None)
    problem = ContactProblem(scene, verbose=False)
    c = problem.contacts[0]
    L = global_diameter(problem.comm, c.slave.X.reshape(-1, 2))
    assert float(c.normal.eps_N.value) == pytest.approx(min(1.0, E_flat) / L, rel=1e-12)
    # the friction default follows: eps_T = eps_N
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], mu=0.3)
    c = ContactProblem(scene, verbose=False).contacts[0]
    assert float(c.friction.eps_T.value) == float(c.normal.eps_N.value)


@pytest.mark.serial  # a property of the equations, not of the partition
def test_default_eps_gives_the_same_solution(verification):
    """Hertz with eps_N = E/h (200 here) and with the default E/L (0.45): the contact force
    agrees to 1e-4 and the peak multiplier to 1e-6 (measured 6.5e-5 and 5.7e-7 at this mesh:
    the difference lives in the elements cut by the edge of the contact zone)."""
    explicit = solved(scenes.hertz_2d(h_contact=0.01, depth=0.02).scene)
    scene = scenes.hertz_2d(h_contact=0.01, depth=0.02).scene
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=None)
    default = solved(scene)
    assert float(default.contacts[0].normal.eps_N.value) < 1.0
    F0, F1 = explicit.contact_force()[1], default.contact_force()[1]
    peak = [
        p.comm.allreduce(p.contacts[0].multiplier_at_points().max(initial=0.0), op=MPI.MAX)
        for p in (explicit, default)
    ]
    case = "Hertz 2D, Neo-Hookean, one step, depth 0.02, h = 0.01, eps_N = E / L against E / h"
    for quantity, change, bound in (
        ("relative change of the contact force", F1 / F0 - 1.0, 1e-4),
        ("relative change of the peak multiplier", peak[1] / peak[0] - 1.0, 1e-6),
    ):
        verification(
            case, quantity, change, 0.0, f"|change| < {bound:g}", INDEPENDENT, kind="consistency"
        )
    assert np.isfinite(F1) and F1 > 0
    assert abs(F1 / F0 - 1.0) < 1e-4
    assert abs(peak[1] / peak[0] - 1.0) < 1e-6


def linear_hertz_scene(h_contact: float, eps_N: float | None = None):
    """The 2D Hertz scene with a linear elastic bulk and ``eps_N`` (``None``: the default)."""
    scene = scenes.hertz_2d(h_contact=h_contact, depth=0.02).scene
    scene.bodies = [
        dataclasses.replace(b, material=LinearElastic(b.material.E, b.material.nu))
        for b in scene.bodies
    ]
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=eps_N)
    return scene


def linear_hertz(h_contact: float, eps_N: float | None = None):
    """:func:`linear_hertz_scene` solved in one load step."""
    return solved(linear_hertz_scene(h_contact, eps_N))


@pytest.mark.serial
def test_newton_per_step_does_not_grow_under_refinement(verification):
    """2D Hertz (linear elastic, one load step) with the default eps on three meshes
    (a / h ~ 2.5, 5, 10, 3k to 26k unknowns): Newton needs 4, 4, 4 iterations (measured,
    with the first-contact predictor; 6, 9, 8 without; the scenes' eps = E / h needs 17,
    6, 7 (14 without on the coarsest): at a / h = 2.5 the full-step Newton cycles through
    0, 40, 16 active points until the line search takes over). The finest mesh needs no
    more than the coarsest, and every mesh at most 5 (the guide's bound is about 10). On
    the finest, 10 eps and eps / 10 give the default's contact force to 1e-5 and 1e-6
    (measured 3.4e-6 and 3.5e-7): the result does not depend on eps."""
    problems = [linear_hertz(h) for h in (0.02, 0.01, 0.005)]
    its = [max(s.newton_iterations for s in p.history.steps) for p in problems]
    assert all(len(p.history.cutbacks) == 0 for p in problems)
    assert max(its) <= 5, its
    assert its[-1] <= its[0], its
    finest = problems[-1]
    eps = float(finest.contacts[0].normal.eps_N.value)
    F = finest.contact_force()[1]
    case = "Hertz 2D, linear elastic, one step, depth 0.02, h = 0.005, eps_N = E / L"
    for factor, bound, name in ((10.0, 1e-5, "10 eps_N"), (0.1, 1e-6, "eps_N / 10")):
        other = linear_hertz(0.005, factor * eps)
        change = other.contact_force()[1] / F - 1.0
        quantity = f"relative change of the contact force with {name}"
        verification(
            case, quantity, change, 0.0, f"|change| < {bound:g}", INDEPENDENT, kind="consistency"
        )
        assert max(s.newton_iterations for s in other.history.steps) <= 10
        assert abs(change) < bound


def first_contact(dim: int, h_contact: float, level) -> ContactProblem:
    """Hertz (linear elastic in 2D, the default eps, one load step) with the solver's
    ``first_contact_level`` (``None``: no predictor iterate)."""
    if dim == 2:
        scene = linear_hertz_scene(h_contact)
    else:
        scene = scenes.hertz_3d(h_contact=h_contact, depth=0.01).scene
        scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=None)
    problem = ContactProblem(scene, verbose=False)
    problem.solver.strategies = default_strategies(first_contact_level=level)
    problem.solve(num_steps=1)
    return problem


def newton_and_force(problems: list[ContactProblem]) -> tuple[list[int], list[float]]:
    assert all(not p.history.cutbacks for p in problems)
    its = [p.history.steps[0].newton_iterations for p in problems]
    return its, [p.contact_force()[p.gdim - 1] for p in problems]


@pytest.mark.serial  # a property of the step, not of the partition
def test_first_contact_predictor_keeps_newton_flat(verification):
    """The first contact of a step from the open state: the free iterate overlaps the whole
    approach (3D Hertz: twice the contact area), and the semismooth Newton then releases
    the excess from the zone's edge inwards, about one more iterate each time the excess
    points double (5, 6, 9 iterations at a / h ~ 2, 4, 8). The predictor iterate (points in
    contact where the free iterate overlaps by more than its mean overlap, half the deepest
    over an elliptic region: the zone of a Hertz contact of paraboloids) starts Newton from
    about the right zone: 4, 4, 5 iterations (measured), never more than without it, the
    same solution to solver tolerance."""
    meshes = (0.05, 0.025, 0.0125)
    its, force = newton_and_force([first_contact(3, h, "mean") for h in meshes])
    its_without, force_without = newton_and_force([first_contact(3, h, None) for h in meshes])
    assert max(its) <= 5 and its[-1] <= its[0] + 1, its
    assert all(a <= b for a, b in zip(its, its_without, strict=True)), (its, its_without)
    assert its[-1] < its_without[-1], (its, its_without)
    changes = [a / b - 1.0 for a, b in zip(force, force_without, strict=True)]
    case = "Hertz 3D, linear elastic, one step, h = 0.05, 0.025, 0.0125, first-contact predictor"
    quantity = "relative change of the contact force against no predictor"
    tolerance = "|change| < 1e-8"
    verification(case, quantity, changes, 0.0, tolerance, SAME_EQUATIONS, kind="consistency")
    # two solves converged to SNES's rtol (1e-9) from other starts: 2.8e-10 measured
    assert max(abs(c) for c in changes) < 1e-8, changes


@pytest.mark.serial  # a property of the step, not of the partition
def test_first_contact_level_of_a_line_contact(verification):
    """2D Hertz (a line contact): the zone's edge lies at two thirds of the free iterate's
    deepest overlap here, which is the mean overlap of a parabolic strip; half the deepest
    (right for a point contact) overestimates the zone (228 points for 184 at a / h = 20)
    and Newton releases the excess over more iterates. Measured at a / h = 5 and 10: 4, 4
    with the mean, 6, 6 with half the deepest, 9, 8 without a predictor; the same force to
    1e-8."""
    meshes = (0.01, 0.005)
    its, force = newton_and_force([first_contact(2, h, "mean") for h in meshes])
    its_half, force_half = newton_and_force([first_contact(2, h, 0.5) for h in meshes])
    its_without, force_without = newton_and_force([first_contact(2, h, None) for h in meshes])
    assert max(its) <= 4, its
    assert all(a < b < c for a, b, c in zip(its, its_half, its_without, strict=True)), (
        its,
        its_half,
        its_without,
    )
    changes = [
        [a / c - 1.0 for a, c in zip(force, force_without, strict=True)],
        [b / c - 1.0 for b, c in zip(force_half, force_without, strict=True)],
    ]
    case = "Hertz 2D, linear elastic, one step, h = 0.01, 0.005, first-contact predictor"
    tolerance = "|change| < 1e-8"
    for level, change in zip(("the mean", "half the deepest"), changes, strict=True):
        quantity = f"relative change of the contact force, level {level}, against none"
        verification(case, quantity, change, 0.0, tolerance, SAME_EQUATIONS, kind="consistency")
    # two solves converged to SNES's rtol (1e-9) from other starts: 1.7e-10 measured
    assert np.abs(changes).max() < 1e-8, changes


def test_first_contact_level_is_checked():
    for level in ("median", 1.5, 0.0):
        with pytest.raises(ValueError, match="first_contact_level must be 'mean'"):
            default_strategies(first_contact_level=level)
