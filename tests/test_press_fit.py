"""A press fit: two blocks that overlap in the reference configuration, the overlap resolved
in the first step or ramped in over pseudo-time (``ContactPair.overlap_ramp``), verified
against the closed form of two linear elastic blocks in series under uniaxial stress.

The blocks' contact surfaces end where the other's do, and their nodes match: with
non-matching nodes a slave point at the end slides off the master's end as the two widen,
an error of order h (-5e-5 of the force on 4 against 5 cells, half of it on 8 against 10)
that is not the press fit's."""

import dolfinx
import numpy as np
import pytest
from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import LinearElastic
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Domain, Scene
from contact_ufl.verification.geometries import tag_single_body

E, NU = 1.0, 0.3
OVERLAP = 0.02
LOWER, UPPER = 1.0, 0.8  # heights


def block(y0: float, height: float, n: int, name: str, held: int) -> Domain:
    """A unit-wide block on rollers: its left side held along x, the side ``held`` (1 the
    bottom, 2 the top) along y; the other horizontal side (3 - held) is its contact surface."""
    mesh = dolfinx.mesh.create_rectangle(
        MPI.COMM_WORLD, [[0.0, y0], [1.0, y0 + height]], [n, n], dolfinx.mesh.CellType.triangle
    )
    sides = [
        lambda x: np.isclose(x[1], y0),
        lambda x: np.isclose(x[1], y0 + height),
        lambda x: np.isclose(x[0], 0.0),
    ]
    cells, facets = tag_single_body(mesh, sides)
    supports = [Dirichlet(3, 0.0, component=0), Dirichlet(held, 0.0, component=1)]
    material = LinearElastic(E, NU)
    return Domain(mesh, cells, facets, [Body(1, material)], dirichlet=supports, name=name)


def press_fit(ramp=None) -> ContactProblem:
    lower = block(0.0, LOWER, 4, "lower", held=1)
    upper = block(LOWER - OVERLAP, UPPER, 4, "upper", held=2)
    pair = ContactPair(1, 2, slave_domain="upper", master_domain="lower", overlap_ramp=ramp)
    return ContactProblem(Scene(domains=[lower, upper], contacts=[pair]), verbose=False)


def closed_form() -> float:
    """The contact force (per unit thickness) of the blocks in series: uniaxial stress in
    plane strain (sigma_xx = 0), E' = E / (1 - nu^2), shortening the two by the overlap."""
    return E / (1.0 - NU**2) * OVERLAP / (LOWER + UPPER)


def test_the_initial_overlap_is_reported():
    problem = press_fit()
    assert problem.contacts[0].initial_overlap == pytest.approx(OVERLAP, rel=1e-12)


def test_a_press_fit_is_resolved_in_one_step(verification):
    problem = press_fit()
    problem.solve(num_steps=1)
    force = problem.contact_force()[1]
    error = force / closed_form() - 1.0
    verification(
        "press fit of two blocks in series, linear elastic, overlap 0.02",
        "relative error of the contact force, one step",
        error,
        "P = E' delta / (L1 + L2): uniaxial stress in plane strain",
        "|error| < 1e-8",
        "closed form (homogeneous fields)",
    )
    assert abs(error) < 1e-8


def test_a_press_fit_ramped_in_over_pseudo_time(verification):
    """With overlap_ramp=1 the force grows linearly with t (linear elasticity), half the
    final force at t = 0.5, and reaches the closed form at t = 1."""
    problem = press_fit(ramp=1.0)
    forces = []
    problem.solve(num_steps=4, callback=lambda p, record: forces.append(p.contact_force()[1]))
    ratios = np.array(forces) / closed_form()
    case = "press fit of two blocks in series, linear elastic, overlap 0.02"
    verification(
        case,
        "contact force over the closed form at t = 0.25, 0.5, 0.75, 1 (ramped)",
        ratios,
        [0.25, 0.5, 0.75, 1.0],
        "|error| < 1e-8",
        "closed form at the ramped overlap t delta",
    )
    assert ratios == pytest.approx([0.25, 0.5, 0.75, 1.0], abs=1e-8)
