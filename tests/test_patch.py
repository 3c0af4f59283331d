"""Contact patch test: uniform pressure through a flat non-matching interface."""

import dataclasses

import numpy as np
import pytest
from mpi4py import MPI

from contact_ufl.problem import ContactProblem
from contact_ufl.results import body_resultants
from contact_ufl.verification.scenes import patch

PRESSURE = 0.01
TIGHT = {"snes_rtol": 1e-13, "snes_atol": 1e-15}
UNIFORM = "the applied pressure: the patch test's exact solution is uniform"
EQUILIBRIUM = "the equilibrium of a converged solve: the P1 test functions sum to one"
ACTION = "action = reaction: the master shape functions sum to one"


def deviation(problem):
    """The largest |lambda_N / p - 1| over the multiplier nodes of all ranks."""
    lam = problem.contacts[0].lambda_N.x.array
    local = float(np.abs(lam / PRESSURE - 1.0).max(initial=0.0))
    return problem.comm.allreduce(local, op=MPI.MAX)


def record_pressure(verification, case, error, tolerance):
    """Record the largest relative deviation of the multiplier from the applied pressure."""
    quantity = "largest |lambda_N / p - 1|"
    verification(case, quantity, error, "lambda_N = p", tolerance, UNIFORM)


def record_action_reaction(verification, case, slave, master):
    """Record |slave + master| / |slave| of the contact resultants on the two bodies."""
    ratio = np.linalg.norm(slave + master) / np.linalg.norm(slave)
    quantity = "|F_slave + F_master| / |F_slave|"
    verification(case, quantity, ratio, 0.0, "< 1e-14", ACTION, kind="consistency")


def solve_patch(degree, subdivisions, dim=2, cell=None):
    scene = patch(dim, PRESSURE, quadrature_degree=degree, subdivisions=subdivisions, cell=cell)
    problem = ContactProblem(scene, verbose=False, petsc_options=TIGHT)
    problem.solve(num_steps=1)
    return problem


PATCH_2D = "patch test 2D, 2-point Gauss rule on 8 sub-segments"


@pytest.fixture(scope="module")
def composite():
    """Two-point Gauss rule repeated on 8 sub-segments of every slave facet."""
    return solve_patch(3, 8)


def test_patch_pressure_uniform(composite, verification):
    error = deviation(composite)
    record_pressure(verification, PATCH_2D, error, "< 1e-3")
    assert error < 1e-3


def test_patch_total_force_exact(composite, verification):
    """The contact force balances the applied load (width 1) to round-off. This holds by
    construction (the equilibrium of any converged solve: the P1 test functions sum to
    one), so it checks the post-processing, not the pressure; test_patch_pressure_uniform
    is the verification.

    Its tangential part is not zero to round-off: the master surface tilts by the small
    residual waviness of the non-matching interface (held by the supports of the sides),
    by 1e-7 of the normal force (4.6e-8 measured).
    """
    force = composite.contact_force()
    normal, tangential = abs(force[1] / PRESSURE - 1.0), abs(force[0]) / PRESSURE
    kind = "consistency"
    verification(PATCH_2D, "|F_y / (p w) - 1|", normal, 0.0, "< 1e-12", EQUILIBRIUM, kind=kind)
    verification(PATCH_2D, "|F_x| / (p w)", tangential, 0.0, "< 1e-7", EQUILIBRIUM, kind=kind)
    assert abs(force[1] / PRESSURE - 1.0) < 1e-12
    assert abs(force[0]) < 1e-7 * PRESSURE


def test_patch_action_reaction(composite, verification):
    """(e): the contact forces on the two bodies are opposite to round-off. This holds by
    construction (the master virtual displacement is interpolated with shape functions
    that sum to one), whatever the solution: not a verification of it."""
    resultants = body_resultants(composite, composite.contact_residual())
    slave, master = (resultants[b.tag] for b in composite.scene.bodies)
    record_action_reaction(verification, PATCH_2D, slave, master)
    assert np.linalg.norm(slave) > 0.5 * PRESSURE
    assert np.linalg.norm(slave + master) < 1e-14 * np.linalg.norm(slave)


def test_patch_one_gauss_rule_is_not_enough(verification):
    """A single 2-point rule per facet misses the master kinks: the error is visible."""
    problem = solve_patch(3, 1)
    error = deviation(problem)
    case = "patch test 2D, one 2-point Gauss rule per facet (expected to fail it)"
    record_pressure(verification, case, error, "> 1e-2")
    assert error > 1e-2


@pytest.mark.parametrize(
    "cell, degree, subdivisions, tolerance",
    [
        ("tetrahedron", 2, 4, 1e-2),  # triangle master facets
        ("hexahedron", 3, 2, 3e-2),  # bilinear quadrilateral master facets
    ],
)
def test_patch_3d(cell, degree, subdivisions, tolerance, verification):
    """The pressure within ``tolerance`` in 3D; the total force and action equals reaction
    hold by construction (see the 2D tests)."""
    problem = solve_patch(degree, subdivisions, dim=3, cell=cell)
    error = deviation(problem)
    case = f"patch test 3D, {cell}, degree {degree} rule on {subdivisions} sub-facets"
    record_pressure(verification, case, error, f"< {tolerance:g}")
    assert error < tolerance
    force = problem.contact_force()
    normal = abs(force[2] / PRESSURE - 1.0)
    quantity = "|F_z / (p A) - 1|"
    verification(case, quantity, normal, 0.0, "< 1e-12", EQUILIBRIUM, kind="consistency")
    assert abs(force[2] / PRESSURE - 1.0) < 1e-12
    resultants = body_resultants(problem, problem.contact_residual())
    slave, master = (resultants[b.tag] for b in problem.scene.bodies)
    record_action_reaction(verification, case, slave, master)
    assert np.linalg.norm(slave + master) < 1e-14 * np.linalg.norm(slave)


def test_patch_lobatto_rule(verification):
    """The Gauss-Lobatto rule (points on the slave vertices, as the beams use it) passes
    the patch test and transfers the load exactly. The end points of the slave surface lie
    on the ends of the master surface (same widths): within round-off they stay paired."""
    scene = patch(2, PRESSURE, quadrature_degree=3, subdivisions=4)
    pair = dataclasses.replace(scene.contacts[0], quadrature_rule="lobatto")
    problem = ContactProblem(
        dataclasses.replace(scene, contacts=[pair]), verbose=False, petsc_options=TIGHT
    )
    c = problem.contacts[0]
    assert np.any(np.isin(c.slave.points_ref, [0.0, 1.0]))  # the vertices are points
    problem.solve(num_steps=1)
    assert problem.history.steps[0].newton_iterations <= 4
    assert problem.active_points() == problem.comm.allreduce(c.slave.X.size // 2)
    error = deviation(problem)
    case = "patch test 2D, Gauss-Lobatto rule on 4 sub-segments"
    record_pressure(verification, case, error, "< 5e-3")
    normal = abs(problem.contact_force()[1] / PRESSURE - 1.0)
    quantity = "|F_y / (p w) - 1|"
    verification(case, quantity, normal, 0.0, "< 1e-12", EQUILIBRIUM, kind="consistency")
    assert error < 5e-3
    assert abs(problem.contact_force()[1] / PRESSURE - 1.0) < 1e-12
