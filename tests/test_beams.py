"""The two-beam showcase: beam theory at small load, global equilibrium, the Coulomb law,
friction that changes the result, and independence of the number of ranks."""

import numpy as np
import pytest
from mpi4py import MPI

from contact_ufl.problem import ContactProblem
from contact_ufl.results import coulomb_law, equilibrium_error, section_motion
from contact_ufl.verification import geometries, scenes

SUPPORTS = ["upper_clamp", "lower_clamp"]
#: a small gap: contact starts long before large rotations
NEAR = geometries.BeamPair(gap=0.1, lower_length=10.0)


def solve_near_pair(load: float, comm=MPI.COMM_WORLD):
    beams = scenes.beams(load=load, divisions=3, geometry=NEAR, comm=comm)
    problem = ContactProblem(beams.scene, verbose=False)
    problem.solve(num_steps=3)
    return problem, beams


@pytest.fixture(scope="module")
def showcase():
    """The demo's scene (divisions 3, load 3 EI/L^2) without and with friction, and the
    Coulomb check of every converged frictional step."""
    runs, checks = {}, []
    for mu in (0.0, 0.3):
        beams = scenes.beams(mu=mu, divisions=3, load=3.0)
        problem = ContactProblem(beams.scene, verbose=False)

        def record(problem, step, mu=mu):
            if mu > 0:
                checks.append(coulomb_law(problem))

        problem.solve(num_steps=20, callback=record)
        runs[mu] = problem
    return runs, checks


def test_two_cantilevers_in_series():
    """At small load the pair acts as two springs in series (beam theory, within 5%)."""
    problem, beams = solve_near_pair(load=0.12)
    P = beams.load * beams.bending_stiffness / NEAR.length**2
    N, w = beams.two_springs(P)
    assert N > 0.5 * P  # well into contact
    force = problem.contact_force()
    u_tip, n_tip = section_motion(problem, beams.scene.tags["upper_tip"])
    assert abs(force[2] / N - 1.0) < 0.05, (force, N)
    assert abs(-u_tip[2] / w - 1.0) < 0.05, (u_tip, w)
    assert np.degrees(np.arccos(abs(n_tip[0]))) < 3.0  # small rotations


def test_same_result_on_any_number_of_ranks():
    world, _ = solve_near_pair(load=0.12)
    alone, _ = solve_near_pair(load=0.12, comm=MPI.COMM_SELF)
    assert np.allclose(world.contact_force(), alone.contact_force(), rtol=1e-7, atol=1e-12)
    tip = world.scene.tags["upper_tip"]
    assert np.allclose(section_motion(world, tip)[0], section_motion(alone, tip)[0], atol=1e-9)
    assert [s.newton_iterations for s in world.history.steps] == [
        s.newton_iterations for s in alone.history.steps
    ]


def test_large_rotations_and_equilibrium(showcase):
    runs, _ = showcase
    for problem in runs.values():
        assert not problem.history.cutbacks or len(problem.history.steps) >= 20
        assert problem.t == pytest.approx(1.0)
        _, n_tip = section_motion(problem, problem.scene.tags["upper_tip"])
        assert np.degrees(np.arccos(abs(n_tip[0]))) > 25.0  # large rotation of the tip
        assert problem.active_points() > 0
        assert equilibrium_error(problem, SUPPORTS) < 1e-8
        # the lower beam carries only the contact force: its clamp balances it, so the
        # reaction equals the contact force on the upper beam (friction included)
        force = problem.contact_force()
        reaction = problem.reaction(problem.scene.tags["lower_clamp"])
        assert np.linalg.norm(reaction - force) < 1e-6 * np.linalg.norm(force)


def test_coulomb_law_at_every_step(showcase):
    """|lambda_T| <= mu lambda_N at every point in contact of every step; where a point
    slips, |lambda_T| = mu lambda_N and the slip runs along lambda_T."""
    _, checks = showcase
    in_contact = [law for law in checks if law.active > 0]
    assert len(in_contact) > 5
    assert max(law.excess for law in in_contact) < 1e-4
    slipping = [law for law in in_contact if law.slipping > 0]
    assert len(slipping) > 5  # the tip corner slides along the lower beam
    assert max(law.slip_excess for law in slipping) < 1e-4
    assert min(law.alignment for law in slipping) > 0.99


def test_friction_changes_the_final_state(showcase):
    runs, _ = showcase
    tip = runs[0.0].scene.tags["upper_tip"]
    u0, u3 = (section_motion(runs[mu], tip)[0] for mu in (0.0, 0.3))
    assert abs(u0[0] - u3[0]) > 0.05 * abs(u0[0])
    f0, f3 = runs[0.0].contact_force(), runs[0.3].contact_force()
    # without friction the tangential force comes only from the tilt of the lower beam and
    # pushes the tip along; friction holds it back
    assert f0[0] > 0 > f3[0]
