"""The default augmentation eps_N = E / L (E of the softer body, L the slave surface's size):
a pair needs no eps_N, and the solution does not depend on it beyond the elements where the
contact zone ends."""

import dataclasses

import numpy as np
import pytest
from mpi4py import MPI

from contact_ufl.mpi import global_diameter
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes


def solved(scene):
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=1)
    return problem


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


def test_default_eps_gives_the_same_solution():
    """Hertz with eps_N = E/h (200 here) and with the default E/L (0.45): the contact force
    and the peak multiplier agree to 2e-4 (measured 6e-5 and 1e-6 at this mesh: the
    difference lives in the elements cut by the edge of the contact zone)."""
    explicit = solved(scenes.hertz_2d(h_contact=0.01, depth=0.02).scene)
    scene = scenes.hertz_2d(h_contact=0.01, depth=0.02).scene
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=None)
    default = solved(scene)
    assert float(default.contacts[0].normal.eps_N.value) < 1.0
    F0, F1 = explicit.contact_force()[1], default.contact_force()[1]
    assert abs(F1 / F0 - 1.0) < 2e-4
    peak = [
        p.comm.allreduce(p.contacts[0].multiplier_at_points().max(initial=0.0), op=MPI.MAX)
        for p in (explicit, default)
    ]
    assert abs(peak[1] / peak[0] - 1.0) < 2e-4
    assert np.isfinite(F1) and F1 > 0
