"""The two-beam showcase: beam theory at small load (the contact force, the tip deflection
and, without friction, the force normal to the lower beam's surface), global equilibrium,
the Coulomb law, friction that changes the result, and independence of the number of ranks.
The showcase's final state is compared with a snapshot of this code's output (a regression
check), not with an independent solution."""

import numpy as np
import pytest
from conftest import across_ranks
from mpi4py import MPI

from contact_ufl import output
from contact_ufl.problem import ContactProblem
from contact_ufl.results import (
    contact_force_parts,
    coulomb_law,
    equilibrium_error,
    section_motion,
)
from contact_ufl.verification import geometries, scenes

SUPPORTS = ["upper_clamp", "lower_clamp"]
#: clamps at opposite ends and a small gap: the upper tip corner lands on the lower beam long
#: before large rotations, a point contact between two cantilevers
NEAR = geometries.BeamPair(
    gap=0.1, lower_length=10.0, lower_height=1.5, tip=6.0, master_start=4.0, clamps="opposite"
)
NEAR_CASE = "two cantilevers, opposite clamps, gap 0.1, tip load 0.12 EI/L^2, mu = 0"
BEAM_THEORY = "Euler-Bernoulli beam theory: two cantilevers in series (BeamsScene.two_springs)"
#: beam theory at small load: relative errors of the contact force (measured -2.9%), the tip
#: deflection (1.4%) and the slope of the lower beam's surface under the tip (1.0%)
SPRINGS_TOL = {"force": 0.05, "deflection": 0.03, "slope": 0.02}
#: the demo's scene (``demos/beams.py``, default geometry): final load in EI / L^2, steps
LOAD, STEPS = 6.0, 20
CASE = "two beams of demos/beams.py, follower tip load 6 EI/L^2, 20 steps"
#: the Coulomb check leaves out the points at the edge of the contact zone, where the P1
#: multiplier lambda_N is zero to its projection error (measured down to -1.3e-4 of its
#: peak, with |lambda_T| - mu lambda_N = 4e-4 of max mu lambda_N and lambda_T against the
#: slip there): lambda_N <= FLOOR max(lambda_N)
FLOOR = 1e-3
#: a snapshot of this code's output (regression, not an independent solution): tip
#: displacement (x, z), tip rotation (deg), contact force (x, z) on the upper beam at the last
#: step, for mu = 0 and 0.3, to 4 decimals (rotation 2); 1 and 2 ranks agree to 1e-6
SNAPSHOT = {
    0.0: ((1.0347, -3.9104), 38.95, (-2.7094, 3.6005)),
    0.3: ((0.9448, -3.7958), 36.90, (-3.9910, 3.1941)),
}
#: differences from the snapshot (its rounding: measured 4.9e-5, rotation 3.7e-3 degree)
SNAPSHOT_TOL, ROTATION_TOL = 1e-4, 0.01
SNAPSHOT_SOURCE = "snapshot of this code's output, 4 decimals (rotation 2)"
#: consistency, to the Newton tolerance: equilibrium of loads, reactions and contact forces
#: (measured 2.1e-10), and the lower clamp's reaction against the contact force (3.2e-8)
EQUILIBRIUM_TOL, REACTION_TOL = 5e-10, 1e-7
#: the Coulomb law on the multipliers: excess over the cone, and off the cone where slipping,
#: over max(mu lambda_N) (measured 1.7e-5 and 2.3e-5), and 1 - cos(slip, lambda_T) where
#: slipping (1.4e-3)
COULOMB_TOL, ALIGNMENT_TOL = 5e-5, 3e-3
EQUILIBRIUM = "equilibrium of the converged solve"
COULOMB = "the formulation's property (e): the Coulomb law on the multipliers"


def solve_near_pair(load: float, comm=MPI.COMM_WORLD, mu: float = 0.0):
    beams = scenes.beams(load=load, divisions=3, geometry=NEAR, comm=comm, mu=mu)
    problem = ContactProblem(beams.scene, verbose=False)
    problem.solve(num_steps=3)
    return problem, beams


def contact_zone(problem) -> tuple[np.ndarray, np.ndarray]:
    """Reference x of the slave points in contact (the upper beam's underside) and their
    normal tractions t_N, all ranks."""
    c = problem.contacts[0]
    active = c.active()
    x = c.slave.X.reshape(-1, 3)[active, 0]
    t_N = c.normal_traction_at_points()[active]
    return tuple(np.concatenate(problem.comm.allgather(a)) for a in (x, t_N))


def slave_state(problem) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reference positions of all slave points (sorted), their normal tractions t_N and
    whether they are in contact, all ranks."""
    c = problem.contacts[0]
    parts = (c.slave.X.reshape(-1, 3), c.normal_traction_at_points(), c.active())
    X, t_N, active = (np.concatenate(problem.comm.allgather(a)) for a in parts)
    order = np.lexsort(np.round(X, 9).T)
    return X[order], t_N[order], active[order]


class Showcase:
    """The demo's scene (divisions 3, load 6 EI/L^2, 20 steps) without and with friction,
    each solved when a test first asks for it, and the Coulomb check of every converged
    frictional step."""

    def __init__(self) -> None:
        self._runs: dict[float, ContactProblem] = {}
        self._checks: list = []

    def __getitem__(self, mu: float) -> ContactProblem:
        if mu not in self._runs:
            beams = scenes.beams(mu=mu, divisions=3, load=LOAD)
            problem = ContactProblem(beams.scene, verbose=False)

            def record(problem, step):
                if mu > 0:
                    self._checks.append(coulomb_law(problem, floor=FLOOR))

            problem.solve(num_steps=STEPS, callback=record)
            self._runs[mu] = problem
        return self._runs[mu]

    @property
    def checks(self) -> list:
        """The Coulomb checks of the frictional run's steps."""
        self[0.3]
        return self._checks


@pytest.fixture(scope="module")
def showcase() -> Showcase:
    return Showcase()


@pytest.mark.serial  # 2 ranks: test_same_result_on_any_number_of_ranks
def test_two_cantilevers_in_series(verification):
    """At small load the pair acts as two springs in series (beam theory): the contact
    force and the upper tip's deflection. Without friction the force is normal to the lower
    beam's top surface, whose slope under the tip is beam theory's ``N a^2 / (2 EI_2)`` (a
    cantilever of arm ``a`` under the contact force ``N``): ``F_x / F_z`` is that slope."""
    problem, beams = solve_near_pair(load=0.12)
    P = beams.load * beams.bending_stiffness / NEAR.length**2
    N, w = beams.two_springs(P)
    assert N > 0.5 * P  # well into contact
    force = problem.contact_force()
    u_tip, n_tip = section_motion(problem, beams.scene.tags["upper_tip"])
    assert np.degrees(np.arccos(abs(n_tip[0]))) < 3.0  # small rotations
    slope = force[2] * NEAR.lower_arm**2 / (2.0 * beams.lower_bending_stiffness)
    errors = {
        "force": (force[2] / N - 1.0, "contact force N", N),
        "deflection": (-u_tip[2] / w - 1.0, "upper tip deflection w", w),
        "slope": (force[0] / force[2] / slope - 1.0, "F_x / F_z (mu = 0)", slope),
    }
    for key, (error, name, reference) in errors.items():
        verification(
            NEAR_CASE,
            f"relative error of the {name}",
            error,
            reference,
            f"|error| < {SPRINGS_TOL[key]:g}",
            BEAM_THEORY if key != "slope" else f"{BEAM_THEORY}; slope N a^2 / (2 EI_2)",
        )
    for key, (error, _, _) in errors.items():
        assert abs(error) < SPRINGS_TOL[key], (key, error)


@pytest.mark.parametrize(
    "mu", [pytest.param(0.0, marks=pytest.mark.slow), 0.3], ids=["mu=0", "mu=0.3"]
)  # frictionless: the other scenes' rank comparisons, and this one in the slow tier
@across_ranks
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


@pytest.mark.serial  # 2 ranks: test_showcase_on_any_number_of_ranks (slow tier)
def test_large_rotations_and_equilibrium(showcase, verification):
    """20 steps without a cut-back, a large rotation, and equilibrium. The two balances
    hold by construction (equilibrium of any converged solve, to the solver tolerance):
    they check the reactions and the contact force, not the solution (consistency)."""
    for mu in (0.0, 0.3):
        problem = showcase[mu]
        assert problem.t == pytest.approx(1.0)
        assert len(problem.history.steps) == STEPS and not problem.history.cutbacks
        _, n_tip = section_motion(problem, problem.scene.tags["upper_tip"])
        assert np.degrees(np.arccos(abs(n_tip[0]))) > 30.0  # large rotation of the tip
        balance = equilibrium_error(problem, SUPPORTS)
        # the lower beam carries only the contact force: its clamp balances it, so the
        # reaction equals the contact force on the upper beam (friction included)
        force = problem.contact_force()
        reaction = problem.reaction(problem.scene.tags["lower_clamp"])
        mismatch = np.linalg.norm(reaction - force) / np.linalg.norm(force)
        case = f"{CASE}, mu = {mu:g}"
        quantity = "equilibrium error of loads, reactions and contact forces"
        tolerance = f"< {EQUILIBRIUM_TOL:g}"
        verification(case, quantity, balance, 0.0, tolerance, EQUILIBRIUM, kind="consistency")
        quantity = "|lower clamp reaction - contact force| / |contact force|"
        tolerance = f"< {REACTION_TOL:g}"
        verification(case, quantity, mismatch, 0.0, tolerance, EQUILIBRIUM, kind="consistency")
        assert balance < EQUILIBRIUM_TOL
        assert mismatch < REACTION_TOL


@pytest.mark.serial  # 2 ranks: test_showcase_on_any_number_of_ranks (slow tier)
@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_final_state_snapshot(showcase, mu, verification):
    """The final state against a snapshot of this code's output (a regression check, to its
    4 decimals, rotation 0.01 degree): tip displacement, tip rotation, contact force."""
    problem = showcase[mu]
    tip, rotation, force = SNAPSHOT[mu]
    u_tip, n_tip = section_motion(problem, problem.scene.tags["upper_tip"])
    measured = {
        "tip displacement (x, z)": (u_tip[[0, 2]], tip, SNAPSHOT_TOL),
        "tip rotation (degrees)": (
            np.degrees(np.arctan2(-n_tip[2], -n_tip[0])),
            rotation,
            ROTATION_TOL,
        ),
        "contact force (x, z) on the upper beam": (
            problem.contact_force()[[0, 2]],
            force,
            SNAPSHOT_TOL,
        ),
    }
    for quantity, (value, snapshot, tolerance) in measured.items():
        verification(
            f"{CASE}, mu = {mu:g}",
            quantity,
            value,
            snapshot,
            f"|difference| < {tolerance:g}",
            SNAPSHOT_SOURCE,
            kind="regression",
        )
    for quantity, (value, snapshot, tolerance) in measured.items():
        assert value == pytest.approx(snapshot, abs=tolerance), quantity


@pytest.mark.serial  # 2 ranks: test_showcase_on_any_number_of_ranks (slow tier)
@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_distributed_contact_zone(showcase, mu, verification):
    """The upper beam's underside lies on the lower beam over a length, not on its tip
    corner only: the points in contact span more than 3.5 of its length (of the overlap 8),
    more than 80 of them are more than one beam height from the tip, and there the pressure
    reaches more than 1.5 (at the tip corner, where the follower force pushes it in, about
    20). The bounds sit below this code's output (regression): no closed form gives them."""
    problem = showcase[mu]
    g = geometries.BeamPair()
    x, t_N = contact_zone(problem)
    assert x.min() == pytest.approx(g.tip)  # the tip corner is in contact
    away = x > g.tip + g.height
    measured = {
        "length spanned by the points in contact": (np.ptp(x), 3.5),
        "points in contact beyond one height from the tip": (np.count_nonzero(away), 80),
        "largest t_N beyond one height from the tip": (t_N[away].max(initial=0.0), 1.5),
    }
    source = "a lower bound below this code's output (snapshot of the distributed contact)"
    for quantity, (value, bound) in measured.items():
        verification(
            f"{CASE}, mu = {mu:g}",
            quantity,
            value,
            f"> {bound:g}",
            f"> {bound:g}",
            source,
            kind="regression",
        )
    for quantity, (value, bound) in measured.items():
        assert value > bound, quantity


@pytest.mark.serial  # 2 ranks: test_showcase_on_any_number_of_ranks (slow tier)
def test_coulomb_law_at_every_step(showcase, verification):
    """|lambda_T| <= mu lambda_N at every point in contact (lambda_N above FLOOR of its
    peak) of every step; where a point slips, |lambda_T| = mu lambda_N and the slip runs
    along lambda_T. The underside slides along the lower beam in every step."""
    checks = showcase.checks
    in_contact = [law for law in checks if law.active > 0]
    assert len(in_contact) == STEPS  # the tip lands in the first step
    slipping = [law for law in in_contact if law.slipping > 0]
    assert len(slipping) == STEPS
    excess = max(law.excess for law in in_contact)
    slip_excess = max(law.slip_excess for law in slipping)
    alignment = min(law.alignment for law in slipping)
    case = f"{CASE}, mu = 0.3, every step"
    for quantity, value, reference, tolerance in (
        ("max (|lambda_T| - mu lambda_N) / max(mu lambda_N)", excess, "<= 0", COULOMB_TOL),
        (
            "max |mu lambda_N - |lambda_T|| / max(mu lambda_N) where slipping",
            slip_excess,
            0.0,
            COULOMB_TOL,
        ),
        ("1 - min cos(slip, lambda_T) where slipping", 1.0 - alignment, 0.0, ALIGNMENT_TOL),
    ):
        verification(case, quantity, value, reference, f"< {tolerance:g}", COULOMB)
    assert excess < COULOMB_TOL
    assert slip_excess < COULOMB_TOL
    assert 1.0 - alignment < ALIGNMENT_TOL


@pytest.mark.serial  # 2 ranks: test_showcase_on_any_number_of_ranks (slow tier)
def test_friction_changes_the_final_state(showcase, verification):
    """The upper beam slides along the lower one towards the clamps (+x): friction holds it
    back (the Coulomb law: the frictional force opposes the slip), with a force that is a
    sizeable part of the normal one, and the tip moves less along x than without friction."""
    runs = showcase
    tip = runs[0.0].scene.tags["upper_tip"]
    u0, u3 = (section_motion(runs[mu], tip)[0] for mu in (0.0, 0.3))
    normal, frictional = contact_force_parts(runs[0.3])
    f0, f3 = runs[0.0].contact_force(), runs[0.3].contact_force()
    change = abs(u0[0] - u3[0]) / abs(u0[0])
    holding = frictional[0] / np.linalg.norm(normal)
    case = f"{CASE}, mu = 0.3 against mu = 0"
    source = "the Coulomb law, property (e): the frictional force opposes the slip (+x)"
    for quantity, value, bound in (
        ("frictional force F_x over |normal force|", holding, "< -0.1"),
        ("contact force F_x(mu = 0.3) - F_x(mu = 0)", f3[0] - f0[0], "< -0.5"),
        ("|tip u_x(mu = 0.3) - u_x(mu = 0)| / |u_x(mu = 0)|", change, "> 0.05"),
    ):
        verification(case, quantity, value, bound, bound, source)
    assert holding < -0.1
    assert f3[0] - f0[0] < -0.5
    assert change > 0.05


@pytest.mark.slow  # the rank comparison of the default suite: the near pair, mu = 0 and 0.3
@across_ranks
def test_showcase_on_any_number_of_ranks(showcase):
    """Under MPI: the showcase (mu = 0) solved on one rank gives the same state."""
    world = showcase[0.0]
    beams = scenes.beams(divisions=3, load=LOAD, comm=MPI.COMM_SELF)
    alone = ContactProblem(beams.scene, verbose=False)
    alone.solve(num_steps=STEPS)
    assert np.allclose(world.contact_force(), alone.contact_force(), rtol=1e-6, atol=1e-10)
    tip = world.scene.tags["upper_tip"]
    assert np.allclose(section_motion(world, tip)[0], section_motion(alone, tip)[0], atol=1e-8)
    (X, t_N, active), (X1, t_N1, active1) = slave_state(world), slave_state(alone)
    assert np.allclose(X, X1)
    # the same points in contact, but for those at the zone's edge whose normal traction
    # is zero to solver tolerance (MUMPS's round-off on 2 ranks varies from run to run)
    edge = np.maximum(t_N, t_N1) < 1e-8 * t_N.max()
    assert np.array_equal(active[~edge], active1[~edge])
    assert np.count_nonzero(active != active1) <= 2
    assert [s.newton_iterations for s in world.history.steps] == [
        s.newton_iterations for s in alone.history.steps
    ]


@pytest.mark.serial  # the gather to rank 0 runs on 2 ranks in tests/test_demos.py
def test_contact_state_picture(showcase, tmp_path):
    """The picture's surface holds every slave point, with t_N > 0 exactly at the points in
    contact and its peak at the tip corner; bad camera or colour input fails on every rank."""
    problem = showcase[0.3]
    surface = output.gathered_contact_surface(problem)
    _, t_N = contact_zone(problem)
    slave = problem.contacts[0].slave
    points = problem.comm.allreduce(slave.X.shape[0] * slave.X.shape[1])
    active = problem.active_points()
    if MPI.COMM_WORLD.rank == 0:
        assert surface.n_points == points
        assert np.count_nonzero(surface["t_N"] > 0.0) == active
        assert surface["t_N"].max() == pytest.approx(t_N.max())
        assert np.any(surface["t_T"])  # the frictional traction is there to draw
    else:
        assert surface is None
    folder = MPI.COMM_WORLD.bcast(tmp_path, root=0)
    for bad in ({"view": (0.0, 0.0, 0.0)}, {"view": "side"}, {"saturate": 0.0}):
        with pytest.raises(ValueError):
            output.plot_contact_state(problem, folder / "bad.png", **bad)
    output.plot_contact_state(problem, folder / "state.png", "xz", saturate=80.0)
    if MPI.COMM_WORLD.rank == 0:
        assert (folder / "state.png").stat().st_size > 10_000


def test_unknown_clamps_are_refused():
    with pytest.raises(ValueError, match="clamps must be 'opposite' or 'same'"):
        geometries.beams_3d(geometries.BeamPair(clamps="middle"), divisions=1)
