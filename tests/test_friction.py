"""Coulomb friction: consistent tangent in stick and in slip, friction only where mu > 0."""

import dataclasses

import numpy as np
import pytest

from contact_ufl.friction import FrictionalContact
from contact_ufl.problem import ContactProblem
from contact_ufl.scenes import curved_pair
from contact_ufl.taylor import curved_case, taylor_test


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("mu, state", [(0.3, "slip"), (100.0, "stick")])
def test_frictional_taylor_second_order(dim, mu, state):
    problem, dz, steps = curved_case(dim, mu=mu)
    c = problem.contacts[0]
    active = problem.comm.allreduce(int(c.active().sum()))
    stick = problem.comm.allreduce(int(c.stick().sum()))
    assert active > 10
    assert stick == (active if state == "stick" else 0)
    result = taylor_test(problem, dz, steps)
    assert not result.facets_changed and not result.active_changed
    assert np.all(np.abs(result.slopes - 2.0) < 0.1), result.slopes


def test_friction_unknowns_only_with_mu():
    scene = curved_pair(2)
    frictionless = ContactProblem(scene, verbose=False)
    assert len(frictionless.unknowns) == 2  # u, lambda_N
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], mu=0.3)
    frictional = ContactProblem(scene, verbose=False)
    assert isinstance(frictional.contacts[0], FrictionalContact)
    assert len(frictional.unknowns) == 3  # u, lambda_N, lambda_T
    assert frictional.layout.global_size > frictionless.layout.global_size


def test_no_nan_where_q_vanishes():
    """lambda_T = 0 and no slip: q = 0 at every point, the residual and tangent are finite."""
    problem, _, _ = curved_case(2, mu=0.3)
    c = problem.contacts[0]
    c.lambda_T.x.array[:] = 0.0
    c.mask_n.x.array[:] = 0.0  # no slip history
    problem.forget_state()
    import dolfinx.fem.petsc

    dolfinx.fem.petsc.assign(problem.unknowns, problem.x)
    R = problem.evaluate_residual(problem.x)
    J = problem.evaluate_jacobian(problem.x)
    assert np.isfinite(R.norm()) and np.isfinite(J.norm())
