"""Contact with membranes, in either role: a membrane's cells are its contact surface.

As a slave, the membrane's cells carry the multipliers; as a master, it is two-sided: the
side facing each slave point acts. Verified by the Taylor test of the tangent (the membrane
made of a curved solid surface, its normal either way) and by a patch test: a membrane
pressed between the two blocks of the contact patch test, master of one pair and slave of
the other, where the exact multipliers are the applied pressure on both.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.results import body_resultants, equilibrium_error
from contact_ufl.taylor import taylor_test
from contact_ufl.verification import scenes
from contact_ufl.verification.taylor_cases import curved_case

COMM = MPI.COMM_WORLD
PRESSURE = 0.01
TIGHT = {"snes_rtol": 1e-12, "snes_atol": 1e-15}


@pytest.mark.parametrize(
    "dim, side, mu, direction",
    [
        (2, "master", 0.0, 1.0),
        (2, "master", 0.05, -1.0),
        (2, "slave", 0.0, 1.0),
        (2, "slave", 0.05, -1.0),
        (3, "master", 0.0, -1.0),
        (3, "slave", 0.05, 1.0),
    ],
)
def test_taylor_membrane(dim, side, mu, direction):
    """Taylor slope 2 with a membrane master (either orientation: the acting side follows
    the slave) or a membrane slave, frictionless and in slip."""
    problem, dz, steps = curved_case(dim, mu=mu, membrane=side, direction=direction)
    assert any(b.membrane for b in problem.bulks) and problem.active_points() > 10
    kinematics = problem.contacts[0].kinematics
    if side == "master":  # the sides of the paired points: those facing the slave body
        sides = kinematics._side[problem.contacts[0].projection.facet >= 0]
        facing = COMM.allreduce(int(np.count_nonzero(sides == direction)))
        assert facing > 0.9 * COMM.allreduce(len(sides))
    result = taylor_test(problem, dz, steps)
    assert not result.facets_changed and not result.active_changed
    assert np.all(np.abs(result.slopes - 2.0) < 0.01), result.slopes


def _sandwich(dim: int) -> cu.ContactProblem:
    problem = cu.ContactProblem(
        scenes.membrane_sandwich(dim, PRESSURE), verbose=False, petsc_options=TIGHT
    )
    problem.solve(num_steps=1)
    return problem


@pytest.mark.parametrize("dim, tolerance", [(2, 1e-3), (3, 2e-2)])
def test_membrane_sandwich_patch(dim, tolerance):
    """A membrane between the patch-test blocks, master of the upper block's pair and slave
    on the lower block: uniform multipliers ``lambda_N = p`` on both pairs (to the
    quadrature error of the solid patch tests, tests/test_patch.py), the whole load through
    both interfaces, global equilibrium, and action and reaction on each body."""
    problem = _sandwich(dim)
    on_membrane, membrane_on_block = problem.contacts
    assert problem.bulks[on_membrane.pair.master_domain].membrane
    assert problem.bulks[membrane_on_block.pair.slave_domain].membrane
    for c in problem.contacts:
        active = c.active()
        assert COMM.allreduce(int(active.sum())) == COMM.allreduce(len(active))
        error = np.abs(c.multiplier_at_points() / PRESSURE - 1.0).max(initial=0.0)
        assert COMM.allreduce(error, MPI.MAX) < tolerance
        force = c.integrate("traction")
        assert abs(force[-1] / PRESSURE - 1.0) < 1e-10
    resultants = body_resultants(problem, problem.contact_residual())
    upper, lower, membrane = (resultants[b.bodies[0].tag] for b in problem.bulks)
    scale = np.abs(upper).max()
    assert np.abs(upper + lower + membrane).max() < 1e-12 * scale  # (e), over both pairs
    # pressed equally from both sides (in its plane: the tilts of the non-matching facets,
    # held by its boundary support)
    assert abs(membrane[-1]) < 1e-12 * scale and np.abs(membrane).max() < 1e-6 * scale
    names = ["left", "right"] if dim == 2 else ["x0", "y0", "x1", "y1"]
    supports = [f"{b}_{n}" for b in ("upper", "lower") for n in names]
    supports += ["lower_bottom", "membrane_boundary"]
    assert equilibrium_error(problem, supports) < 1e-10
