"""Rigid obstacles as the master of a contact pair: consistent tangent, Hertz on a rigid
flat, the obstacle's reaction, friction, the same result on any number of ranks, bad input."""

import dataclasses

import dolfinx
import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from conftest import across_ranks, assert_taylor_slopes
from mpi4py import MPI
from test_hertz import hertz_errors

import contact_ufl as cu
from contact_ufl.errors import ContactInputError
from contact_ufl.problem import ContactProblem
from contact_ufl.results import coulomb_law, equilibrium_error
from contact_ufl.verification import scenes
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.taylor_cases import obstacle_case, rotation

#: a rotation about (1, 1, 1) by 0.4 (test_closest_points_on_a_moved_obstacle)
ROT = rotation(0.4 * np.ones(3) / np.sqrt(3.0))


@pytest.mark.parametrize("dim, shape", [(2, "circle"), (3, "cylinder"), (3, "sphere")])
@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_on_a_moving_obstacle(dim, shape, mu):
    """A deformed slave pressed onto a translated and rotated circle (2D), cylinder or
    sphere (3D) and slid over it: second-order remainders, frictionless and in slip (the
    slip reference moved with the obstacle since the last committed step)."""
    problem, dz, steps = obstacle_case(dim, mu=mu, shape=shape)
    c = problem.contacts[0]
    expected = cu.RigidCylinder if shape == "cylinder" else cu.RigidSphere
    assert isinstance(c.pair.master, expected)
    assert c.fields == [c.lambda_N, *([c.friction.lambda_T] if mu else [])]  # no master field
    active = problem.active_points()
    assert active > 10
    if mu:
        assert problem.comm.allreduce(int(c.stick().sum())) == 0  # all in slip
        slip = np.abs(c.friction.slip_at_points()).max(initial=0.0)
        slip = problem.comm.allreduce(slip, op=MPI.MAX)
        assert slip > 1e-3
    assert ufl_numpy_mismatch(problem) < 1e-12
    assert_taylor_slopes(problem, dz, steps)


def test_taylor_detects_a_frozen_obstacle_projection():
    """Freezing the obstacle's normal and projected point leaves a first-order remainder;
    unfreezing it restores the second order."""
    problem, dz, steps = obstacle_case(3, shape="sphere")
    problem.contacts[0].kinematics.frozen_projection = True
    assert_taylor_slopes(problem, dz, steps, slope=1.0, unchanged=False)
    problem.contacts[0].kinematics.frozen_projection = False
    assert_taylor_slopes(problem, dz, steps, unchanged=False)


def ufl_numpy_mismatch(problem) -> float:
    """``|(g, nu)_UFL - (g, nu)_NumPy|`` in L2 over the paired slave points, relative: the
    forms and the results see the same closest points on the moved obstacle."""
    c = problem.contacts[0]
    k, slave = c.kinematics, c.slave
    proj = k.projection
    paired = proj.facet >= 0
    data = dolfinx.fem.Function(slave.point_space((1 + c.gdim,)))
    slave.set_at_points(
        data, np.where(paired[:, None], np.hstack([proj.gap[:, None], proj.normal]), 0)
    )
    exact = ufl.as_vector([k.gap, *[k.nu[i] for i in range(c.gdim)]])
    diff = k.mask * (exact - data)
    values = [
        dolfinx.fem.assemble_scalar(dolfinx.fem.form(f * c.ds, entity_maps=[slave.entity_map]))
        for f in (ufl.dot(diff, diff), k.mask * ufl.dot(data, data))
    ]
    total = problem.comm.allreduce(np.array(values), MPI.SUM)
    return float(np.sqrt(total[0] / total[1]))


@pytest.mark.parametrize(
    "obstacle",
    [
        cu.RigidPlane((0.0, 0.5, 0.0), (1.0, 2.0, 2.0), motion=lambda t: (np.ones(3) * t, ROT)),
        cu.RigidSphere((0.1, 0.2, 0.3), 0.7, motion=lambda t: (np.ones(3) * t, ROT)),
        cu.RigidCylinder((0.1, 0.2, 0.3), (0.0, 1.0, 1.0), 0.7, motion=lambda t: ((t, 0, 0), ROT)),
        cu.RigidSphere((0.1, 0.2), 0.7, motion=lambda t: (t, 2.0 * t)),
    ],
)
def test_closest_points_on_a_moved_obstacle(obstacle):
    """The moved obstacle (rotation about its point, then translation): the closest point y
    of x is on the moved surface, x - y is along the unit outward normal nu, and
    g = -nu . (x - y)."""
    gdim = len(obstacle.reference_point)
    rng = np.random.default_rng(0)
    x = rng.uniform(-2.0, 2.0, (50, gdim))
    p, Q = obstacle.pose(0.5, gdim)
    nu, g, valid = obstacle.closest(x, p, Q)
    assert valid.all()
    y = x + g[:, None] * nu
    assert np.allclose(np.linalg.norm(nu, axis=1), 1.0)
    assert np.allclose(-np.einsum("pd,pd->p", nu, x - y), g)
    # the moved surface: the reference surface mapped by P -> p + Q (P - p0)
    Y = (y - p) @ Q + obstacle.reference_point  # back to the reference position
    if isinstance(obstacle, cu.RigidPlane):
        n0 = np.asarray(obstacle.normal)
        assert np.allclose((Y - obstacle.point) @ n0, 0.0)
        assert np.allclose(nu, Q @ n0 / np.linalg.norm(n0))
    elif isinstance(obstacle, cu.RigidSphere):
        assert np.allclose(np.linalg.norm(Y - obstacle.centre, axis=1), obstacle.radius)
    else:
        a0 = np.asarray(obstacle.axis) / np.linalg.norm(obstacle.axis)
        w = Y - obstacle.point
        assert np.allclose(np.linalg.norm(w - np.outer(w @ a0, a0), axis=1), obstacle.radius)


def test_hertz_on_a_rigid_flat():
    """The half disc of the Hertz scene pressed onto a RigidPlane: a and p0 within 1% of
    Hertz with E* = E / (1 - nu^2) at a/h = 10, as the elastic flat of test_hertz. (Measured
    -0.4% and +0.9%. The depth is half that of test_hertz: with a rigid flat the disc takes
    all the strain, and at the same depth the finite-strain departure from the linear theory
    alone is 1.2%.)"""
    hertz = scenes.hertz_on_rigid_flat(h_contact=0.0035, depth=0.0025)
    problem = ContactProblem(hertz.scene, verbose=False)
    problem.solve(num_steps=4)
    a_err, p0_err, profile_err, exact = hertz_errors(problem, hertz)
    assert exact.a / hertz.h_contact > 8
    assert abs(a_err) < 0.01
    assert abs(p0_err) < 0.01
    assert profile_err < 0.03


def test_obstacle_reaction_balances_the_support():
    """A block clamped at its bottom and pressed by a rigid circle moved down: the reaction
    of the obstacle (its force on the block) is minus the support's reaction.

    This holds by construction: the contact traction is a term of the displacement
    residual, and the sum of the residual over the dofs of a body is the resultant of the
    forces on it (the internal forces sum to zero), so reaction(support) = -(contact force)
    up to the residual of the free dofs (the solver tolerance)."""
    scene, circle = scenes.block_under_circle(n=8, depth=0.05)
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=3)
    R_obstacle = problem.obstacle_reaction(circle)
    R_support = problem.reaction(1)
    assert R_obstacle[1] < -0.01  # the circle pushes the block down
    assert np.allclose(R_obstacle, problem.contact_force(), rtol=0, atol=1e-14)
    assert np.linalg.norm(R_obstacle + R_support) < 1e-9 * np.linalg.norm(R_support)
    assert problem.active_points() > 5
    with pytest.raises(ValueError, match="no contact pair"):
        problem.obstacle_reaction(cu.RigidPlane((0.0, 0.0), (0.0, 1.0)))


def test_block_dragged_on_a_rigid_plane_sticks_then_slips():
    """A block pressed onto a RigidPlane and dragged: it sticks while the tangential force
    is below mu times the normal force, and where it slips |lambda_T| = mu lambda_N (the
    global ratio is then mu: the plane's normal is constant)."""
    mu, push, steps = 0.3, 0.03, 20
    problem = ContactProblem(scenes.pushed_block_on_plane(mu=mu, push=push, nu=0.0), verbose=False)
    log = []

    def record(problem, step):
        force = problem.contact_force()
        c = problem.contacts[0]
        log.append((step.t, abs(force[0]) / force[1], coulomb_law(problem), c.friction))

    problem.solve(num_steps=2, t_end=1.0, callback=record)
    problem.solve(num_steps=steps, t_end=2.0, callback=record)
    plane = problem.scene.contacts[0].master
    assert equilibrium_error(problem, ["lower_bottom", "upper_top"], [plane]) < 1e-8
    assert equilibrium_error(problem, ["lower_bottom", "upper_top"]) > 0.1  # the plane's part
    stuck = [(r, check, f) for t, r, check, f in log if r < 0.5 * mu]
    sliding = [(r, check) for t, r, check, f in log if t > 1.5]
    assert len(stuck) > 2 and sliding
    for _, check, friction in stuck:
        assert check.slipping == 0 and check.active > 40
        assert friction.last_weak_slip < 1e-6 * push / steps
    for ratio, check in sliding:
        assert check.slipping == check.active > 40
        assert check.slip_excess < 1e-10 and check.excess < 1e-10 and check.alignment > 0.999
        assert abs(ratio - mu) < 1e-10


def _slid_block(comm):
    scene, circle = scenes.block_under_circle(n=8, depth=0.04, slide=0.02, mu=0.3, comm=comm)
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=3)
    return problem, circle


@across_ranks
def test_same_result_on_any_number_of_ranks():
    """The frictional circle pressed and slid over the block: the same obstacle reaction and
    Newton iterations on this communicator as on one rank."""
    alone, circle_alone = _slid_block(MPI.COMM_SELF)
    shared, circle = _slid_block(MPI.COMM_WORLD)
    f1, f2 = alone.obstacle_reaction(circle_alone), shared.obstacle_reaction(circle)
    assert abs(f1[0]) > 0.05 * abs(f1[1])  # a real tangential force
    assert np.allclose(f1, f2, rtol=0, atol=1e-9 * np.linalg.norm(f1))
    assert [s.newton_iterations for s in alone.history.steps] == [
        s.newton_iterations for s in shared.history.steps
    ]


@pytest.mark.parametrize(
    "master, message",
    [
        (cu.RigidSphere((0.0, 1.0), 0.0), "radius must be positive"),
        (cu.RigidSphere((0.0, 1.0), -0.5), "radius must be positive"),
        (cu.RigidPlane((0.0, 1.0), (0.0, 0.0)), "normal must be a nonzero vector"),
        (cu.RigidPlane((0.0, 0.0, 1.0), (0.0, 0.0, -1.0)), "must have 2 components in 2D"),
        (cu.RigidCylinder((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), 0.5), "needs a 3D scene"),
        (cu.RigidPlane((0.0, 1.0), (0.0, 1.0)), "never faces its obstacle"),
        (
            cu.RigidPlane((0.0, 1.0), (0.0, -1.0), motion=lambda t: (t, 2 * t, 0.0)),
            "motion",
        ),
    ],
)
def test_bad_obstacles(master, message):
    """A degenerate or misplaced obstacle: a clear error on every rank."""
    scene, _ = scenes.block_under_circle(n=2)
    pair = dataclasses.replace(scene.contacts[0], master=master)
    with pytest.raises(ContactInputError, match=message):
        ContactProblem(dataclasses.replace(scene, contacts=[pair]), verbose=False)


def test_an_obstacle_cannot_be_the_slave():
    scene, circle = scenes.block_under_circle(n=2)
    pair = cu.ContactPair(slave=circle, master=2)
    with pytest.raises(ContactInputError, match="cannot be the slave"):
        ContactProblem(dataclasses.replace(scene, contacts=[pair]), verbose=False)


def test_no_smoothed_normal_on_an_obstacle():
    scene, circle = scenes.block_under_circle(n=2)
    pair = cu.ContactPair(slave=2, master=circle, master_normal="smoothed")
    with pytest.raises(ContactInputError, match="own exact normal"):
        ContactProblem(dataclasses.replace(scene, contacts=[pair]), verbose=False)


@pytest.mark.parametrize("dim", [2, 3])
def test_slip_follows_the_obstacle(dim):
    """A slave body carried along with the obstacle's rigid motion (translation and rotation)
    since the last converged step does not slip on it: zero slip, unchanged gaps."""
    problem, _, _ = obstacle_case(dim, mu=0.05)
    c, solver = problem.contacts[0], problem.solver
    problem.commit(solver.x)
    problem.begin_step()
    gap = c.projection.gap.copy()
    p1, Q1 = c.kinematics.pose
    problem.set_time(1.5)
    p2, Q2 = c.kinematics.pose
    assert np.linalg.norm(Q2 - Q1) > 0.05 and np.linalg.norm(p2 - p1) > 0.005
    # x -> p2 + Q2 Q1^T (x - p1) at the nodes: exact for P1, the map being affine
    X = problem.V.tabulate_dof_coordinates()[:, :dim]
    x = X + problem.u.x.array.reshape(-1, dim)
    problem.u.x.array[:] = (p2 + (x - p1) @ (Q2 @ Q1.T).T - X).ravel()
    dolfinx.fem.petsc.assign(problem.unknowns, solver.x)
    solver.forget_state()
    solver.evaluate_residual(solver.x)
    slip = np.abs(c.friction.slip_at_points()).max(initial=0.0)
    assert problem.comm.allreduce(slip, op=MPI.MAX) < 1e-13
    paired = c.projection.facet >= 0
    assert np.allclose(c.projection.gap[paired], gap[paired], rtol=0, atol=1e-13)
    assert problem.comm.allreduce(int(paired.sum())) > 10


def _cube_scene(master) -> cu.Scene:
    """The unit cube as one body, clamped at z = 0 (tag 1), its top z = 1 (tag 2) the slave
    of a pair with ``master``."""
    mesh = dolfinx.mesh.create_unit_cube(
        MPI.COMM_WORLD, 2, 2, 2, ghost_mode=dolfinx.mesh.GhostMode.shared_facet
    )
    cells, facets = tag_single_body(
        mesh, [lambda x: np.isclose(x[2], 0.0), lambda x: np.isclose(x[2], 1.0)]
    )
    return cu.Scene(
        mesh,
        cells,
        facets,
        [cu.Body(1, cu.NeoHookean(1.0, 0.3))],
        contacts=[cu.ContactPair(2, master)],
        dirichlet=[cu.Dirichlet(1, (0.0, 0.0, 0.0))],
    )


@pytest.mark.parametrize(
    "master, message",
    [
        (cu.RigidCylinder((0.5, 0.5, 2.0), (0.0, 0.0, 0.0), 0.5), "axis must be a nonzero"),
        (cu.RigidCylinder((0.5, 0.5, 2.0), (1.0, 0.0, 0.0), 0.0), "radius must be positive"),
        (cu.RigidCylinder((0.5, 2.0), (1.0, 0.0), 0.5), "must have 3 components in 3D"),
        (cu.RigidSphere((0.5, 0.5, 2.0), -1.0), "radius must be positive"),
        (cu.RigidPlane((0.5, 0.5, 1.5), (0.0, 0.0, 0.0)), "normal must be a nonzero"),
    ],
)
def test_bad_obstacles_in_3d(master, message):
    with pytest.raises(ContactInputError, match=message):
        ContactProblem(_cube_scene(master), verbose=False)


def test_a_cylinder_above_a_cube():
    """The 3D scene of the bad-input cases with a valid cylinder moved down onto the cube:
    it solves, and the obstacle's reaction balances the support's."""
    down = lambda t: (0.0, 0.0, -0.05 * t)  # noqa: E731
    cylinder = cu.RigidCylinder((0.5, 0.5, 1.5), (1.0, 0.0, 0.0), 0.5, motion=down)
    problem = ContactProblem(_cube_scene(cylinder), verbose=False)
    problem.solve(num_steps=2)
    R = problem.obstacle_reaction(cylinder)
    assert R[2] < -1e-3
    assert np.linalg.norm(R + problem.reaction(1)) < 1e-9 * np.linalg.norm(R)


def test_names_resolve_around_an_obstacle():
    """A slave given by physical-group name is resolved; the obstacle master is left as it
    is, and the pair works."""
    scene, circle = scenes.block_under_circle(n=4)
    named = cu.Scene(
        scene.mesh,
        scene.cell_tags,
        scene.facet_tags,
        scene.bodies,
        contacts=[cu.ContactPair("top", circle)],
        dirichlet=[cu.Dirichlet("bottom", (0.0, 0.0))],
        tags={"bottom": 1, "top": 2},
    )
    assert named.contacts[0].slave == 2 and named.contacts[0].master is circle
    problem = ContactProblem(named, verbose=False)
    problem.solve(num_steps=1)
    assert problem.active_points() > 0
