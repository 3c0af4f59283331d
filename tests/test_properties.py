"""Properties (c) and (e) of the formulation, and independence of the number of ranks."""

import numpy as np
import pytest
from conftest import across_ranks, solve_hertz
from mpi4py import MPI

from contact_ufl.results import body_resultants, contact_samples, traction_mismatch


@pytest.mark.serial  # 2 ranks: test_same_result_on_any_number_of_ranks
def test_multipliers_are_the_tractions(hertz_sequence, verification):
    """(c): lambda_N nu equals the bulk traction Pi N, up to an error that falls with h."""
    errors = np.array([traction_mismatch(p) for p, _ in hertz_sequence])
    verification(
        "Hertz 2D, Neo-Hookean, a/h = 2.5, 5, 10",
        "relative L2 distance of lambda_N nu from Pi N on the slave surface",
        errors,
        "lambda_N nu = Pi N",
        "falls with h; < 0.2 at a/h = 10",
        "the traction of the continuum at the contact surface: property (c), theory page",
    )
    assert errors[-1] < 0.2
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
        "Hertz 2D, Neo-Hookean, a/h = 10",
        "|F_slave + F_master| / |F_slave|",
        np.linalg.norm(slave + master) / np.linalg.norm(slave),
        0.0,
        "< 1e-13",
        "action = reaction, property (e): the master shape functions sum to one",
        kind="consistency",
    )
    assert np.linalg.norm(slave) > 0.5 * np.linalg.norm(problem.contact_force())
    assert np.linalg.norm(slave + master) < 1e-13 * np.linalg.norm(slave)


@across_ranks
def test_same_result_on_any_number_of_ranks():
    """The distributed solve equals a solve on one rank (each rank redoes it alone)."""
    world, _ = solve_hertz(0.01)
    alone, _ = solve_hertz(0.01, comm=MPI.COMM_SELF)
    assert np.allclose(world.contact_force(), alone.contact_force(), rtol=1e-7, atol=0)
    sw, sa = contact_samples(world), contact_samples(alone)
    ow, oa = np.lexsort(sw.x.T), np.lexsort(sa.x.T)
    assert np.allclose(sw.x[ow], sa.x[oa], rtol=0, atol=1e-10)
    scale = sa.lambda_N.max()
    assert np.allclose(sw.lambda_N[ow], sa.lambda_N[oa], rtol=0, atol=1e-7 * scale)
    assert [r.newton_iterations for r in world.history.steps] == [
        r.newton_iterations for r in alone.history.steps
    ]
