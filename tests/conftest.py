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


def tagged_unit_square(n: int = 4, cell_type=None):
    """The unit square as one body (cell tag 1), sides tagged left 1, right 2, bottom 3, top 4."""
    import dolfinx
    import numpy as np

    from contact_ufl.meshes import tag_single_body

    cell_type = cell_type or dolfinx.mesh.CellType.triangle
    mesh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, n, n, cell_type)
    sides = [lambda x, k=k, v=v: np.isclose(x[k], v) for k, v in ((0, 0), (0, 1), (1, 0), (1, 1))]
    return (mesh, *tag_single_body(mesh, sides))
