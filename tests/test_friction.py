"""Coulomb friction: consistent tangent in stick and in slip, friction only where mu > 0."""

import dataclasses

import numpy as np
import pytest
from conftest import assert_taylor_slopes
from mpi4py import MPI

from contact_ufl.contact.coulomb import CoulombLaw
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes
from contact_ufl.verification.scenes import curved_pair
from contact_ufl.verification.taylor_cases import curved_case


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("mu, state", [(0.3, "slip"), (100.0, "stick")])
def test_frictional_taylor_second_order(dim, mu, state):
    problem, dz, steps = curved_case(dim, mu=mu)
    c = problem.contacts[0]
    active = problem.comm.allreduce(int(c.active().sum()))
    stick = problem.comm.allreduce(int(c.stick().sum()))
    assert active > 10
    assert stick == (active if state == "stick" else 0)
    assert_taylor_slopes(problem, dz, steps)


def test_friction_unknowns_only_with_mu():
    scene = curved_pair(2)
    frictionless = ContactProblem(scene, verbose=False)
    assert len(frictionless.unknowns) == 2  # u, lambda_N
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], mu=0.3)
    frictional = ContactProblem(scene, verbose=False)
    assert isinstance(frictional.contacts[0].friction, CoulombLaw)
    assert frictionless.contacts[0].friction is None
    assert len(frictional.unknowns) == 3  # u, lambda_N, lambda_T
    assert frictional.layout.global_size > frictionless.layout.global_size


def test_no_nan_where_q_vanishes():
    """lambda_T = 0 and no slip: q = 0 at every point, the residual and tangent are finite."""
    problem, _, _ = curved_case(2, mu=0.3)
    c = problem.contacts[0]
    c.friction.lambda_T.x.array[:] = 0.0
    c.friction.mask_n.x.array[:] = 0.0  # no slip history
    solver = problem.solver
    solver.forget_state()
    import dolfinx.fem.petsc

    dolfinx.fem.petsc.assign(problem.unknowns, solver.x)
    R = solver.evaluate_residual(solver.x)
    J = solver.evaluate_jacobian(solver.x)
    assert np.isfinite(R.norm()) and np.isfinite(J.norm())


def test_block_sticks_then_slides():
    """A block pressed on a flat and pushed: stuck while the tangential force is below
    mu N (no slip, in the weak sense of the multiplier equation), sliding above it (every
    contact point slips, against the frictional traction on the slave body). The weak
    slip of the stuck steps stays below 1e-6 of the step's push (2e-7 measured)."""
    mu, push, steps = 0.3, 0.03, 10
    problem = ContactProblem(scenes.pushed_block(mu=mu, push=push), verbose=False)
    c = problem.contacts[0]
    log = []

    def record(problem, step):
        active = c.active()
        power = np.einsum(
            "pd,pd->p",
            c.friction.traction_at_points(c.normal_traction_at_points()),
            c.friction.last_slip,
        )[active]
        friction = problem.comm.allreduce(
            float(
                np.sum(
                    np.einsum(
                        "pd,pd->p", c.friction.last_slip[active], c.friction.last_slip[active]
                    )
                )
            )
        )
        log.append(
            dict(
                t=step.t,
                ratio=abs(step.contact_force[0]) / step.contact_force[1],
                active=problem.comm.allreduce(int(active.sum())),
                stick=problem.comm.allreduce(int((c.friction.last_stick & active).sum())),
                weak_slip=c.friction.last_weak_slip,
                slip2=friction,
                # the frictional traction on the slave body against its slip
                power=problem.comm.allreduce(float(np.max(power, initial=-np.inf)), op=MPI.MAX),
            )
        )

    problem.solve(num_steps=2, t_end=1.0, callback=record)
    problem.solve(num_steps=steps, t_end=2.0, callback=record)
    increment = push / steps
    stuck = [r for r in log if r["t"] > 1.0 and r["ratio"] < 0.5 * mu]
    sliding = [r for r in log if r["t"] > 1.75]
    assert stuck and sliding
    for r in stuck:
        assert r["stick"] == r["active"] > 0
        assert r["weak_slip"] < 1e-6 * increment
    for r in log:
        assert r["ratio"] <= mu * (1.0 + 1e-8)
    for r in sliding:
        assert r["stick"] == 0 and r["active"] > 0
        assert np.sqrt(r["slip2"]) > 0.1 * increment
        assert r["power"] < 0.0


def test_objectivity_under_a_large_rotation():
    """Rotating the whole frictional scene by 70 degrees rotates the contact force and leaves
    the Newton iterations unchanged. (The bodies start apart: a point starting exactly at
    g = 0 with lambda_N = 0 sits on the kink of the bracket, where round-off alone may pick
    the Newton path.)"""
    angle = np.deg2rad(70.0)
    runs = []
    for rotation in (0.0, angle):
        hertz = scenes.hertz_2d(
            h_contact=0.01, depth=0.006, gap=0.001, mu=0.3, shift=0.0015, rotation=rotation
        )
        problem = ContactProblem(hertz.scene, verbose=False)
        problem.solve(num_steps=2, t_end=1.0)
        problem.solve(num_steps=3, t_end=2.0)
        runs.append(problem)
    reference, rotated = runs
    R = scenes.rotation_2d(angle)
    f0, f1 = reference.contact_force(), rotated.contact_force()
    assert abs(f0[0]) > 0.1 * abs(f0[1])  # a real tangential load
    assert np.allclose(R @ f0, f1, rtol=0, atol=1e-8 * np.linalg.norm(f0))
    assert [s.newton_iterations for s in reference.history.steps] == [
        s.newton_iterations for s in rotated.history.steps
    ]


def test_pressed_from_touching_sticks_on_any_number_of_ranks():
    """The block of ``scenes.pushed_block`` pressed from touching (g = 0, lambda = 0, no
    slip: every point on the kink of the bracket and at the centre of a disc of radius 0):
    every point sticks from the first iterate on, 3 Newton iterations, on this
    communicator as on one rank. When round-off chose stick or slip there, the first step
    took 8 iterations on one rank and 32 on two (25 of them cycling)."""

    def pressed(comm):
        problem = ContactProblem(scenes.pushed_block(push=0.3, comm=comm), verbose=False)
        problem.solve(num_steps=1, t_end=0.5)
        c = problem.contacts[0]
        counts = np.array([c.active().sum(), c.stick().sum()])
        return problem.history.steps[0].newton_iterations, problem.comm.allreduce(counts)

    its, (active, stick) = pressed(MPI.COMM_WORLD)
    assert its == 3 and active > 50 and stick == active
    if MPI.COMM_WORLD.size > 1:
        assert pressed(MPI.COMM_SELF)[0] == its


def test_points_beyond_the_master_surface_are_released():
    """The pushed block slides past the end of the lower block: its overhanging part is not
    in contact (the last master facet is not an infinite line)."""
    problem = ContactProblem(scenes.pushed_block(push=0.3), verbose=False)
    problem.solve(num_steps=2, t_end=1.0)
    problem.solve(num_steps=10, t_end=2.0)
    c = problem.contacts[0]
    x = c.slave.positions(problem.u).reshape(-1, 2)[:, 0]
    end = c.master.current_nodes()[..., 0].max(initial=-np.inf)
    end = problem.comm.allreduce(end, op=MPI.MAX)
    overhang = x > end + 1e-9
    assert problem.comm.allreduce(int(overhang.sum())) > 0
    assert problem.comm.allreduce(int((c.active() & overhang).sum())) == 0
    assert problem.comm.allreduce(int(c.active().sum())) > 20
