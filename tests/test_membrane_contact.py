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
from conftest import assert_taylor_slopes
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.results import body_resultants, equilibrium_error
from contact_ufl.verification import analytic, scenes
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
        (2, "both", 0.05, -1.0),
        (3, "both", 0.0, 1.0),
    ],
)
def test_taylor_membrane(dim, side, mu, direction):
    """Taylor slope 2 with a membrane master (either orientation: the acting side follows
    the slave), a membrane slave, or both (membrane on membrane), frictionless and in
    slip."""
    problem, dz, steps = curved_case(dim, mu=mu, membrane=side, direction=direction)
    assert any(b.membrane for b in problem.bulks) and problem.active_points() > 10
    kinematics = problem.contacts[0].kinematics
    if side == "master":  # the sides of the paired points: those facing the slave body
        sides = kinematics._side[problem.contacts[0].projection.facet >= 0]
        facing = COMM.allreduce(int(np.count_nonzero(sides == direction)))
        assert facing > 0.9 * COMM.allreduce(len(sides))
    assert_taylor_slopes(problem, dz, steps)


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


MU, T0, R0 = 1.0, 0.01, 1.0


def _tube_between_plates(dim: int, n: int):
    """The quarter tube (string ring in 2D) inflated to half its limit pressure, then pressed
    by a rigid plate from 1.02 to 0.8 times its free radius (10 steps); the closed form."""
    p = 0.5 * MU * T0 / R0
    free = analytic.tube_free_radius(MU, T0, R0, p)
    schedule = scenes.PlatesSchedule(p, 1.02 * free, 0.8 * free)
    plate = schedule.plate(dim)
    tube = scenes.tube_for_plates(schedule, dim=dim, n=n)
    scene = cu.Scene(domains=[tube], contacts=[cu.ContactPair("tube", plate)])
    problem = cu.ContactProblem(scene, verbose=False)
    problem.solve(num_steps=10)
    exact = analytic.tube_between_plates(MU, T0, R0, p, schedule.r_end)
    return problem, schedule, plate, exact


def _pressure_error(problem, schedule, exact) -> float:
    """Largest deviation of the current contact pressure ``lambda_N / (da/dA)`` from the
    inflation pressure over the points in contact within 3/4 of the flat zone's half width
    (away from where the free arc leaves the plate), relative."""
    (c,) = problem.contacts
    active = c.active()
    x = c.slave.positions(c.u).reshape(-1, problem.gdim)[:, 0]
    pressure = c.multiplier_at_points() / c.slave.area_ratio(c.u).ravel()
    inner = active & (x < 0.75 * exact["width"] / 2)
    error = np.abs(pressure[inner] / schedule.pressure - 1.0).max(initial=0.0)
    assert COMM.allreduce(int(inner.sum())) > 4
    return COMM.allreduce(error, MPI.MAX)


@pytest.mark.parametrize("dim", [2, 3])
def test_tube_between_plates(dim):
    """An inflated tube pressed between rigid plates (quarter model; a membrane slave on a
    rigid obstacle): the plate force is the inflation pressure times the contact width, the
    contact pressure in the flat zone is the inflation pressure, the free arcs stay circular
    (:func:`contact_ufl.verification.analytic.tube_between_plates`)."""
    problem, schedule, plate, exact = _tube_between_plates(dim, 128)
    assert not problem.history.cutbacks
    depth = 0.1 if dim == 3 else 1.0  # the 3D tube's length (per unit depth in 2D)
    force = problem.obstacle_reaction(plate)
    assert abs(-force[1] / (0.5 * exact["force"] * depth) - 1.0) < 1e-3
    assert _pressure_error(problem, schedule, exact) < 1e-2
    bulk = problem.bulks[0]
    owned = bulk.V.dofmap.index_map.size_local
    x = bulk.V.tabulate_dof_coordinates()[:owned, :dim]
    x = x + bulk.u.x.array.reshape(-1, dim)[:owned]
    free = x[:, 0] > exact["width"] / 2 + 1e-9
    radius = np.linalg.norm(x[free, :2] - [exact["width"] / 2, 0.0], axis=1)
    error = np.abs(radius / schedule.r_end - 1.0).max(initial=0.0)
    assert COMM.allreduce(error, MPI.MAX) < 1e-3


def test_tube_contact_pressure_converges():
    """The contact pressure's error in the flat zone falls under refinement (2D)."""
    coarse, fine = (_tube_between_plates(2, n) for n in (64, 128))
    e_coarse = _pressure_error(coarse[0], coarse[1], coarse[3])
    e_fine = _pressure_error(fine[0], fine[1], fine[3])
    assert e_fine < 0.25 * e_coarse, (e_coarse, e_fine)


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_string_held_at_its_ends_on_a_plane(mu):
    """A pre-tensioned string on a rigid plane, pressed by a pressure, its ends held in both
    directions: the multipliers at the held ends would constrain what the supports hold (a
    singular tangent, every cut-back failing); they are held at zero, and the step
    converges at once, the plane carrying the pressure but for the ends' halves of a cell."""
    from contact_ufl.verification import membrane_meshes

    data = membrane_meshes.drumhead(COMM, 0.5, 8, quarter=True, dim=2)
    supports = [cu.Dirichlet("x0", 0.0), cu.Dirichlet("xmax", (0.01, 0.0))]
    domain = cu.Domain.from_mesh_data(
        data,
        [cu.Body("membrane", cu.MembraneNeoHookean(1.0, 0.01))],
        supports,
        [cu.FollowerPressure("membrane", lambda t: PRESSURE * t)],
        name="string",
    )
    domain.direction = (0.0, -1.0)  # n0 towards the plane: the pressure pushes it down
    plane = cu.RigidPlane((0.0, 0.0), (0.0, 1.0))
    scene = cu.Scene(domains=[domain], contacts=[cu.ContactPair("membrane", plane, mu=mu)])
    problem = cu.ContactProblem(scene, verbose=False)
    scenes.pretension(problem, 1.02)
    problem.solve(num_steps=1, max_cutbacks=0)
    assert not problem.history.cutbacks and problem.history.steps[0].newton_iterations <= 3
    (c,) = problem.contacts
    held = COMM.allreduce(problem.held_multipliers)
    assert held == (2 if mu == 0.0 else 6)  # the two ends; lambda_T: two components each
    load = np.linalg.norm(problem.load_resultant())
    assert problem.obstacle_reaction(plane)[1] > 0.85 * load  # the plane carries the load
    assert equilibrium_error(problem, ["x0", "xmax"], [plane]) < 1e-8  # the ends the rest
