"""Properties (c) and (e) of the formulation, and independence of the number of ranks."""

import numpy as np
import pytest
from conftest import across_ranks, solve_hertz
from mpi4py import MPI

from contact_ufl.results import body_resultants, contact_samples, traction_mismatch

HERTZ = "Hertz 2D, Neo-Hookean, a/h = 10"
RANKS = "the same scene solved on one rank"


@pytest.mark.serial  # 2 ranks: test_same_result_on_any_number_of_ranks
def test_multipliers_are_the_tractions(hertz_sequence, verification):
    """(c): lambda_N nu equals the bulk traction Pi N on the slave surface, up to the error
    of Pi N: 0.31, 0.22, 0.12 at a/h = 2.5, 5, 10 (bound 0.15 at a/h = 10).

    The distance is large because it measures the traction of the P1 displacement, a
    cell-wise constant stress: a first-order error, largest in the cells next to the contact
    edges (the pressure's slope is infinite there), where the multiplier is close to Hertz's
    pressure. It falls with h (a degree-2 displacement gives 0.075, 0.046, 0.030), with a
    floor of 0.03 from the far part of the arc, meshed at a size that does not refine.
    """
    errors = np.array([traction_mismatch(p) for p, _ in hertz_sequence])
    verification(
        "Hertz 2D, Neo-Hookean, a/h = 2.5, 5, 10",
        "relative L2 distance of lambda_N nu from Pi N on the slave surface",
        errors,
        "lambda_N nu = Pi N",
        "falls with h; < 0.15 at a/h = 10",
        "the traction of the continuum at the contact surface: property (c), theory page",
    )
    assert errors[-1] < 0.15
    assert np.all(np.diff(errors) < 0), errors


@pytest.mark.serial  # 2 ranks: test_same_result_on_any_number_of_ranks
def test_action_equals_reaction(hertz_moderate, verification):
    """(e): the contact forces on the two bodies are opposite to round-off. This holds by
    construction (the master virtual displacement is interpolated with shape functions
    that sum to one), whatever the solution: not a verification of it."""
    problem, _ = hertz_moderate
    resultants = body_resultants(problem, problem.contact_residual())
    slave, master = (resultants[b.tag] for b in problem.scene.bodies)
    verification(
        HERTZ,
        "|F_slave + F_master| / |F_slave|",
        np.linalg.norm(slave + master) / np.linalg.norm(slave),
        0.0,
        "< 1e-14",
        "action = reaction, property (e): the master shape functions sum to one",
        kind="consistency",
    )
    assert np.linalg.norm(slave) > 0.5 * np.linalg.norm(problem.contact_force())
    assert np.linalg.norm(slave + master) < 1e-14 * np.linalg.norm(slave)


@across_ranks
def test_same_result_on_any_number_of_ranks(verification):
    """The distributed solve equals a solve on one rank (each rank redoes it alone), to the
    round-off of another summation order (1e-14 measured, bound 1e-12)."""
    world, _ = solve_hertz(0.01)
    alone, _ = solve_hertz(0.01, comm=MPI.COMM_SELF)
    case = "Hertz 2D, Neo-Hookean, a/h = 5, all ranks against one"
    force = np.abs(world.contact_force() - alone.contact_force()).max()
    force /= np.abs(alone.contact_force()).max()
    sw, sa = contact_samples(world), contact_samples(alone)
    ow, oa = np.lexsort(sw.x.T), np.lexsort(sa.x.T)
    position = np.abs(sw.x[ow] - sa.x[oa]).max()
    scale = sa.lambda_N.max()
    multiplier = np.abs(sw.lambda_N[ow] - sa.lambda_N[oa]).max() / scale
    for quantity, value in (
        ("largest contact force difference, relative", force),
        ("largest slave point position difference", position),
        ("largest multiplier difference, over the largest", multiplier),
    ):
        verification(case, quantity, value, 0.0, "< 1e-12", RANKS, kind="consistency")
    assert force < 1e-12
    assert position < 1e-12
    assert multiplier < 1e-12
    assert [r.newton_iterations for r in world.history.steps] == [
        r.newton_iterations for r in alone.history.steps
    ]
