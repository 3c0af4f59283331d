"""The tangent is the derivative of the residual: second-order Taylor remainders.

The state has curved slave and master surfaces in contact; the direction slides the slave
body along the master facets, deforms both bodies (rotating the master normals) and changes
the multipliers. Over the steps no point changes facet or contact status.
"""

import numpy as np
import pytest

from contact_ufl.problem import ContactProblem
from contact_ufl.scenes import curved_pair
from contact_ufl.taylor import contact_state, sliding_direction, taylor_test

STATES = {
    2: dict(shift=np.array([0.03, -0.04]), slide=np.array([0.05, 0.0]), h0=1e-3),
    3: dict(shift=np.array([0.03, 0.02, -0.04]), slide=np.array([0.05, 0.03, 0.0]), h0=1e-4),
}


def _problem(dim):
    scene = curved_pair(dim)
    problem = ContactProblem(scene, verbose=False)
    state = STATES[dim]
    contact_state(problem, scene.bodies[0].tag, state["shift"])
    dz = sliding_direction(problem, scene.bodies[0].tag, state["slide"])
    steps = [state["h0"] * 2.0**-k for k in range(4)]
    return problem, dz, steps


@pytest.mark.parametrize("dim", [2, 3])
def test_taylor_second_order(dim):
    problem, dz, steps = _problem(dim)
    assert problem.active_points() > 10
    result = taylor_test(problem, dz, steps)
    assert not result.facets_changed and not result.active_changed
    assert np.all(result.zeroth > 0)
    assert np.all(np.abs(np.diff(np.log(result.zeroth)) / np.diff(np.log(result.h)) - 1) < 0.05)
    assert np.all(np.abs(result.slopes - 2.0) < 0.1), result.slopes


def test_taylor_detects_a_frozen_projection():
    """Dropping the variation of the projected point leaves a first-order remainder."""
    problem, dz, steps = _problem(2)
    problem.contacts[0].frozen_projection = True
    result = taylor_test(problem, dz, steps)
    assert np.all(np.abs(result.slopes - 1.0) < 0.1), result.slopes
