"""Verification of contact between membranes and solids (issue #11, item 6).

- A stiff solid pressed into a pre-tensioned drumhead (the solid the slave, the membrane the
  two-sided master): the supports of both meshes balance (no load acts: the reactions sum
  to zero to round-off), the contact resultant on the membrane is minus the indenter's
  (property (e)), the same force and largest multiplier on any number of ranks, and in 2D
  the indenter force of the closed form of a taut string wrapped round a rigid cylinder.
- A flat membrane pressed by a follower pressure onto a solid block (the membrane the
  slave), both stretched in their plane: the exact solution is homogeneous, the multipliers
  are the contact tractions (property (c): ``lambda_N / (da/dA) = p``), and supports,
  pressure and contact forces balance to round-off.
- Friction: a pre-tensioned string (a membrane strip in 3D) pressed onto a rigid plane and
  pulled by one end slips near that end with ``|lambda_T| = mu lambda_N`` and sticks
  beyond, strictly inside the cone; the string's end tension and slip front follow the
  closed form below.

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


@pytest.mark.parametrize("dim, n", [(2, 64), (3, 16)])
def test_solid_pressed_into_a_drumhead(dim, n):
    """A stiff indenter (E = 100, the membrane's ``mu t0 = 0.01``) pressed by its top into
    the pre-tensioned drumhead: equilibrium of all supports of both meshes to round-off,
    action and reaction across the meshes (e), and on this communicator the force and
    largest multiplier of one rank."""
    problem, drum = _indented(dim, COMM, n)
    assert not problem.history.cutbacks
    supports = INDENTER_SUPPORTS[dim]
    top = supports[0]
    force, lam = _force_and_multiplier(problem, top)
    assert force[-1] < -1e-5 and problem.active_points() > 10  # the membrane pushes back up
    # no load acts: the reactions of all supports (both meshes) sum to zero
    assert np.linalg.norm(problem.reaction(supports)) < 1e-11 * abs(force[-1])
    resultants = body_resultants(problem, problem.contact_residual())
    indenter, membrane = resultants[1], resultants[100]
    assert np.linalg.norm(indenter + membrane) < 1e-12 * np.linalg.norm(indenter)  # (e)
    assert np.allclose(-indenter, problem.contact_force(), rtol=0.0, atol=1e-12 * abs(force[-1]))
    if COMM.size > 1:
        alone, _ = _indented(dim, MPI.COMM_SELF, n)
        force_1, lam_1 = _force_and_multiplier(alone, top)
        # measured 2e-12 (2D) and 2e-13 (3D) of the force, 1e-14 of the multiplier
        assert np.allclose(force, force_1, rtol=0.0, atol=1e-10 * abs(force[-1]))
        assert abs(lam / lam_1 - 1.0) < 1e-10
        iterations = [[s.newton_iterations for s in q.history.steps] for q in (problem, alone)]
        assert iterations[0] == iterations[1]


def test_string_drumhead_force_against_the_closed_form():
    """2D: the indenter force is that of a taut string wrapped round a rigid cylinder (the
    module docstring), from the measured position of the indenter's lowest point, within
    0.1% (measured 6e-5; 0.13% with half as many string elements); the string is tensioned
    beyond its pre-tension, and the straight parts leave the indenter at theta."""
    problem, drum = _indented(2, COMM, 64)
    force, _ = _force_and_multiplier(problem, "cylinder_top")
    lowest = drum.gap + lowest_displacement(problem, "cylinder_contact", 1)
    F, theta, T = string_on_cylinder(drum.radius, drum.stretch * drum.a, drum.a, -lowest)
    assert theta > 0.05 and T > analytic.tube_hoop_tension_neo_hookean(MU, T0, drum.stretch)
    assert abs(-force[1] / F - 1.0) < 1e-3, (force, F)
    # the string's nodes off the indenter lie on the straight tangents
    bulk = problem.bulks[1]
    owned = bulk.V.dofmap.index_map.size_local
    x = bulk.V.tabulate_dof_coordinates()[:owned, :2] + bulk.u.x.array.reshape(-1, 2)[:owned]
    c = drum.stretch * drum.a
    straight = np.abs(x[:, 0]) > drum.radius * np.sin(theta) + 1e-3
    expected = -(c - np.abs(x[straight, 0])) * np.tan(theta)
    error = np.abs(x[straight, 1] - expected).max(initial=0.0)
    assert COMM.allreduce(error, MPI.MAX) < 1e-3 * drum.depth


@pytest.mark.parametrize("dim", [2, 3])
def test_membrane_pressed_onto_a_block(dim):
    """A membrane pressed by a follower pressure onto a block, both stretched by s = 1.05 in
    their plane (:func:`~contact_ufl.verification.scenes.membrane_on_block`): the contact
    pressure ``lambda_N / (da/dA)`` is the applied pressure at every slave point, the
    nominal multiplier ``p s^(d-1)``, the block's bottom carries ``p (s a)^(d-1)``, and
    supports, pressure and contact balance to round-off (the multipliers are the contact
    tractions: property (c))."""
    p, s, a = 0.01, 1.05, 0.5
    scene = scenes.membrane_on_block(dim=dim, n=4, a=a, stretch=s, pressure=p)
    problem = cu.ContactProblem(scene, verbose=False, petsc_options=TIGHT)
    problem.solve(num_steps=1)
    (c,) = problem.contacts
    assert problem.bulks[c.pair.slave_domain].membrane
    active = c.active()
    assert COMM.allreduce(int(active.sum())) == COMM.allreduce(len(active)) > 0
    lam = c.multiplier_at_points()
    pressure = lam / c.slave.area_ratio(c.u).ravel()
    assert COMM.allreduce(np.abs(pressure / p - 1.0).max(initial=0.0), MPI.MAX) < 1e-12
    assert (
        COMM.allreduce(np.abs(lam / (p * s ** (dim - 1)) - 1.0).max(initial=0.0), MPI.MAX) < 1e-12
    )
    bottom = problem.reaction("block_bottom")
    assert abs(bottom[-1] / (p * (s * a) ** (dim - 1)) - 1.0) < 1e-12
    edges = ["x0", "xmax", "y0", "ymax"][: 2 * (dim - 1)]
    supports = ["block_bottom", *edges, *(f"block_{e}" for e in edges)]
    assert equilibrium_error(problem, supports) < 1e-12
    resultants = body_resultants(problem, problem.contact_residual())
    membrane, block = resultants[100], resultants[1]
    assert np.linalg.norm(membrane + block) < 1e-12 * np.linalg.norm(block)  # (e)
    assert abs(block[-1] / (p * (s * a) ** (dim - 1)) - 1.0) < 1e-12


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


@pytest.mark.parametrize("dim, n", [(2, 32), (3, 16)])
def test_membrane_dragged_on_a_rigid_plane(dim, n):
    """A pre-tensioned string (2D) or membrane strip (3D, held in its plane on its long
    edges), s = 1.02, pressed onto a RigidPlane (mu = 0.3) and pulled by one end
    (:func:`~contact_ufl.verification.scenes.membrane_dragged_on_plane`).

    Pressed, it sticks everywhere. Pulled, it slips near the pulled end and sticks beyond,
    the zone of slip growing with the pull: the slipping points are on the cone,
    ``|lambda_T| = mu lambda_N``, to solver tolerance (measured 1.4e-16 in 2D, 1.2e-12 in
    3D, of ``max mu lambda_N``: the two-point Lobatto rule makes the multiplier equations
    nodal, so the P1 multipliers are the traction at the nodes; with Gauss points their L2
    projection smears the kink at the stick/slip front, 1.1e-4 measured), and they slip
    along their tangential traction; the sticking points are strictly inside it
    (``|lambda_T| / (mu lambda_N)`` at most 0.69 in 2D, 0.992 in 3D, next to the front).
    Supports, pressure and plane balance to round-off; the same pull force and the same
    slipping points on any number of ranks."""
    mu, p, s, a, pull = 0.3, 0.01, 1.02, 0.5, 0.002
    problem, plane, log = _dragged(dim, mu, p, s, a, pull, n)
    assert not problem.history.cutbacks
    (_, pressed, *_), *pulled = log
    contact_points = COMM.allreduce(len(problem.contacts[0].active()))
    assert pressed.slipping == 0 and pressed.active == contact_points
    slipping = [check.slipping for _, check, *_ in pulled]
    assert 0 < slipping[0] and all(np.diff(slipping) > 0)
    for _, check, inside, last_stick, first_slip in pulled:
        assert 0 < check.slipping < check.active == contact_points
        assert check.slip_excess < 1e-10 and check.excess < 1e-10
        assert check.alignment > 1.0 - 1e-10
        assert inside < 1.0 - 1e-6
        assert last_stick < first_slip  # one stick zone, then one slip zone to the pulled end
    edges = ["x0", "xmax", "y0", "ymax"][: 2 * (dim - 1)]
    assert equilibrium_error(problem, edges, [plane]) < 1e-12
    if COMM.size > 1:  # the same pull force and stick/slip states on one rank
        alone, _, log_1 = _dragged(dim, mu, p, s, a, pull, n, MPI.COMM_SELF)
        force, force_1 = problem.reaction("xmax"), alone.reaction("xmax")
        assert np.allclose(force, force_1, rtol=0.0, atol=1e-10 * abs(force[0]))
        assert [r[1].slipping for r in log] == [r[1].slipping for r in log_1]


def test_string_dragged_against_the_closed_form():
    """2D: the stuck end keeps the pre-tension ``N(s)``, the slip front is that of the
    closed form (module docstring) to within an element, and the pulled end's tension
    ``N(l_e)`` within 2%: the end cells are left out of the contact surface, and the
    friction missing over half a cell, ``mu p s h / 2``, is 1.6% of it (measured -1.7%)."""
    mu, p, s, a, pull, n = 0.3, 0.01, 1.02, 0.5, 0.002, 32
    problem, _, log = _dragged(2, mu, p, s, a, pull, n)
    exact = dragged_string(mu, p, s, a, pull)
    assert exact["front"] > 0.5 * a and exact["stretch"] > s + 0.01
    assert np.isclose(-problem.reaction("x0")[0], exact["stuck"], rtol=1e-10)
    assert abs(problem.reaction("xmax")[0] / exact["tension"] - 1.0) < 0.02
    h = s * a / n
    _, _, _, last_stick, first_slip = log[-1]
    assert abs(0.5 * (last_stick + first_slip) - s * exact["front"]) < h
