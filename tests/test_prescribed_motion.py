"""Prescribed displacements that vary along the facets (a callable of ``(t, x)``, a
:class:`~contact_ufl.loads.RigidMotion`), verified against exact solutions of finite
elasticity: a homogeneous deformation prescribed on the whole boundary of a hyperelastic
body is its solution (no body force: the stress is uniform, so divergence free), and a rigid
rotation leaves it unstressed (objectivity)."""

import numpy as np
import pytest
from conftest import tagged_unit_square

from contact_ufl.errors import ContactInputError
from contact_ufl.loads import Dirichlet, RigidMotion
from contact_ufl.materials import NeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Scene

pytestmark = pytest.mark.serial  # no contact, no parallel path of its own

MATERIAL = NeoHookean(1.0, 0.3)
SIDES = (1, 2, 3, 4)  # the tags of tagged_unit_square's sides


def square_held_by(value):
    mesh, cells, facets = tagged_unit_square(4)
    supports = [Dirichlet(tag, value) for tag in SIDES]
    return Scene(mesh, cells, facets, [Body(1, MATERIAL)], dirichlet=supports)


def nodal_error(problem, exact):
    """Largest |u - u_exact| over the nodes, u_exact a function of the coordinates."""
    x = problem.V.tabulate_dof_coordinates()[:, :2]
    u = problem.u.x.array.reshape(-1, 2)
    return np.abs(u - exact(x)).max()


def test_a_homogeneous_shear_prescribed_on_the_boundary_is_the_solution(verification):
    gamma = 0.4
    problem = ContactProblem(
        square_held_by(lambda t, x: np.stack([gamma * t * x[:, 1], 0.0 * x[:, 0]], axis=1)),
        verbose=False,
    )
    problem.solve(num_steps=2)
    error = nodal_error(problem, lambda x: np.stack([gamma * x[:, 1], 0.0 * x[:, 0]], axis=1))
    verification(
        "unit square, Neo-Hookean, simple shear gamma = 0.4 on the boundary",
        "largest nodal |u - u_exact|",
        error,
        "u = (gamma y, 0): homogeneous, an exact solution of finite elasticity",
        "< 1e-10",
        "closed form (uniform deformation gradient)",
    )
    assert error < 1e-10


def test_a_rigid_rotation_of_the_boundary_turns_the_body_unstressed(verification):
    angle = 1.2  # radians: a large rotation
    centre = np.array([0.5, 0.5])

    def turn(t):
        a = angle * t
        return (0.0, 0.0), [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]

    problem = ContactProblem(square_held_by(RigidMotion(turn, centre)), verbose=False)
    problem.solve(num_steps=4)
    Q = np.asarray(turn(1.0)[1])
    error = nodal_error(problem, lambda x: (x - centre) @ (Q - np.eye(2)).T)
    energy = problem.stored_energy()
    case = "unit square, Neo-Hookean, boundary turned rigidly by 1.2 rad"
    verification(
        case,
        "largest nodal |u - u_exact|",
        error,
        "u = (Q - I)(x - c): a rigid rotation",
        "< 1e-10",
        "closed form (a rigid motion is an exact, unstressed solution)",
    )
    verification(case, "stored energy", energy, 0.0, "< 1e-16", "objectivity of the energy")
    assert error < 1e-10
    assert abs(energy) < 1e-16


@pytest.mark.parametrize(
    "value, message",
    [
        (lambda t, x: np.zeros((3, 2)), r"must return shape \(2, 2\)"),
        (lambda t, x: np.full((len(x), 2), np.nan), "not finite"),
    ],
)
def test_a_value_of_t_and_x_is_checked_when_the_problem_is_made(value, message):
    with pytest.raises(ContactInputError, match=message):
        ContactProblem(square_held_by(value), verbose=False)
