"""Shared fixtures: solved verification problems, built once per session."""

import pytest
from mpi4py import MPI

from contact_ufl import scenes
from contact_ufl.problem import ContactProblem


def solve_hertz(h_contact: float, depth: float = 0.005, comm=MPI.COMM_WORLD, steps: int = 4):
    """Solve the 2D Hertz scene; return the problem and the scene's analytic data."""
    hertz = scenes.hertz_2d(h_contact=h_contact, depth=depth, comm=comm)
    problem = ContactProblem(hertz.scene, verbose=False)
    problem.solve(num_steps=steps)
    return problem, hertz


@pytest.fixture(scope="session")
def hertz_sequence():
    """Hertz on three meshes (a/h ~ 2.5, 5, 10), for refinement studies."""
    return [solve_hertz(h) for h in (0.02, 0.01, 0.005)]


@pytest.fixture(scope="session")
def hertz_moderate(hertz_sequence):
    """Hertz at a/h ~ 10 (the accuracy target mesh)."""
    return hertz_sequence[-1]
