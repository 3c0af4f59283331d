"""The tangent is the derivative of the residual: second-order Taylor remainders.

The state has curved slave and master surfaces in contact; the direction slides the slave
body along the master facets, deforms both bodies (rotating the master normals) and changes
the multipliers. Over the steps no point changes facet or contact status.
"""

import numpy as np
import pytest
from conftest import assert_taylor_slopes
from mpi4py import MPI

from contact_ufl.verification.taylor_cases import curved_case


@pytest.mark.parametrize("dim", [2, 3])
def test_taylor_second_order(dim):
    problem, dz, steps = curved_case(dim)
    assert problem.active_points() > 10
    assert_taylor_slopes(problem, dz, steps, zeroth=True)


def test_taylor_detects_a_frozen_projection():
    """Dropping the variation of the projected point leaves a first-order remainder."""
    problem, dz, steps = curved_case(2)
    problem.contacts[0].kinematics.frozen_projection = True
    assert_taylor_slopes(problem, dz, steps, slope=1.0, unchanged=False)


@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_smoothed_master_normal(mu):
    """The smoothed normal depends on the neighbours of the master segment: its tangent,
    chained through their gathered dofs, is still exact (second order)."""
    problem, dz, steps = curved_case(2, mu=mu, master_normal="smoothed")
    c = problem.contacts[0]
    assert c.kinematics.nx == 4 and problem.active_points() > 10
    facet = curved_case(2, mu=mu)[0].contacts[0]
    change = np.abs(facet.projection.normal - c.projection.normal).max(initial=0.0)
    assert problem.comm.allreduce(change, op=MPI.MAX) > 1e-6  # another normal indeed
    assert_taylor_slopes(problem, dz, steps)


@pytest.mark.parametrize("cell, nn", [("tetrahedron", 3), ("hexahedron", 4)])
@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_smoothed_master_normal_3d(cell, nn, mu):
    """In 3D the smoothed normal depends on the fans of the master facet's nodes (triangles
    of tetrahedra, bilinear quadrilaterals of hexahedra), gathered with the facet's nodes:
    the tangent is still exact, frictionless and in slip."""
    problem, dz, steps = curved_case(3, mu=mu, master_normal="smoothed", cell=cell)
    kinematics = problem.contacts[0].kinematics
    assert kinematics.nx > nn and (kinematics.nx - nn) % nn == 0
    assert problem.active_points() > 10
    if cell == "hexahedron" and problem.comm.size > 1:  # fans of nodes on two ranks
        master = problem.contacts[0].master
        assert problem.comm.allreduce(master.num_facets, op=MPI.MIN) > 0
    assert_taylor_slopes(problem, dz, steps)
