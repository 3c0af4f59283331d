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

TAYLOR = "Taylor's theorem: the remainder of an exact derivative is O(h^2)"
#: the bounds on |slope - 2| of the first-order remainders (largest measured: 1.6e-4 on one
#: rank, 1.8e-4 on two, 3D with friction) and on |slope - 1| of the zeroth-order ones (9.4e-6)
SLOPE_TOL = 4e-4
ZEROTH_TOL = 2e-5


def record_slopes(verification, case, result, slope=2.0, source=TAYLOR, tol=0.01):
    """Record the slopes of the first-order remainder that assert_taylor_slopes checked
    (within ``tol`` of ``slope``: its default 0.01 unless the test passed another)."""
    quantity = "slopes of the Taylor remainder |R1(h)|"
    verification(case, quantity, result.slopes, slope, f"|slope - reference| < {tol:g}", source)


def check_zeroth_slopes(verification, case, result, tol=ZEROTH_TOL):
    """Record, then assert, that the zeroth-order remainder falls with slope 1 within
    ``tol`` (the perturbation is not zero)."""
    zeroth = np.diff(np.log(result.zeroth)) / np.diff(np.log(result.h))
    source = "Taylor's theorem: the zeroth-order remainder is O(h)"
    quantity = "slopes of the remainder |R0(h)|"
    verification(case, quantity, zeroth, 1.0, f"|slope - 1| < {tol:g}", source)
    assert np.all(np.abs(zeroth - 1.0) < tol), zeroth


@pytest.mark.parametrize("dim", [2, 3])
def test_taylor_second_order(dim, verification):
    problem, dz, steps = curved_case(dim)
    assert problem.active_points() > 10
    result = assert_taylor_slopes(problem, dz, steps, tol=SLOPE_TOL)
    case = f"Taylor test {dim}D, curved surfaces, frictionless"
    record_slopes(verification, case, result, tol=SLOPE_TOL)
    check_zeroth_slopes(verification, case, result)


def test_taylor_detects_a_frozen_projection(verification):
    """Dropping the variation of the projected point leaves a first-order remainder."""
    problem, dz, steps = curved_case(2)
    problem.contacts[0].kinematics.frozen_projection = True
    result = assert_taylor_slopes(problem, dz, steps, slope=1.0, tol=SLOPE_TOL, unchanged=False)
    case = "Taylor test 2D, projection's variation dropped (a wrong tangent, on purpose)"
    source = "Taylor's theorem: an inexact derivative leaves an O(h) remainder"
    record_slopes(verification, case, result, slope=1.0, source=source, tol=SLOPE_TOL)


@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_smoothed_master_normal(mu, verification):
    """The smoothed normal depends on the neighbours of the master segment: its tangent,
    chained through their gathered dofs, is still exact (second order)."""
    problem, dz, steps = curved_case(2, mu=mu, master_normal="smoothed")
    c = problem.contacts[0]
    assert c.kinematics.nx == 4 and problem.active_points() > 10
    facet = curved_case(2, mu=mu)[0].contacts[0]
    change = np.abs(facet.projection.normal - c.projection.normal).max(initial=0.0)
    assert problem.comm.allreduce(change, op=MPI.MAX) > 1e-6  # another normal indeed
    result = assert_taylor_slopes(problem, dz, steps, tol=SLOPE_TOL)
    case = f"Taylor test 2D, smoothed master normal, mu = {mu:g}"
    record_slopes(verification, case, result, tol=SLOPE_TOL)


@pytest.mark.parametrize(
    "cell, nn",
    # 2 ranks: tetrahedra (the hexahedra's gathers are the same code)
    [("tetrahedron", 3), pytest.param("hexahedron", 4, marks=pytest.mark.serial)],
)
@pytest.mark.parametrize(
    "mu",
    # 2 ranks: with friction; the frictionless variant with the slow tests (the frictional
    # tangent holds every term of it)
    [pytest.param(0.0, marks=[pytest.mark.serial, pytest.mark.slow]), 0.05],
)
def test_taylor_smoothed_master_normal_3d(cell, nn, mu, verification):
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
    result = assert_taylor_slopes(problem, dz, steps, tol=SLOPE_TOL)
    case = f"Taylor test 3D, {cell}, smoothed master normal, mu = {mu:g}"
    record_slopes(verification, case, result, tol=SLOPE_TOL)
