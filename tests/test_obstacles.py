"""Rigid obstacles as the master of a contact pair: consistent tangent, Hertz on a rigid
flat, the obstacle's reaction, friction, the same result on any number of ranks, bad input."""

import dataclasses
import functools

import dolfinx
import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from conftest import across_ranks
from mpi4py import MPI
from test_friction import check_slopes
from test_hertz import JOHNSON, PROFILE, hertz_errors

import contact_ufl as cu
from contact_ufl.errors import ContactInputError
from contact_ufl.problem import ContactProblem
from contact_ufl.results import coulomb_law, equilibrium_error
from contact_ufl.taylor import taylor_test
from contact_ufl.verification import scenes
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.taylor_cases import obstacle_case, rotation

#: a rotation about (1, 1, 1) by 0.4 (test_closest_points_on_a_moved_obstacle)
ROT = rotation(0.4 * np.ones(3) / np.sqrt(3.0))

COULOMB = "Coulomb's law (theory, property (d)): stick below mu lambda_N, slip against the traction"
EQUILIBRIUM = "equilibrium of the converged solve (supports, loads and obstacles balance)"


@pytest.mark.parametrize("dim, shape", [(2, "circle"), (3, "cylinder"), (3, "sphere")])
@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_on_a_moving_obstacle(dim, shape, mu, verification):
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
    case = f"Taylor test {dim}D, deformed slave on a moving rigid {shape}, mu = {mu:g}"
    mismatch = ufl_numpy_mismatch(problem)
    quantity = "relative L2 distance of (g, nu) of the forms and of NumPy"
    source = "the forms' and the search's closest points (two implementations here)"
    verification(case, quantity, mismatch, 0.0, "< 1e-15", source, kind="consistency")
    assert mismatch < 1e-15
    check_slopes(verification, case, taylor_test(problem, dz, steps), tol=5e-5)


def test_taylor_detects_a_frozen_obstacle_projection(verification):
    """Freezing the obstacle's normal and projected point leaves a first-order remainder;
    unfreezing it restores the second order."""
    problem, dz, steps = obstacle_case(3, shape="sphere")
    problem.contacts[0].kinematics.frozen_projection = True
    frozen = taylor_test(problem, dz, steps)
    case = "Taylor test 3D, moving rigid sphere, projection's variation dropped (on purpose)"
    source = "Taylor's theorem: an inexact derivative leaves an O(h) remainder"
    quantity = "slopes of the Taylor remainder |R1(h)|"
    verification(case, quantity, frozen.slopes, 1.0, "|slope - reference| < 5e-5", source)
    assert np.all(np.abs(frozen.slopes - 1.0) < 5e-5), frozen.slopes
    problem.contacts[0].kinematics.frozen_projection = False
    exact = taylor_test(problem, dz, steps)
    check_slopes(verification, "Taylor test 3D, moving rigid sphere, mu = 0", exact, tol=5e-5)


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
def test_closest_points_on_a_moved_obstacle(obstacle, verification):
    """The moved obstacle (rotation about its point, then translation): the point
    y = x + g nu returned for x lies on the moved surface, and nu is the surface's unit
    outward normal at y (the closest point of a convex surface), to round-off (1e-14;
    7e-16 measured)."""
    gdim = len(obstacle.reference_point)
    rng = np.random.default_rng(0)
    x = rng.uniform(-2.0, 2.0, (50, gdim))
    p, Q = obstacle.pose(0.5, gdim)
    nu, g, valid = obstacle.closest(x, p, Q)
    assert valid.all()
    y = x + g[:, None] * nu
    # the moved surface: the reference surface mapped by P -> p + Q (P - p0)
    Y = (y - p) @ Q + obstacle.reference_point  # back to the reference position
    if isinstance(obstacle, cu.RigidPlane):
        n0 = np.asarray(obstacle.normal) / np.linalg.norm(obstacle.normal)
        off = (Y - obstacle.point) @ n0
        normal = np.tile(n0, (len(Y), 1))
    elif isinstance(obstacle, cu.RigidSphere):
        radial = Y - obstacle.centre
        off = np.linalg.norm(radial, axis=1) - obstacle.radius
        normal = radial / np.linalg.norm(radial, axis=1, keepdims=True)
    else:
        a0 = np.asarray(obstacle.axis) / np.linalg.norm(obstacle.axis)
        w = Y - obstacle.point
        radial = w - np.outer(w @ a0, a0)
        off = np.linalg.norm(radial, axis=1) - obstacle.radius
        normal = radial / np.linalg.norm(radial, axis=1, keepdims=True)
    errors = [np.abs(off).max(), np.abs(nu - normal @ Q.T).max()]
    case = f"closest points on a moved {type(obstacle).__name__} ({gdim}D), 50 random points"
    source = "the obstacle's geometry, closed form"
    for quantity, error in zip(
        ("largest distance of y from the moved surface", "largest |nu - surface normal at y|"),
        errors,
        strict=True,
    ):
        verification(case, quantity, error, 0.0, "< 1e-14", source)
    assert errors[0] < 1e-14 and errors[1] < 1e-14


@pytest.mark.serial  # on 2 ranks: this file's rank comparisons
def test_hertz_on_a_rigid_flat(verification):
    """The half disc of the Hertz scene pressed onto a RigidPlane: a and p0 within 1% of
    Hertz with E* = E / (1 - nu^2) at a/h = 10, as the elastic flat of test_hertz, and the
    profile within 2% of p0. (Measured -0.4%, +0.9% and 0.9%. The depth is half that of
    test_hertz: with a rigid flat the disc takes all the strain, and at the same depth the
    finite-strain departure from the linear theory alone is 1.2%.)"""
    hertz = scenes.hertz_on_rigid_flat(h_contact=0.0035, depth=0.0025)
    problem = ContactProblem(hertz.scene, verbose=False)
    problem.solve(num_steps=4)
    a_err, p0_err, profile_err, exact = hertz_errors(problem, hertz)
    case = "Hertz 2D on a RigidPlane, Neo-Hookean, 4 load steps, a/h = 10"
    for quantity, error, reference, tolerance in (
        ("relative error of the half-width", a_err, "a = sqrt(4 P R / (pi E*))", "|error| < 0.01"),
        ("relative error of the peak pressure", p0_err, "p0 = 2 P / (pi a)", "|error| < 0.01"),
        ("RMS pressure error in |x| < 0.8 a, over p0", profile_err, PROFILE, "< 0.02"),
    ):
        verification(case, quantity, error, reference, tolerance, JOHNSON)
    assert exact.a / hertz.h_contact > 8
    assert abs(a_err) < 0.01
    assert abs(p0_err) < 0.01
    assert profile_err < 0.02


def test_obstacle_reaction_balances_the_support(verification):
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
    case = "block clamped at its bottom, pressed by a rigid circle"
    same = np.abs(R_obstacle - problem.contact_force()).max()
    imbalance = np.linalg.norm(R_obstacle + R_support) / np.linalg.norm(R_support)
    quantity = "largest |obstacle reaction - contact force|"
    source = "the obstacle's reaction is the contact force (the same integral)"
    verification(case, quantity, same, 0.0, "< 1e-14", source, kind="consistency")
    quantity = "|obstacle reaction + support reaction| / |support reaction|"
    verification(case, quantity, imbalance, 0.0, "< 1e-9", EQUILIBRIUM, kind="consistency")
    assert same < 1e-14
    assert imbalance < 1e-9
    assert problem.active_points() > 5
    with pytest.raises(ValueError, match="no contact pair"):
        problem.obstacle_reaction(cu.RigidPlane((0.0, 0.0), (0.0, 1.0)))


@pytest.mark.serial  # on 2 ranks: this file's rank comparisons
def test_block_dragged_on_a_rigid_plane_sticks_then_slips(verification):
    """A block pressed onto a RigidPlane and dragged: it sticks while the tangential force
    is below mu times the normal force, and where it slips |lambda_T| = mu lambda_N (the
    global ratio is then mu: the plane's normal is constant)."""
    mu, push, steps = 0.3, 0.03, 20
    problem = ContactProblem(scenes.pushed_block_on_plane(mu=mu, push=push, nu=0.0), verbose=False)
    log = []

    def record(problem, step):
        force = problem.contact_force()
        c = problem.contacts[0]
        weak_slip = c.friction.last_weak_slip  # of this step
        log.append((step.t, abs(force[0]) / force[1], coulomb_law(problem), weak_slip))

    problem.solve(num_steps=2, t_end=1.0, callback=record)
    problem.solve(num_steps=steps, t_end=2.0, callback=record)
    plane = problem.scene.contacts[0].master
    supports = ["lower_bottom", "upper_top"]
    imbalance = equilibrium_error(problem, supports, [plane])
    assert equilibrium_error(problem, supports) > 0.1  # the plane's part
    stuck = [(r, check, w) for t, r, check, w in log if r < 0.5 * mu]
    sliding = [(r, check) for t, r, check, _ in log if t > 1.5]
    assert len(stuck) > 2 and sliding
    case = "block dragged on a RigidPlane, mu = 0.3"
    weak_slip = max(w for _, _, w in stuck) / (push / steps)
    excess = max(check.slip_excess for _, check in sliding)  # every point slips
    alignment = min(check.alignment for _, check in sliding)
    ratio_error = max(abs(ratio - mu) for ratio, _ in sliding)
    note = functools.partial(verification, case)
    note("|reactions + loads| / |loads|", imbalance, 0.0, "< 1e-9", EQUILIBRIUM, kind="consistency")
    note(
        "largest weak slip of the stuck steps, over the step's drag",
        weak_slip,
        0.0,
        "< 1e-7",
        COULOMB,
        kind="consistency",
    )
    note(
        "largest ||lambda_T| - mu lambda_N| / max mu lambda_N, t > 1.5",
        excess,
        0.0,
        "< 1e-14",
        COULOMB,
        kind="consistency",
    )
    note("smallest cosine of lambda_T and the slip, t > 1.5", alignment, 1.0, "> 0.999", COULOMB)
    note(
        "largest ||Fx| / Fy - mu|, t > 1.5",
        ratio_error,
        0.0,
        "< 1e-14",
        "Coulomb's law under full slip on a flat: |Fx| / Fy = mu",
        kind="consistency",
    )
    assert imbalance < 1e-9  # SNES's rtol (4e-15 measured)
    for _, check, slip in stuck:
        assert check.slipping == 0 and check.active > 40
        # the stick equations' residual, SNES's tolerance (2e-14 here, 5e-8 in test_friction)
        assert slip < 1e-7 * push / steps
    for ratio, check in sliding:
        assert check.slipping == check.active > 40
        # round-off: the plane's constant normal and a uniform slip (3e-16 measured)
        assert check.slip_excess < 1e-14 and check.excess < 1e-14 and check.alignment > 0.999
        assert abs(ratio - mu) < 1e-14


def _slid_block(comm):
    scene, circle = scenes.block_under_circle(n=8, depth=0.04, slide=0.02, mu=0.3, comm=comm)
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=3)
    return problem, circle


@across_ranks
def test_same_result_on_any_number_of_ranks(verification):
    """The frictional circle pressed and slid over the block: the same obstacle reaction and
    Newton iterations on this communicator as on one rank."""
    alone, circle_alone = _slid_block(MPI.COMM_SELF)
    shared, circle = _slid_block(MPI.COMM_WORLD)
    f1, f2 = alone.obstacle_reaction(circle_alone), shared.obstacle_reaction(circle)
    assert abs(f1[0]) > 0.05 * abs(f1[1])  # a real tangential force
    difference = np.abs(f1 - f2).max() / np.linalg.norm(f1)
    case = f"block under a rigid circle pressed and slid, mu = 0.3, {shared.comm.size} ranks"
    quantity = "largest |obstacle reaction difference| over |reaction|"
    source = "the same run on one rank"
    verification(case, quantity, difference, 0.0, "< 1e-9", source, kind="consistency")
    assert difference < 1e-9
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


@pytest.mark.serial  # on 2 ranks: this file's rank comparisons
@pytest.mark.parametrize("dim", [2, 3])
def test_slip_follows_the_obstacle(dim, verification):
    """A slave body carried along with the obstacle's rigid motion (translation and rotation)
    since the last converged step does not slip on it: zero slip, unchanged gaps."""
    problem, _, _ = obstacle_case(dim, mu=0.05)
    c, operator = problem.contacts[0], problem.operator
    problem.commit(operator.x)
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
    dolfinx.fem.petsc.assign(problem.unknowns, operator.x)
    operator.forget_state()
    operator.evaluate_residual(operator.x)
    slip = np.abs(c.friction.slip_at_points()).max(initial=0.0)
    slip = problem.comm.allreduce(slip, op=MPI.MAX)
    paired = c.projection.facet >= 0
    change = np.abs(c.projection.gap[paired] - gap[paired]).max(initial=0.0)
    change = problem.comm.allreduce(change, op=MPI.MAX)
    case = f"slave carried along with a moving rigid obstacle ({dim}D)"
    source = "a rigid motion of both bodies changes no gap and makes no slip (objectivity)"
    verification(case, "largest |slip|", slip, 0.0, "< 1e-14", source)
    verification(case, "largest change of the gap", change, 0.0, "< 1e-14", source)
    assert slip < 1e-14
    assert change < 1e-14
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


def test_a_cylinder_above_a_cube(verification):
    """The 3D scene of the bad-input cases with a valid cylinder moved down onto the cube:
    it solves, and the obstacle's reaction balances the support's."""
    down = lambda t: (0.0, 0.0, -0.05 * t)  # noqa: E731
    cylinder = cu.RigidCylinder((0.5, 0.5, 1.5), (1.0, 0.0, 0.0), 0.5, motion=down)
    problem = ContactProblem(_cube_scene(cylinder), verbose=False)
    problem.solve(num_steps=2)
    R = problem.obstacle_reaction(cylinder)
    assert R[2] < -1e-3
    imbalance = np.linalg.norm(R + problem.reaction(1)) / np.linalg.norm(R)
    case = "unit cube clamped at its bottom, pressed by a rigid cylinder"
    quantity = "|obstacle reaction + support reaction| / |obstacle reaction|"
    verification(case, quantity, imbalance, 0.0, "< 1e-9", EQUILIBRIUM, kind="consistency")
    assert imbalance < 1e-9


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
