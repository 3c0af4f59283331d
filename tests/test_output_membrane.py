"""The contact pressure on a membrane as cell data (contact_ufl.output)."""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl import output
from contact_ufl.verification import scenes

PRESSURE = 0.01
#: the cells' mean contact pressure against the applied one: the quadrature error of the
#: solid patch test's rule on the non-matching interface (measured 1.3e-4)
TOLERANCE = 3e-4


def test_membrane_contact_pressure_of_the_sandwich(verification):
    """The membrane between the patch-test blocks is the slave of one pair, pressed by the
    uniform pressure: every cell's mean contact pressure is that pressure (to the patch
    test's quadrature error), and only the membrane mesh gets a field."""
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
    error = MPI.COMM_WORLD.allreduce(error, MPI.MAX)
    case = "membrane between the patch-test blocks 2D"
    quantity = "largest |cell contact pressure / p - 1| of output.membrane_contact_pressure"
    source = "the applied pressure: the exact solution of the patch test is uniform"
    verification(case, quantity, error, 0.0, TOLERANCE, source)
    assert error < TOLERANCE
