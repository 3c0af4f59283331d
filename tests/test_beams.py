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


def solve_near_pair(load: float, comm=MPI.COMM_WORLD, mu: float = 0.0):
    beams = scenes.beams(load=load, divisions=3, geometry=NEAR, comm=comm, mu=mu)
    problem = ContactProblem(beams.scene, verbose=False)
    problem.solve(num_steps=3)
    return problem, beams


#: The README's table (2 ranks, 20 steps): tip displacement (x, z), tip rotation in
#: degrees, contact force on the upper beam (x, z), unknowns
SHOWCASE = {
    0.0: dict(tip=(0.880, -3.648), rotation=34.5, force=(0.192, 1.818), unknowns=5368),
    0.3: dict(tip=(0.812, -3.550), rotation=32.5, force=(-0.317, 1.549), unknowns=5668),
}


def tip_rotation(problem) -> float:
    """The rotation of the upper beam's tip section in the plane of bending, in degrees."""
    _, n_tip = section_motion(problem, problem.scene.tags["upper_tip"])
    return float(np.degrees(np.arctan2(-n_tip[2], -n_tip[0])))


@pytest.fixture(scope="module")
def showcase():
    """The demo's scene (divisions 3, load 3 EI/L^2) without and with friction, the
    Coulomb check of every converged frictional step, and the tip rotation and number of
    contact points of every frictionless step."""
    runs, checks, landing = {}, [], []
    for mu in (0.0, 0.3):
        beams = scenes.beams(mu=mu, divisions=3, load=3.0)
        problem = ContactProblem(beams.scene, verbose=False)

        def record(problem, step, mu=mu):
            if mu > 0:
                checks.append(coulomb_law(problem))
            else:
                landing.append((tip_rotation(problem), step.active_points))

        problem.solve(num_steps=20, callback=record)
        runs[mu] = problem
    return runs, checks, landing


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


@pytest.mark.parametrize("mu", [0.0, 0.3], ids=["mu=0", "mu=0.3"])
def test_same_result_on_any_number_of_ranks(mu):
    """The distributed solve equals the solve on one rank (each rank redoes it alone), with
    and without friction: contact force, tip displacement, Newton iterations."""
    world, _ = solve_near_pair(load=0.12, mu=mu)
    alone, _ = solve_near_pair(load=0.12, comm=MPI.COMM_SELF, mu=mu)
    if mu > 0:  # friction acts: the tangential force is a good part of the normal one
        force = alone.contact_force()
        assert abs(force[0]) > 0.1 * force[2]
    assert np.allclose(world.contact_force(), alone.contact_force(), rtol=1e-7, atol=1e-12)
    tip = world.scene.tags["upper_tip"]
    assert np.allclose(section_motion(world, tip)[0], section_motion(alone, tip)[0], atol=1e-9)
    assert [s.newton_iterations for s in world.history.steps] == [
        s.newton_iterations for s in alone.history.steps
    ]


def test_large_rotations_and_equilibrium(showcase):
    """20 steps without a cut-back, a large rotation, and equilibrium. The two balances
    hold by construction (equilibrium of any converged solve, to the solver tolerance):
    they check the reactions and the contact force, not the solution."""
    runs, _, _ = showcase
    for problem in runs.values():
        assert not problem.history.cutbacks
        assert len(problem.history.steps) == 20
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
    slips, |lambda_T| = mu lambda_N and the slip runs along lambda_T. The P1 multiplier
    meets the disc to 5e-6 of max mu lambda_N (4.2e-6 measured: the error of the weak
    projection, property (c)). The tip corner lands in step 7 and slides in all 14 steps
    in contact."""
    _, checks, _ = showcase
    in_contact = [law for law in checks if law.active > 0]
    assert len(in_contact) == 14
    assert max(law.excess for law in in_contact) < 5e-6
    slipping = [law for law in in_contact if law.slipping > 0]
    assert len(slipping) == 14  # the tip corner slides along the lower beam
    assert max(law.slip_excess for law in slipping) < 5e-6
    assert min(law.alignment for law in slipping) > 0.9999


def test_showcase_table(showcase):
    """The README's table: tip displacement, rotation and contact force at the last step,
    at the precision printed there (3 decimals, rotation to 0.05 degrees), and the
    unknowns. Without friction the tip corner lands on the lower beam in step 7, when the
    tip has turned through 27.0 degrees (24.0 in step 6, still free)."""
    runs, _, landing = showcase
    for mu, problem in runs.items():
        expected = SHOWCASE[mu]
        u_tip, _ = section_motion(problem, problem.scene.tags["upper_tip"])
        assert u_tip[[0, 2]] == pytest.approx(expected["tip"], abs=5e-4)
        assert tip_rotation(problem) == pytest.approx(expected["rotation"], abs=0.05)
        assert problem.contact_force()[[0, 2]] == pytest.approx(expected["force"], abs=5e-4)
        assert problem.layout.global_size == expected["unknowns"]
    first = next(k for k, (_, active) in enumerate(landing) if active > 0)
    assert first + 1 == 7
    assert [r for r, _ in landing[5:7]] == pytest.approx([24.0, 27.0], abs=0.05)


def test_friction_changes_the_final_state(showcase):
    runs, _, _ = showcase
    tip = runs[0.0].scene.tags["upper_tip"]
    u0, u3 = (section_motion(runs[mu], tip)[0] for mu in (0.0, 0.3))
    assert abs(u0[0] - u3[0]) > 0.05 * abs(u0[0])
    f0, f3 = runs[0.0].contact_force(), runs[0.3].contact_force()
    # without friction the tangential force comes only from the tilt of the lower beam and
    # pushes the tip along; friction holds it back
    assert f0[0] > 0 > f3[0]
