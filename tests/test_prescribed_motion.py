"""Prescribed displacements that vary along the facets (a callable of ``(t, x)``, a
:class:`~contact_ufl.loads.RigidMotion`) and a total force (:class:`~contact_ufl.loads.DeadForce`),
verified against exact solutions: a homogeneous deformation prescribed on the whole boundary
of a hyperelastic body is its solution (no body force: the stress is uniform, so divergence
free), a rigid rotation leaves it unstressed (objectivity), and a force on a side of a square
on rollers stretches it uniformly."""

import numpy as np
import pytest
from conftest import symmetric_square, tagged_unit_square
from mpi4py import MPI

from contact_ufl.errors import ContactInputError
from contact_ufl.loads import DeadForce, Dirichlet, RigidMotion
from contact_ufl.materials import LinearElastic, NeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.results import equilibrium_error
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
    # no load: the supports' reactions balance each other (relative to the largest)
    balance = equilibrium_error(problem, SIDES)
    verification(
        "unit square, Neo-Hookean, simple shear gamma = 0.4 on the boundary",
        "|sum of the reactions| over the largest",
        balance,
        0.0,
        "< 1e-10",
        "equilibrium of the converged solve",
        kind="consistency",
    )
    assert balance < 1e-10


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


def test_a_dead_force_is_spread_over_the_reference_area(verification):
    """A total force P on the right side of the unit square (a DeadForce, per unit
    thickness), held by rollers on the left and bottom: uniaxial stress P / 1 in plane
    strain, so the right side moves by u_x = P (1 - nu^2) / E (linear elasticity, exact for
    the homogeneous field on any mesh); the resultant of the load is P."""
    E, nu, P = 1.0, 0.3, 1e-3
    problem = ContactProblem(
        symmetric_square(LinearElastic(E, nu), [DeadForce(2, lambda t: (P * t, 0.0))], n=3),
        verbose=False,
    )
    problem.solve(num_steps=1)
    x = problem.V.tabulate_dof_coordinates()[:, 0]
    u_x = problem.u.x.array.reshape(-1, 2)[np.isclose(x, 1.0), 0]
    exact = P * (1.0 - nu**2) / E
    error = np.abs(u_x / exact - 1.0).max()
    verification(
        "unit square, linear elastic, total force P on a side",
        "largest relative error of u_x on the loaded side",
        error,
        "u_x = P (1 - nu^2) / E: uniaxial stress in plane strain",
        "< 1e-9",
        "closed form (homogeneous field)",
    )
    assert error < 1e-9
    resultant = problem.load_resultant()
    verification(
        "unit square, linear elastic, total force P on a side",
        "load resultant over P",
        resultant[0] / P,
        1.0,
        "|x - 1| < 1e-12",
        "the load's definition (T = P / A0)",
        kind="consistency",
    )
    assert resultant == pytest.approx([P, 0.0], rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("value", [(1.0, 2.0, 3.0), lambda t: 1.0])
def test_a_dead_load_of_the_wrong_shape_is_refused(value):
    with pytest.raises(ContactInputError, match=r"DeadForce on tag 2: the value is a vector of 2"):
        ContactProblem(symmetric_square(MATERIAL, [DeadForce(2, value)]), verbose=False)


def test_a_rigid_motion_of_the_wrong_dimension_is_named():
    def turn_3d(t):
        return (0.0, 0.0), np.eye(3)

    with pytest.raises(ContactInputError, match=r"pair \(translation, 2x2 rotation\) in 2D"):
        ContactProblem(square_held_by(RigidMotion(turn_3d, (0.5, 0.5))), verbose=False)


def annulus(h: float, theta: float) -> Scene:
    """A linear elastic annulus, radii A < B, clamped at its rim; its hub turned by
    ``theta`` at t = 1 (a RigidMotion about the centre)."""
    import gmsh

    from contact_ufl.gmshio import gmsh_session, read_gmsh

    def turn(t):
        c, s = np.cos(theta * t), np.sin(theta * t)
        return (0.0, 0.0), [[c, -s], [s, c]]

    comm = MPI.COMM_WORLD
    with gmsh_session("annulus", {"Mesh.MeshSizeMax": h}):
        if comm.rank == 0:
            outer = gmsh.model.occ.addDisk(0.0, 0.0, 0.0, B, B)
            inner = gmsh.model.occ.addDisk(0.0, 0.0, 0.0, A, A)
            gmsh.model.occ.cut([(2, outer)], [(2, inner)])
            gmsh.model.occ.synchronize()
            (_, surface), *_ = gmsh.model.getEntities(2)
            curves = [c for _, c in gmsh.model.getBoundary([(2, surface)], oriented=False)]
            length = {c: gmsh.model.occ.getMass(1, c) for c in curves}
            hub = [c for c in curves if abs(length[c] - 2 * np.pi * A) < 1e-9]
            rim = [c for c in curves if abs(length[c] - 2 * np.pi * B) < 1e-9]
            gmsh.model.addPhysicalGroup(2, [surface], name="ring")
            gmsh.model.addPhysicalGroup(1, hub, name="hub")
            gmsh.model.addPhysicalGroup(1, rim, name="rim")
            gmsh.model.mesh.generate(2)
        data = read_gmsh(gmsh.model if comm.rank == 0 else None, comm, gdim=2)
    return Scene.from_mesh_data(
        data,
        bodies=[Body("ring", LinearElastic(1.0, 0.3))],
        dirichlet=[Dirichlet("rim", (0.0, 0.0)), Dirichlet("hub", RigidMotion(turn, (0.0, 0.0)))],
    )


A, B = 0.5, 1.0


def test_the_torque_of_a_turned_hub(verification):
    """The hub of a clamped linear elastic annulus turned by a small angle theta: the
    torque on it (reaction_moment) against the closed form 4 pi G theta A^2 B^2 / (B^2 -
    A^2) (u_theta = C r + D / r, u_r = 0), its error falling under refinement (P1 on the
    polygonal annulus: 4.0e-3 at h = 0.1, 1.3e-3 at h = 0.05), and the rim's torque its
    opposite (to the solver's tolerance)."""
    theta, G = 1e-4, 1.0 / (2.0 * 1.3)
    exact = 4.0 * np.pi * G * theta * A**2 * B**2 / (B**2 - A**2)
    errors, balance = [], []
    for h in (0.1, 0.05):
        problem = ContactProblem(annulus(h, theta), verbose=False)
        problem.solve(num_steps=1)
        hub = problem.reaction_moment("hub", (0.0, 0.0))
        rim = problem.reaction_moment("rim", (0.0, 0.0))
        errors.append(hub / exact - 1.0)
        balance.append(abs(hub + rim) / exact)
    case = "annulus, linear elastic, hub turned by 1e-4 rad, rim clamped"
    verification(
        case,
        "relative error of the hub's torque, h = 0.1 and 0.05",
        errors,
        "T = 4 pi G theta A^2 B^2 / (B^2 - A^2)",
        "|error| < 6e-3, 2e-3",
        "closed form (plane torsion of an annulus)",
    )
    verification(
        case,
        "|hub torque + rim torque| over the closed form",
        balance,
        0.0,
        "< 1e-7",
        "equilibrium of the converged solve",
        kind="consistency",
    )
    assert abs(errors[0]) < 6e-3 and abs(errors[1]) < 2e-3
    assert abs(errors[1]) < 0.5 * abs(errors[0])  # converging
    assert max(balance) < 1e-7
