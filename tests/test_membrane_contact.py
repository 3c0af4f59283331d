"""Contact with membranes, in either role: a membrane's cells are its contact surface.

As a slave, the membrane's cells carry the multipliers; as a master, it is two-sided: the
side facing each slave point acts. Verified by the Taylor test of the tangent (the membrane
made of a curved solid surface, its normal either way), by a patch test (a membrane pressed
between the two blocks of the contact patch test, master of one pair and slave of the
other, where the exact multipliers are the applied pressure on both) and by the closed form
of an inflated tube pressed between rigid plates (plate force, flat-zone pressure, free
arcs). The equilibrium and action-reaction checks hold by construction: consistency.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import across_ranks, assert_taylor_slopes
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.results import body_resultants, equilibrium_error
from contact_ufl.verification import analytic, scenes
from contact_ufl.verification.taylor_cases import curved_case

COMM = MPI.COMM_WORLD
PRESSURE = 0.01
TIGHT = {"snes_rtol": 1e-12, "snes_atol": 1e-15}

TAYLOR = "Taylor's theorem: the remainder of an exact derivative is O(h^2)"
UNIFORM = "the applied pressure: the exact solution of the patch test is uniform"
EQUILIBRIUM = "the equilibrium of a converged solve: the P1 test functions sum to one"
ACTION = "action = reaction, property (e): the master shape functions sum to one"
TUBE = (
    "closed form of the inflated tube between frictionless plates "
    "(analytic.tube_between_plates: T = p r on the free arcs, p in the flat zone, F = p w)"
)
ONE_RANK = "the same scene solved on one rank"


@pytest.mark.parametrize(
    "dim, side, mu, direction",
    [
        # on 2 ranks: the 3D cases and membrane on membrane with friction (the same gathers)
        pytest.param(2, "master", 0.0, 1.0, marks=pytest.mark.serial),
        pytest.param(2, "master", 0.05, -1.0, marks=pytest.mark.serial),
        pytest.param(2, "slave", 0.0, 1.0, marks=pytest.mark.serial),
        pytest.param(2, "slave", 0.05, -1.0, marks=pytest.mark.serial),
        (3, "master", 0.0, -1.0),
        (3, "slave", 0.05, 1.0),
        (2, "both", 0.05, -1.0),
        (3, "both", 0.0, 1.0),
    ],
)
def test_taylor_membrane(dim, side, mu, direction, verification):
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
    result = assert_taylor_slopes(problem, dz, steps, tol=4e-4)  # 1e-4 measured at most
    case = f"Taylor test {dim}D, membrane {side}, normal {direction:+g}, mu = {mu:g}"
    quantity = "slopes of the Taylor remainder |R1(h)|"
    verification(case, quantity, result.slopes, 2.0, "|slope - reference| < 4e-4", TAYLOR)


def _sandwich(dim: int) -> cu.ContactProblem:
    problem = cu.ContactProblem(
        scenes.membrane_sandwich(dim, PRESSURE), verbose=False, petsc_options=TIGHT
    )
    problem.solve(num_steps=1)
    return problem


#: the largest |lambda_N / p - 1| of the sandwich, by dimension: the quadrature error of the
#: solid patch tests' rules on the non-matching interfaces (tests/test_patch.py); measured
#: 4.6e-4 (2D) and 3.9e-3 (3D)
SANDWICH_TOLERANCE = {2: 1e-3, 3: 8e-3}
#: the membrane's in-plane contact resultant over the load, by dimension: the tilts of the
#: non-matching facets (measured 5.2e-12 in 2D, 1.7e-8 in 3D)
SANDWICH_IN_PLANE = {2: 1e-11, 3: 4e-8}
#: a sum at round-off (measured at most 4e-15 of its terms, on 1 or 2 ranks: the round-off
#: of the sums and of the factorisation changes with the partition)
ROUND_OFF = 1e-14


@pytest.mark.parametrize(
    "dim",
    [2, pytest.param(3, marks=pytest.mark.serial)],  # 3D on 2 ranks: the tube on a plate
)
def test_membrane_sandwich_patch(dim, verification):
    """A membrane between the patch-test blocks, master of the upper block's pair and slave
    on the lower block: uniform multipliers ``lambda_N = p`` on both pairs (to the
    quadrature error of the solid patch tests, tests/test_patch.py). Consistency: the whole
    load through both interfaces, global equilibrium, action and reaction on each body."""
    problem = _sandwich(dim)
    case = f"membrane between the patch-test blocks {dim}D"
    on_membrane, membrane_on_block = problem.contacts
    assert problem.bulks[on_membrane.pair.master_domain].membrane
    assert problem.bulks[membrane_on_block.pair.slave_domain].membrane
    tolerance = SANDWICH_TOLERANCE[dim]
    for c, pair in zip(problem.contacts, ("block on membrane", "membrane on block"), strict=True):
        active = c.active()
        assert COMM.allreduce(int(active.sum())) == COMM.allreduce(len(active))
        error = np.abs(c.multiplier_at_points() / PRESSURE - 1.0).max(initial=0.0)
        error = COMM.allreduce(error, MPI.MAX)
        quantity = f"largest |lambda_N / p - 1|, {pair}"
        verification(case, quantity, error, "lambda_N = p", tolerance, UNIFORM)
        assert error < tolerance
        force = abs(c.integrate("traction")[-1] / PRESSURE - 1.0)
        quantity = f"|F_N / (p A) - 1|, {pair}"
        verification(case, quantity, force, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
        assert force < ROUND_OFF
    resultants = body_resultants(problem, problem.contact_residual())
    upper, lower, membrane = (resultants[b.bodies[0].tag] for b in problem.bulks)
    scale = np.abs(upper).max()
    balance = np.abs(upper + lower + membrane).max() / scale
    quantity = "|F_upper + F_lower + F_membrane| / |F_upper|, both pairs"
    verification(case, quantity, balance, 0.0, ROUND_OFF, ACTION, kind="consistency")
    assert balance < ROUND_OFF
    # pressed equally from both sides (in its plane: the tilts of the non-matching facets,
    # held by its boundary support)
    normal, in_plane = abs(membrane[-1]) / scale, np.abs(membrane[:-1]).max() / scale
    source = "the membrane's equilibrium: its support holds it in its plane only"
    quantity = "normal contact resultant on the membrane / |F_upper|"
    verification(case, quantity, normal, 0.0, ROUND_OFF, source, kind="consistency")
    quantity = "in-plane contact resultant on the membrane / |F_upper|"
    bound = SANDWICH_IN_PLANE[dim]
    verification(case, quantity, in_plane, 0.0, bound, source, kind="consistency")
    assert normal < ROUND_OFF and in_plane < bound
    names = ["left", "right"] if dim == 2 else ["x0", "y0", "x1", "y1"]
    supports = [f"{b}_{n}" for b in ("upper", "lower") for n in names]
    supports += ["lower_bottom", "membrane_boundary"]
    error = equilibrium_error(problem, supports)
    quantity = "|supports + loads| / |loads|"
    verification(case, quantity, error, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
    assert error < ROUND_OFF


MU, T0, R0 = 1.0, 0.01, 1.0
#: the tube between plates, 128 cells around the quarter: the bounds of the errors against
#: the closed form (measured in 2D and 3D alike: plate force 1.9e-5, flat-zone pressure
#: 1.4e-3, free arcs 4.6e-6)
TUBE_FORCE, TUBE_PRESSURE, TUBE_ARCS = 4e-5, 3e-3, 1e-5


def _tube_between_plates(dim: int, n: int, comm: MPI.Comm = COMM):
    """The quarter tube (string ring in 2D) inflated to half its limit pressure, then pressed
    by a rigid plate from 1.02 to 0.8 times its free radius (10 steps); the closed form."""
    p = 0.5 * MU * T0 / R0
    free = analytic.tube_free_radius(MU, T0, R0, p)
    schedule = scenes.PlatesSchedule(p, 1.02 * free, 0.8 * free)
    plate = schedule.plate(dim)
    tube = scenes.tube_for_plates(schedule, dim=dim, n=n, comm=comm)
    scene = cu.Scene(domains=[tube], contacts=[cu.ContactPair("tube", plate)])
    problem = cu.ContactProblem(scene, verbose=False)
    problem.solve(num_steps=10)
    exact = analytic.tube_between_plates(MU, T0, R0, p, schedule.r_end)
    return problem, schedule, plate, exact


def _plate_force_error(problem, plate, exact, dim: int) -> float:
    """``F / (p w / 2) - 1`` of the plate force on the quarter (per unit length in 3D)."""
    depth = 0.1 if dim == 3 else 1.0  # the 3D tube's length (per unit depth in 2D)
    force = problem.obstacle_reaction(plate)
    return float(-force[1] / (0.5 * exact["force"] * depth) - 1.0)


def _pressure_error(problem, schedule, exact) -> float:
    """Largest deviation of the current contact pressure ``lambda_N / (da/dA)`` from the
    inflation pressure over the points in contact within 3/4 of the flat zone's half width
    (away from where the free arc leaves the plate), relative."""
    (c,) = problem.contacts
    comm = problem.comm
    active = c.active()
    x = c.slave.positions(c.u).reshape(-1, problem.gdim)[:, 0]
    pressure = c.multiplier_at_points() / c.slave.area_ratio(c.u).ravel()
    inner = active & (x < 0.75 * exact["width"] / 2)
    error = np.abs(pressure[inner] / schedule.pressure - 1.0).max(initial=0.0)
    assert comm.allreduce(int(inner.sum())) > 4
    return comm.allreduce(error, MPI.MAX)


def _arc_error(problem, schedule, exact, dim: int) -> float:
    """Largest relative distance of the nodes beyond the flat zone from the circle of radius
    ``r`` about ``(w/2, 0)``."""
    bulk = problem.bulks[0]
    owned = bulk.V.dofmap.index_map.size_local
    x = bulk.V.tabulate_dof_coordinates()[:owned, :dim]
    x = x + bulk.u.x.array.reshape(-1, dim)[:owned]
    free = x[:, 0] > exact["width"] / 2 + 1e-9
    radius = np.linalg.norm(x[free, :2] - [exact["width"] / 2, 0.0], axis=1)
    error = np.abs(radius / schedule.r_end - 1.0).max(initial=0.0)
    return problem.comm.allreduce(error, MPI.MAX)


@pytest.mark.serial  # 2 ranks: test_tube_between_plates_on_any_number_of_ranks
@pytest.mark.parametrize("dim", [2, 3])
def test_tube_between_plates(dim, verification):
    """An inflated tube pressed between rigid plates (quarter model, 128 cells around; a
    membrane slave on a rigid obstacle), against the closed form
    (:func:`contact_ufl.verification.analytic.tube_between_plates`): the plate force is the
    inflation pressure times the contact width, the contact pressure in the flat zone is
    the inflation pressure (a flat membrane carries no pressure difference), the free arcs
    are circles of radius ``r`` (Laplace's law ``T = p r``, the tension uniform)."""
    problem, schedule, plate, exact = _tube_between_plates(dim, 128)
    assert not problem.history.cutbacks
    case = f"inflated tube between rigid plates {dim}D, 128 cells per quarter"
    force = abs(_plate_force_error(problem, plate, exact, dim))
    verification(case, "|plate force / (p w) - 1|", force, 0.0, TUBE_FORCE, TUBE)
    pressure = _pressure_error(problem, schedule, exact)
    quantity = "largest |t_N / p - 1| in the inner 3/4 of the flat zone"
    verification(case, quantity, pressure, 0.0, TUBE_PRESSURE, TUBE)
    arcs = _arc_error(problem, schedule, exact, dim)
    quantity = "largest |distance / r - 1| of the free nodes from their arc"
    verification(case, quantity, arcs, 0.0, TUBE_ARCS, TUBE)
    assert force < TUBE_FORCE
    assert pressure < TUBE_PRESSURE
    assert arcs < TUBE_ARCS


@pytest.mark.serial  # 2 ranks: test_tube_between_plates_on_any_number_of_ranks
def test_tube_contact_pressure_converges(verification):
    """The contact pressure's error in the flat zone falls under refinement (2D, 64 and 128
    cells per quarter)."""
    coarse, fine = (_tube_between_plates(2, n) for n in (64, 128))
    e_coarse = _pressure_error(coarse[0], coarse[1], coarse[3])
    e_fine = _pressure_error(fine[0], fine[1], fine[3])
    case = "inflated tube between rigid plates 2D, 64 and 128 cells per quarter"
    quantity = "flat-zone pressure error at 128 over that at 64 cells per quarter"
    # measured 0.05: the error falls faster than h^2 once the flat zone spans many cells
    verification(case, quantity, e_fine / e_coarse, "falls", "< 0.1", TUBE)
    assert e_fine < 0.1 * e_coarse, (e_coarse, e_fine)


@across_ranks
def test_tube_between_plates_on_any_number_of_ranks(verification):
    """The 3D quarter tube between the plates (quadrilaterals, 128 cells around): the same
    plate force, free arcs and Newton iterations on this communicator as on one rank."""
    world = _tube_between_plates(3, 128)
    alone = _tube_between_plates(3, 128, MPI.COMM_SELF)
    forces = [problem.obstacle_reaction(plate) for problem, _, plate, _ in (world, alone)]
    arcs = [
        _arc_error(problem, schedule, exact, 3) for problem, schedule, _, exact in (world, alone)
    ]
    case = "inflated tube between rigid plates 3D, 128 cells per quarter"
    difference = np.linalg.norm(forces[0] - forces[1]) / np.linalg.norm(forces[1])
    quantity = f"|F - F_1| / |F_1| on {COMM.size} ranks"
    # the factorisation's round-off differs with the partition (measured 4e-16)
    verification(case, quantity, difference, 0.0, 1e-13, ONE_RANK, kind="consistency")
    assert difference < 1e-13
    # the free nodes' distance from the arc, relative to r: the same nodes, moved alike
    assert abs(arcs[0] - arcs[1]) < 1e-12
    iterations = [[s.newton_iterations for s in p.history.steps] for p, *_ in (world, alone)]
    assert iterations[0] == iterations[1]


@pytest.mark.serial  # on 2 ranks: this file's rank comparisons
@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_string_held_at_its_ends_on_a_plane(mu, verification):
    """A pre-tensioned string on a rigid plane, pressed by a pressure, its ends held in both
    directions: the multipliers at the held ends would constrain what the supports hold (a
    singular tangent, every cut-back failing); they are held at zero, and the step
    converges at once, the plane carrying the pressure but for the ends' halves of a cell
    (consistency: the share the discrete multiplier equations give it)."""
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
    # converges at once (one Newton iteration measured)
    assert not problem.history.cutbacks and problem.history.steps[0].newton_iterations <= 2
    held = COMM.allreduce(problem.held_multipliers)
    assert held == (2 if mu == 0.0 else 6)  # the two ends; lambda_T: two components each
    case = f"pre-tensioned string on a rigid plane, ends held, mu = {mu:g}"
    load = np.linalg.norm(problem.load_resultant())
    share = problem.obstacle_reaction(plane)[1] / load
    expected = _held_ends_share(8)
    deviation = abs(share / expected - 1.0)
    quantity = f"|plane's share of the pressure / {expected:.6f} - 1|"
    source = "the P1 multipliers held at zero at the ends: the consistent mass, solved"
    verification(case, quantity, deviation, 0.0, ROUND_OFF, source, kind="consistency")
    assert deviation < ROUND_OFF
    error = equilibrium_error(problem, ["x0", "xmax"], [plane])  # the ends carry the rest
    quantity = "|supports + plane + pressure| / |pressure|"
    verification(case, quantity, error, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
    assert error < ROUND_OFF


def _held_ends_share(n: int) -> float:
    """The share of the pressure's resultant a plane carries under a flat string of ``n``
    cells whose end multipliers are held at zero: the equations of the interior nodes,
    ``int lambda phi_i = p h`` (the consistent mass ``h/6 (1, 4, 1)``), summed over the
    string, ``h sum lambda_i``, over ``n p h``."""
    mass = (4.0 * np.eye(n - 1) + np.eye(n - 1, k=1) + np.eye(n - 1, k=-1)) / 6.0
    return float(np.linalg.solve(mass, np.ones(n - 1)).sum() / n)
