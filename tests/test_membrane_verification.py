"""Verification of contact between membranes and solids.

- A stiff solid pressed into a pre-tensioned drumhead (the solid the slave, the membrane the
  two-sided master): in 2D the indenter force and the string's straight parts are those of
  the closed form of a taut string wrapped round a rigid cylinder. Consistency: the
  supports of both meshes balance (no load acts: the reactions sum to zero), the contact
  resultant on the membrane is minus the indenter's (property (e)), and the same force and
  largest multiplier on 2 ranks as on one.
- A flat membrane pressed by a follower pressure onto a solid block (the membrane the
  slave), both stretched in their plane: the exact solution is homogeneous, the multipliers
  are the contact tractions (property (c): ``lambda_N / (da/dA) = p``). Consistency:
  supports, pressure and contact forces balance to round-off.
- Friction: a pre-tensioned string (a membrane strip in 3D) pressed onto a rigid plane and
  pulled by one end slips near that end and sticks beyond; the string's end tensions and
  slip front follow the closed form below. Consistency: ``|lambda_T| = mu lambda_N`` at the
  slipping points, strictly inside the cone at the sticking ones (the nodal multiplier
  equations impose it), balance, and the same pull on 2 ranks as on one.

Closed form of the string (plane strain, per unit depth). A string of reference length
``2 a`` held at its ends ``(+-c, 0)`` is pressed at its middle by a rigid cylinder of radius
``R`` whose lowest point is at ``y = -d``. Frictionless contact loads it normally only, so
its tension ``T`` is uniform; the string wraps the cylinder over the arc ``|phi| <= theta``
about its lowest point and runs straight from there, tangent to the circle, to the ends.
With the centre ``C = (0, R - d)`` and ``D = |C - (c, 0)|``, the straight part has the
length ``sqrt(D^2 - R^2)`` and leaves the horizontal at ``theta = asin(R / D) - atan((R -
d) / c)``; the stretch is ``l = (sqrt(D^2 - R^2) + R theta) / a``, the tension that of the
Neo-Hookean string ``T = mu t0 (l - l^-3)``, and the vertical balance of the cylinder gives
its force ``F = 2 T sin(theta)``: exact for any deflection while the contact is one arc.

Closed form of the dragged string. A string at the pre-stretch ``s`` lies on a flat with
friction ``mu`` under the pressure ``p``; its end ``X = a`` is pulled out by ``delta``. In
the slip zone ``X_f < X < a`` its nominal tension ``N(l) = mu t0 (l - l^-3)`` grows by the
friction ``mu lambda_N = mu p l`` per unit reference length (``lambda_N`` is per unit
reference length, the pressure per unit current length), ``N'(l) dl/dX = mu p l``; beyond
the front it sticks at the stretch ``s``. Hence ``dX = N'(l) dl / (mu p l)``, the end's
stretch ``l_e`` solves ``delta = int_s^{l_e} (l - s) N'(l) / (mu p l) dl``, the slip zone
is ``a - X_f = int_s^{l_e} N'(l) / (mu p l) dl`` long and the end carries ``N(l_e)``, the
stuck end ``N(s)``.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import across_ranks
from mpi4py import MPI
from scipy.integrate import quad
from scipy.optimize import brentq

import contact_ufl as cu
from contact_ufl.results import (
    body_resultants,
    coulomb_law,
    equilibrium_error,
    lowest_displacement,
)
from contact_ufl.verification import analytic, scenes

COMM = MPI.COMM_WORLD
#: Newton to the round-off floor of the residual (the stiff indenter's forces set its scale)
TIGHT = {"snes_rtol": 1e-13, "snes_atol": 1e-17}
#: the dragged string: its round-off floor is reached at 1e-12
TIGHT_STRING = {"snes_rtol": 1e-12, "snes_atol": 1e-15}
MU, T0 = 1.0, 0.01  # the membrane law of the scenes (MembraneNeoHookean(1.0, 0.01))

#: the supports of the indented drumheads, by dimension
INDENTER_SUPPORTS = {
    2: ["cylinder_top", "xmin", "xmax"],
    3: ["indenter_top", "indenter_x0", "indenter_y0", "x0", "y0", "xmax", "ymax"],
}


def string_on_cylinder(R: float, c: float, a: float, d: float) -> tuple[float, float, float]:
    """The closed form of the module docstring: ``(F, theta, T)`` for a cylinder of radius
    ``R`` whose lowest point is ``d`` below the ends ``(+-c, 0)`` of a Neo-Hookean string of
    reference length ``2 a``."""
    h = R - d
    D = np.hypot(c, h)
    theta = np.arcsin(R / D) - np.arctan2(h, c)
    stretch = (np.sqrt(D**2 - R**2) + R * theta) / a
    T = analytic.tube_hoop_tension_neo_hookean(MU, T0, stretch)
    return 2.0 * T * np.sin(theta), theta, T


def _indented(dim: int, comm: MPI.Comm, n: int, steps: int = 4):
    drum = scenes.indented_drumhead(dim=dim, n=n, comm=comm)
    problem = cu.ContactProblem(drum.scene, verbose=False, petsc_options=TIGHT)
    scenes.pretension(problem, drum.stretch, domain=1)
    problem.solve(num_steps=steps)
    return problem, drum


def _force_and_multiplier(problem, top: str) -> tuple[np.ndarray, float]:
    (c,) = problem.contacts
    lam = problem.comm.allreduce(c.multiplier_at_points().max(initial=0.0), MPI.MAX)
    return problem.reaction(top), lam


#: the bounds of the string drumhead's indenter force and of the distance of its free nodes
#: from the straight tangents (over the indentation depth) against the closed form
#: (measured 5.8e-5 and 6.0e-5)
STRING_FORCE, STRING_TANGENTS = 1e-4, 1e-4
#: the indented drumhead's support reactions, which sum to zero to the solver's tolerance
#: on the stiff indenter's forces (measured 2.4e-12 in 2D, 8.6e-13 in 3D of the force)
DRUM_BALANCE = 5e-12
#: the contact pressure of the membrane pressed onto a block: exact to round-off (measured
#: at most 5.3e-15 on 1 or 2 ranks)
HOMOGENEOUS_TOLERANCE = 2e-14
#: the dragged string: its end tension against the closed form with the half cell's friction
#: (measured 1.5e-5, falling under refinement)
DRAGGED_END = 3e-5
#: the Coulomb law at the points of the dragged string (strip), of max mu lambda_N, to the
#: Newton solve's last residual (measured 1.3e-14 in 3D, 1.4e-16 in 2D)
CONE = 5e-14
#: the largest |lambda_T| / (mu lambda_N) at the sticking points of the dragged string
#: (strip), by dimension: strictly inside the cone (measured 0.685 and 0.992, next to the
#: front; the bounds halve the distance to the cone)
STICK_INSIDE = {2: 0.85, 3: 0.996}
#: a sum at round-off, relative to its terms (measured at most 8.7e-15 on 1 or 2 ranks: the
#: round-off of the sums and of the factorisation changes with the partition)
ROUND_OFF = 2e-14
ONE_RANK = "the same scene solved on one rank"
#: a run on 2 ranks against one on 1 rank: the factorisation's round-off differs with the
#: partition and from run to run; the indented drumhead's force agrees to the solver's
#: tolerance on the stiff indenter (measured up to 2e-12), its largest multiplier and the
#: dragged string's pull force to round-off (measured 7e-15 and 3e-16)
RANKS_FORCE, RANKS_MULTIPLIER, RANKS_PULL = 1e-11, 3e-14, 1e-13
EQUILIBRIUM = "the equilibrium of a converged solve: the P1 test functions sum to one"
ACTION = "action = reaction, property (e): the master shape functions sum to one"
STRING = "closed form of a taut string wrapped round a rigid cylinder (module docstring)"
DRAGGED = "closed form of the string dragged over a flat with friction (module docstring)"
HOMOGENEOUS = "the exact homogeneous solution: the contact pressure is the applied pressure"
INDENTED = {
    2: "solid pressed into a string drumhead 2D, 64 cells",
    3: "solid pressed into a drumhead 3D, quarter, 16 cells",
}


@pytest.mark.serial  # 2 ranks: test_drumhead_on_any_number_of_ranks
@pytest.mark.parametrize("dim, n", [(2, 64), (3, 16)])
def test_solid_pressed_into_a_drumhead(dim, n, verification):
    """A stiff indenter (E = 100, the membrane's ``mu t0 = 0.01``) pressed by its top into
    the pre-tensioned drumhead. Consistency: equilibrium of all supports of both meshes to
    the solver's tolerance, action and reaction across the meshes (e) to round-off."""
    problem, drum = _indented(dim, COMM, n)
    assert not problem.history.cutbacks
    supports = INDENTER_SUPPORTS[dim]
    force, _ = _force_and_multiplier(problem, supports[0])
    assert force[-1] < -1e-5 and problem.active_points() > 10  # the membrane pushes back up
    case = INDENTED[dim]
    # no load acts: the reactions of all supports (both meshes) sum to zero
    balance = np.linalg.norm(problem.reaction(supports)) / abs(force[-1])
    quantity = "|sum of all support reactions| / |indenter force|"
    verification(case, quantity, balance, 0.0, DRUM_BALANCE, EQUILIBRIUM, kind="consistency")
    resultants = body_resultants(problem, problem.contact_residual())
    indenter, membrane = resultants[1], resultants[100]
    action = np.linalg.norm(indenter + membrane) / np.linalg.norm(indenter)
    quantity = "|F_indenter + F_membrane| / |F_indenter|"
    verification(case, quantity, action, 0.0, ROUND_OFF, ACTION, kind="consistency")
    slave = np.abs(indenter + problem.contact_force()).max() / abs(force[-1])
    quantity = "|contact resultant on the indenter's dofs - contact force| / |force|"
    source = "the contact force is the resultant of the slave's contact terms"
    verification(case, quantity, slave, 0.0, ROUND_OFF, source, kind="consistency")
    assert balance < DRUM_BALANCE and action < ROUND_OFF and slave < ROUND_OFF


@across_ranks
@pytest.mark.parametrize("dim, n", [(2, 64), (3, 16)])
def test_drumhead_on_any_number_of_ranks(dim, n, verification):
    """The indented drumhead: the same indenter force, largest multiplier and Newton
    iterations on this communicator as on one rank."""
    top = INDENTER_SUPPORTS[dim][0]
    problem, _ = _indented(dim, COMM, n)
    alone, _ = _indented(dim, MPI.COMM_SELF, n)
    (force, lam), (force_1, lam_1) = (_force_and_multiplier(q, top) for q in (problem, alone))
    case = INDENTED[dim]
    difference = np.abs(force - force_1).max() / abs(force_1[-1])
    quantity = f"|F - F_1| / |F_1| on {COMM.size} ranks"
    verification(case, quantity, difference, 0.0, RANKS_FORCE, ONE_RANK, kind="consistency")
    change = abs(lam / lam_1 - 1.0)
    quantity = f"|max lambda_N / its value on 1 rank - 1| on {COMM.size} ranks"
    verification(case, quantity, change, 0.0, RANKS_MULTIPLIER, ONE_RANK, kind="consistency")
    assert difference < RANKS_FORCE and change < RANKS_MULTIPLIER
    iterations = [[s.newton_iterations for s in q.history.steps] for q in (problem, alone)]
    assert iterations[0] == iterations[1]


@pytest.mark.serial  # 2 ranks: test_drumhead_on_any_number_of_ranks
def test_string_drumhead_force_against_the_closed_form(verification):
    """2D: the indenter force is that of a taut string wrapped round a rigid cylinder (the
    module docstring), from the measured position of the indenter's lowest point; the string
    is tensioned beyond its pre-tension, and the straight parts leave the indenter at
    theta."""
    problem, drum = _indented(2, COMM, 64)
    force, _ = _force_and_multiplier(problem, "cylinder_top")
    lowest = drum.gap + lowest_displacement(problem, "cylinder_contact", 1)
    F, theta, T = string_on_cylinder(drum.radius, drum.stretch * drum.a, drum.a, -lowest)
    assert theta > 0.05 and T > analytic.tube_hoop_tension_neo_hookean(MU, T0, drum.stretch)
    case = INDENTED[2]
    error = abs(-force[1] / F - 1.0)
    verification(case, "|indenter force / F - 1|", error, 0.0, STRING_FORCE, STRING)
    # the string's nodes off the indenter lie on the straight tangents
    bulk = problem.bulks[1]
    owned = bulk.V.dofmap.index_map.size_local
    x = bulk.V.tabulate_dof_coordinates()[:owned, :2] + bulk.u.x.array.reshape(-1, 2)[:owned]
    c = drum.stretch * drum.a
    straight = np.abs(x[:, 0]) > drum.radius * np.sin(theta) + 1e-3
    expected = -(c - np.abs(x[straight, 0])) * np.tan(theta)
    off = np.abs(x[straight, 1] - expected).max(initial=0.0)
    off = COMM.allreduce(off, MPI.MAX) / drum.depth
    quantity = "largest distance of the free nodes from the tangents / indentation depth"
    verification(case, quantity, off, 0.0, STRING_TANGENTS, STRING)
    assert error < STRING_FORCE, (force, F)
    assert off < STRING_TANGENTS


@pytest.mark.parametrize("dim", [2, 3])
def test_membrane_pressed_onto_a_block(dim, verification):
    """A membrane pressed by a follower pressure onto a block, both stretched by s = 1.05 in
    their plane (:func:`~contact_ufl.verification.scenes.membrane_on_block`): the contact
    pressure ``lambda_N / (da/dA)`` is the applied pressure at every slave point, the
    nominal multiplier ``p s^(d-1)`` (the exact solution is homogeneous; the multipliers are
    the contact tractions, property (c)). Consistency: the block's bottom carries ``p (s
    a)^(d-1)``, and supports, pressure and contact balance to round-off."""
    p, s, a = 0.01, 1.05, 0.5
    scene = scenes.membrane_on_block(dim=dim, n=4, a=a, stretch=s, pressure=p)
    problem = cu.ContactProblem(scene, verbose=False, petsc_options=TIGHT)
    problem.solve(num_steps=1)
    (c,) = problem.contacts
    assert problem.bulks[c.pair.slave_domain].membrane
    active = c.active()
    assert COMM.allreduce(int(active.sum())) == COMM.allreduce(len(active)) > 0
    case = f"membrane pressed onto a block {dim}D, stretched by 1.05"
    lam = c.multiplier_at_points()
    pressure = lam / c.slave.area_ratio(c.u).ravel()
    pressure = COMM.allreduce(np.abs(pressure / p - 1.0).max(initial=0.0), MPI.MAX)
    quantity = "largest |lambda_N / (da/dA) / p - 1|"
    verification(case, quantity, pressure, 0.0, HOMOGENEOUS_TOLERANCE, HOMOGENEOUS)
    nominal = COMM.allreduce(np.abs(lam / (p * s ** (dim - 1)) - 1.0).max(initial=0.0), MPI.MAX)
    quantity = "largest |lambda_N / (p s^(d-1)) - 1|"
    verification(case, quantity, nominal, 0.0, HOMOGENEOUS_TOLERANCE, HOMOGENEOUS)
    assert pressure < HOMOGENEOUS_TOLERANCE and nominal < HOMOGENEOUS_TOLERANCE
    load = p * (s * a) ** (dim - 1)  # the pressure's resultant on the stretched membrane
    bottom = abs(problem.reaction("block_bottom")[-1] / load - 1.0)
    quantity = "|bottom reaction / (p (s a)^(d-1)) - 1|"
    verification(case, quantity, bottom, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
    edges = ["x0", "xmax", "y0", "ymax"][: 2 * (dim - 1)]
    supports = ["block_bottom", *edges, *(f"block_{e}" for e in edges)]
    error = equilibrium_error(problem, supports)
    quantity = "|supports + pressure| / |pressure|"
    verification(case, quantity, error, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
    resultants = body_resultants(problem, problem.contact_residual())
    membrane, block = resultants[100], resultants[1]
    action = np.linalg.norm(membrane + block) / np.linalg.norm(block)
    quantity = "|F_membrane + F_block| / |F_block|"
    verification(case, quantity, action, 0.0, ROUND_OFF, ACTION, kind="consistency")
    on_block = abs(block[-1] / load - 1.0)
    quantity = "|contact resultant on the block / (p (s a)^(d-1)) - 1|"
    verification(case, quantity, on_block, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
    assert bottom < ROUND_OFF and error < ROUND_OFF
    assert action < ROUND_OFF and on_block < ROUND_OFF


def dragged_string(mu: float, p: float, s: float, a: float, delta: float) -> dict[str, float]:
    """The closed form of the dragged string (module docstring): the end stretch ``l_e``,
    the end tension ``N(l_e)``, the stuck tension ``N(s)`` and the slip front ``X_f``."""

    def N(stretch: float) -> float:
        return MU * T0 * (stretch - stretch**-3)

    def dX(stretch: float) -> float:  # dX/dl in the slip zone
        return MU * T0 * (1.0 + 3.0 * stretch**-4) / (mu * p * stretch)

    def pulled(end: float) -> float:
        return quad(lambda stretch: (stretch - s) * dX(stretch), s, end)[0] - delta

    end = brentq(pulled, s, 2.0 * s, xtol=1e-14)
    length = quad(dX, s, end)[0]
    return {"stretch": end, "tension": N(end), "stuck": N(s), "front": a - length}


def _stick_zone(problem) -> tuple[float, float, float]:
    """``max |lambda_T| / (mu lambda_N)`` over the sticking points in contact, and the
    current x of the outermost sticking and of the innermost slipping point."""
    (c,) = problem.contacts
    friction = c.friction
    active = c.active()
    stick = friction.last_stick & active
    radius = float(friction.mu.value) * c.multiplier_at_points()
    ratio = np.linalg.norm(friction.tangential_multiplier_at_points(), axis=1)[stick]
    ratio = ratio / radius[stick]
    x = c.slave.positions(c.u).reshape(-1, c.gdim)[:, 0]
    return (
        COMM.allreduce(ratio.max(initial=0.0), MPI.MAX),
        COMM.allreduce(x[stick].max(initial=-np.inf), MPI.MAX),
        COMM.allreduce(x[active & ~stick].min(initial=np.inf), MPI.MIN),
    )


def _dragged(dim: int, mu: float, p: float, s: float, a: float, pull: float, n: int, comm=COMM):
    """The dragged strip solved: pressed (one step), then pulled (four steps); the problem,
    the plane and ``(t, CoulombCheck, stick ratio, last stick x, first slip x)`` per step."""
    scene, plane = scenes.membrane_dragged_on_plane(n, a, s, p, pull, mu, dim=dim, comm=comm)
    # to the residual's round-off floor (about 1e-18 here): with TIGHT_STRING's atol a step
    # may stop at a residual of 7e-16, which leaves 1.3e-12 of the load's resultant out of
    # balance (measured on 2 ranks, where MUMPS's round-off differs from run to run)
    options = {**TIGHT_STRING, "snes_atol": 1e-17}
    problem = cu.ContactProblem(scene, verbose=False, petsc_options=options)
    scenes.pretension(problem, s)
    log = []

    def record(problem, step):
        log.append((step.t, coulomb_law(problem), *_stick_zone(problem)))

    problem.solve(num_steps=1, t_end=1.0, callback=record)
    problem.solve(num_steps=4, t_end=2.0, callback=record)
    return problem, plane, log


DRAGGED_CASE = {
    2: "string dragged on a rigid plane 2D, 32 cells, mu = 0.3",
    3: "membrane strip dragged on a rigid plane 3D, 16 x 4 cells, mu = 0.3",
}
#: the Coulomb law at the points, by construction: the two-point Lobatto rule makes the
#: multiplier equations nodal, so a converged solve imposes it at the nodes
NODAL = "the nodal multiplier equations of the converged solve (Lobatto rule)"


@pytest.mark.serial  # 2 ranks: test_dragged_on_any_number_of_ranks
@pytest.mark.parametrize("dim, n", [(2, 32), (3, 16)])
def test_membrane_dragged_on_a_rigid_plane(dim, n, verification):
    """A pre-tensioned string (2D) or membrane strip (3D, held in its plane on its long
    edges), s = 1.02, pressed onto a RigidPlane (mu = 0.3) and pulled by one end
    (:func:`~contact_ufl.verification.scenes.membrane_dragged_on_plane`).

    Pressed, it sticks everywhere. Pulled, it slips near the pulled end and sticks beyond,
    the zone of slip growing with the pull. Consistency: the slipping points are on the
    cone, ``|lambda_T| = mu lambda_N``, to solver tolerance (the two-point Lobatto rule
    makes the multiplier equations nodal, so the P1 multipliers are the traction at the
    nodes; with Gauss points their L2 projection smears the kink at the stick/slip front,
    1.1e-4 measured), and they slip along their tangential traction; the sticking points
    are strictly inside it (``|lambda_T| / (mu lambda_N)`` at most 0.69 in 2D, 0.992 in 3D,
    next to the front); supports, pressure and plane balance to round-off. The closed form
    of the 2D string is checked in :func:`test_string_dragged_against_the_closed_form`."""
    mu, p, s, a, pull = 0.3, 0.01, 1.02, 0.5, 0.002
    problem, plane, log = _dragged(dim, mu, p, s, a, pull, n)
    assert not problem.history.cutbacks
    (_, pressed, *_), *pulled = log
    contact_points = COMM.allreduce(len(problem.contacts[0].active()))
    assert pressed.slipping == 0 and pressed.active == contact_points
    slipping = [check.slipping for _, check, *_ in pulled]
    assert 0 < slipping[0] and all(np.diff(slipping) > 0)
    case = DRAGGED_CASE[dim]
    slip_excess = max(check.slip_excess for _, check, *_ in pulled)
    excess = max(check.excess for _, check, *_ in pulled)
    alignment = min(check.alignment for _, check, *_ in pulled)
    inside = max(r[2] for r in pulled)
    quantity = "largest |mu lambda_N - |lambda_T|| at the slipping points / max mu lambda_N"
    verification(case, quantity, slip_excess, 0.0, CONE, NODAL, kind="consistency")
    quantity = "largest |lambda_T| - mu lambda_N / max mu lambda_N"
    verification(case, quantity, excess, "<= 0", CONE, NODAL, kind="consistency")
    quantity = "1 - smallest cosine of the slip with lambda_T"
    verification(case, quantity, 1.0 - alignment, 0.0, CONE, NODAL, kind="consistency")
    quantity = "largest |lambda_T| / (mu lambda_N) at the sticking points"
    bound = STICK_INSIDE[dim]
    verification(case, quantity, inside, "< 1", bound, NODAL, kind="consistency")
    for _, check, _, last_stick, first_slip in pulled:
        assert 0 < check.slipping < check.active == contact_points
        assert last_stick < first_slip  # one stick zone, then one slip zone to the pulled end
    assert slip_excess < CONE and excess < CONE and 1.0 - alignment < CONE
    assert inside < bound
    edges = ["x0", "xmax", "y0", "ymax"][: 2 * (dim - 1)]
    error = equilibrium_error(problem, edges, [plane])
    quantity = "|supports + plane + pressure| / |pressure|"
    verification(case, quantity, error, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
    assert error < ROUND_OFF


@across_ranks
@pytest.mark.parametrize("dim, n", [(2, 32), (3, 16)])
def test_dragged_on_any_number_of_ranks(dim, n, verification):
    """The dragged string (strip): the same pull force and the same numbers of slipping
    points at every step on this communicator as on one rank."""
    mu, p, s, a, pull = 0.3, 0.01, 1.02, 0.5, 0.002
    problem, _, log = _dragged(dim, mu, p, s, a, pull, n)
    alone, _, log_1 = _dragged(dim, mu, p, s, a, pull, n, MPI.COMM_SELF)
    force, force_1 = problem.reaction("xmax"), alone.reaction("xmax")
    difference = np.abs(force - force_1).max() / abs(force_1[0])
    quantity = f"|F - F_1| / |F_1| of the pull on {COMM.size} ranks"
    verification(
        DRAGGED_CASE[dim], quantity, difference, 0.0, RANKS_PULL, ONE_RANK, kind="consistency"
    )
    assert difference < RANKS_PULL
    assert [r[1].slipping for r in log] == [r[1].slipping for r in log_1]


@pytest.mark.serial  # 2 ranks: test_dragged_on_any_number_of_ranks
def test_string_dragged_against_the_closed_form(verification):
    """2D: the stuck end keeps the pre-tension ``N(s)``, the slip front is that of the
    closed form (module docstring) to within an element, and the pulled end carries
    ``N(l_e)`` less the friction over half a cell, ``mu p l_e h / 2``: the end cells are
    left out of the contact surface, so the node next to the pulled end has half its
    friction (without that term the end tension is 1.7% low)."""
    mu, p, s, a, pull, n = 0.3, 0.01, 1.02, 0.5, 0.002, 32
    problem, _, log = _dragged(2, mu, p, s, a, pull, n)
    exact = dragged_string(mu, p, s, a, pull)
    assert exact["front"] > 0.5 * a and exact["stretch"] > s + 0.01
    case = DRAGGED_CASE[2]
    stuck = abs(-problem.reaction("x0")[0] / exact["stuck"] - 1.0)
    verification(case, "|stuck end's tension / N(s) - 1|", stuck, 0.0, ROUND_OFF, DRAGGED)
    h = a / n
    end = exact["tension"] - mu * p * exact["stretch"] * h / 2.0
    pulled = abs(problem.reaction("xmax")[0] / end - 1.0)
    quantity = "|pulled end's tension / (N(l_e) - mu p l_e h / 2) - 1|"
    verification(case, quantity, pulled, 0.0, DRAGGED_END, DRAGGED)
    _, _, _, last_stick, first_slip = log[-1]
    front = abs(0.5 * (last_stick + first_slip) - s * exact["front"]) / (s * h)
    quantity = "|slip front - closed form| / current cell size"
    verification(case, quantity, front, 0.0, 1.0, DRAGGED)
    assert stuck < ROUND_OFF and pulled < DRAGGED_END and front < 1.0
