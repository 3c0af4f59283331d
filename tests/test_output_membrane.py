"""The contact pressure on a membrane as cell data (contact_ufl.output)."""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl import output
from contact_ufl.verification import scenes

PRESSURE = 0.01


def test_membrane_contact_pressure_of_the_sandwich():
    """The membrane between the patch-test blocks is the slave of one pair, pressed by the
    uniform pressure: every cell's mean contact pressure is that pressure (to the patch
    test's quadrature error, 1e-3 in 2D), and only the membrane mesh gets a field."""
    problem = cu.ContactProblem(
        scenes.membrane_sandwich(2, PRESSURE),
        verbose=False,
        petsc_options={"snes_rtol": 1e-12, "snes_atol": 1e-15},
    )
    problem.solve(num_steps=1)
    pressures = output.membrane_contact_pressure(problem)
    assert list(pressures) == [k for k, b in enumerate(problem.bulks) if b.membrane] == [2]
    f = pressures[2]
    owned = f.function_space.dofmap.index_map.size_local
    error = np.abs(f.x.array[:owned] / PRESSURE - 1.0).max(initial=0.0)
    assert MPI.COMM_WORLD.allreduce(owned, MPI.SUM) > 4
    assert MPI.COMM_WORLD.allreduce(error, MPI.MAX) < 1e-3
