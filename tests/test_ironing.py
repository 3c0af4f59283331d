"""Shallow ironing (large frictional sliding) on coarse meshes, serial.

The published geometry (:func:`contact_ufl.verification.geometries.ironing_2d`): the indenter
is pressed 0.8 into the block and slid 10 along it. Verified against the spread of the
published force curves and ratios, against the energy balance (the work done on the
indenter is the frictional dissipation plus the change of stored energy) and against
Coulomb's law at the slave points; the frictional part of the force ratio is mu under full
slip (a consistency check). ``MEASURED`` is a snapshot of this code's own output (the
benchmark's ``--quick`` mesh and, marked slow, its default mesh; the numbers of the 2D
ironing table of the benchmark page): the checks against it are regression checks, which
catch a change of the answer, not an error of it. A shortened frictional run (pressing and
the first slide steps) also runs on 2 ranks, against the same run on one rank.
"""

import numpy as np
import pytest
from conftest import across_ranks
from mpi4py import MPI

from contact_ufl.problem import ContactProblem
from contact_ufl.results import coulomb_law
from contact_ufl.verification import scenes
from contact_ufl.verification.literature import IRONING_FORCES, IRONING_LITERATURE
from contact_ufl.verification.runs import energy_balance, history_at, ironing_run, steady_ratio

COARSE = dict(h_punch=0.05, h_block=0.2, slide_steps=100)

#: A snapshot of this code's output (``benchmarks/results/ironing_quick.json`` and
#: ``ironing.json``): unknowns, accepted steps, cut-backs, Newton iterations, |Fx/Fy| in
#: steady sliding and its frictional and normal parts, the energy mismatch
#: ``(work - dissipation - stored) / work``, and Fy at t = 1.0, Fy and Fx at t = 1.5.
MEASURED = {
    ("quick", 0.0): dict(
        unknowns=2521, steps=120, cutbacks=0, newton=977, ratio=0.003, friction=0.0,
        normal=0.003, energy=0.0046,
    ),
    ("quick", 0.3): dict(
        unknowns=2651, steps=120, cutbacks=0, newton=1259, ratio=0.326, friction=0.302,
        normal=0.024, energy=0.0033, forces=(3.21e8, 4.12e8, 1.36e8),
    ),
    ("fine", 0.3): dict(
        unknowns=9751, steps=220, cutbacks=0, newton=1827, ratio=0.329, friction=0.302,
        normal=0.027, energy=-0.00285, forces=(3.17e8, 4.05e8, 1.34e8),
    ),
}  # fmt: skip

SNAPSHOT = "snapshot of this code's output (MEASURED: the benchmark's ironing table)"
PUBLISHED = "the spread of the published results (literature.IRONING_FORCES, six sources)"
ENERGY = "energy balance of a quasi-static process: work = dissipation + change of stored energy"
COULOMB = "Coulomb's law (theory, property (d)): |lambda_T| <= mu lambda_N, slip along lambda_T"
FULL_SLIP = "Coulomb's law under full slip: the frictional force is mu times the normal force"


def case_of(mu: float, mesh: str = "quick") -> str:
    size = "h = 0.05 / 0.2" if mesh == "quick" else "h = 0.025 / 0.1"
    return f"2D shallow ironing, mu = {mu:g}, {size}"


@pytest.fixture(scope="module", params=[0.0, 0.3], ids=["mu=0", "mu=0.3"])
def ironing(request):
    run, problem = ironing_run(request.param, **COARSE)
    run["problem"] = problem  # at t = 2, the indenter still sliding
    return run


def _published(k: int, j: int) -> tuple[float, float]:
    values = [forces[k][j] for forces in IRONING_FORCES.values()]
    return min(values), max(values)


def _check_run(run: dict, measured: dict, verification, case: str) -> None:
    """Every accepted step converged by SNES's own reason, every cut-back was a Newton
    failure whose step was reached later, and the counts are the snapshot's (regression)."""
    history = run["history"]
    assert history[-1]["time"] == pytest.approx(2.0)
    assert all(r["converged"] for r in history)
    assert all(r["snes_reason"].startswith("CONVERGED") for r in history)
    times = np.array([r["time"] for r in history])
    assert np.all(np.diff(times) > 0.0)
    for cutback in run["cutbacks"]:
        assert cutback["reason"].startswith("DIVERGED"), cutback
        assert np.abs(times - cutback["time"]).min() < 1e-12  # reached with smaller steps
    counts = [run["unknowns"], len(history), len(run["cutbacks"])]
    reference = [measured[k] for k in ("unknowns", "steps", "cutbacks")]
    quantity = "unknowns, accepted steps, cut-backs"
    verification(case, quantity, counts, reference, "equal", SNAPSHOT, kind="regression")
    newton = sum(r["newton_iterations"] for r in history)
    quantity = "Newton iterations over the run"
    tolerance = "relative difference < 0.02"
    verification(case, quantity, newton, measured["newton"], tolerance, SNAPSHOT, kind="regression")
    assert counts == reference
    assert newton == pytest.approx(measured["newton"], rel=0.02)


def _check_ratios(history: list[dict], measured: dict, verification, case: str) -> None:
    """|Fx/Fy| in steady sliding and its two parts, at the three decimals of the snapshot
    (regression)."""
    ratios = {}
    for part, key, name in (
        (None, "ratio", "|Fx/Fy|"),
        ("contact_friction", "friction", "|Fx/Fy|, frictional part"),
        ("contact_normal", "normal", "|Fx/Fy|, normal part"),
    ):
        ratios[key] = steady_ratio(history, part=part)
        quantity = f"{name} in steady sliding (1.2 <= t <= 1.7)"
        tolerance = "|difference| < 5e-4"
        verification(
            case, quantity, ratios[key], measured[key], tolerance, SNAPSHOT, kind="regression"
        )
    for key, value in ratios.items():
        assert value == pytest.approx(measured[key], abs=5e-4), key


def _check_forces(history: list[dict], measured: dict, verification, case: str) -> None:
    """Fy at t = 1.0, Fy and Fx at t = 1.5, at the snapshot's three digits (regression)."""
    values = [history_at(history, 1.0, "Fy"), history_at(history, 1.5, "Fy")]
    values.append(history_at(history, 1.5, "Fx"))
    quantity = "|Fy| at t = 1.0, |Fy| and |Fx| at t = 1.5"
    tolerance = "|difference| < 0.005e8"
    verification(case, quantity, values, measured["forces"], tolerance, SNAPSHOT, kind="regression")
    assert values == pytest.approx(measured["forces"], abs=0.005e8)


@pytest.mark.serial
def test_every_step_converged_to_the_end(ironing, verification):
    """SNES's converged reason of every accepted step, the cut-backs (none on the quick mesh
    since a failed full-step try is followed by one from the predicted state,
    :class:`~contact_ufl.strategies.PredictedStateRetry`; 3 with
    friction before) and, against the snapshot (regression), the numbers of accepted steps,
    unknowns and Newton iterations (within 2%)."""
    mu = ironing["mu"]
    _check_run(ironing, MEASURED["quick", mu], verification, case_of(mu))


@pytest.mark.serial
def test_contact_force_balances_the_support(ironing, verification):
    """The reaction on the indenter's top balances the integrated contact tractions
    (normal plus frictional part) at every step, to 1e-8 of the largest force: action
    equals reaction. This holds by construction (equilibrium of the indenter in any
    converged solve, to the solver tolerance): a consistency check of the post-processing,
    not a verification of the solution."""
    scale = max(abs(r["Fy"]) for r in ironing["history"])
    imbalance = max(
        np.linalg.norm(np.add(r["contact_normal"], r["contact_friction"]) + [r["Fx"], r["Fy"]])
        for r in ironing["history"][1:]
    )
    verification(
        case_of(ironing["mu"]),
        "largest |support reaction + contact force| over the steps, over max |Fy|",
        imbalance / scale,
        0.0,
        "< 1e-8",
        "equilibrium of the indenter in the converged solve",
        kind="consistency",
    )
    assert imbalance < 1e-8 * scale


@pytest.mark.serial
def test_work_is_dissipation_plus_stored_energy(ironing, verification):
    """Over the steady sliding the support's work equals the frictional dissipation plus
    the change of elastic energy to 0.5% (the time discretisation, 100 steps over the
    slide; +0.46% and +0.33% measured), and with friction the slide dissipates all but 1%
    of the work (0.5% measured: steady sliding stores no energy). The mismatch is also held
    at the snapshot's (regression, to 5e-5)."""
    mu = ironing["mu"]
    case = case_of(mu)
    work, dissipation, stored = energy_balance(ironing["history"])
    assert work > 0.0
    mismatch = (work - dissipation - stored) / work
    quantity = "(work - dissipation - stored) / work, 1.2 <= t <= 1.7"
    verification(case, quantity, mismatch, 0.0, "|mismatch| < 0.005", ENERGY)
    measured = MEASURED["quick", mu]["energy"]
    tolerance = "|difference| < 5e-5"
    verification(case, quantity, mismatch, measured, tolerance, SNAPSHOT, kind="regression")
    assert abs(mismatch) < 0.005
    assert mismatch == pytest.approx(measured, abs=5e-5)
    if mu > 0.0:
        quantity = "dissipation / work, 1.2 <= t <= 1.7"
        source = ENERGY + "; steady sliding stores no energy"
        verification(case, quantity, dissipation / work, 1.0, "> 0.99", source)
        assert dissipation > 0.99 * work


@pytest.mark.serial
def test_global_friction_coefficient(ironing, verification):
    """mu = 0: almost no tangential force in steady sliding (0.003). mu = 0.3: the
    frictional part of |Fx/Fy| is mu within 1% (0.302: the indenter slides over the whole
    contact, a consistency check); with the pressure on the indenter's inclined front
    (0.024) the total (0.326) lies in the published range (0.30 to 0.53 at t = 1.5). The
    three ratios are also held at the snapshot's (regression)."""
    history, mu = ironing["history"], ironing["mu"]
    case = case_of(mu)
    _check_ratios(history, MEASURED["quick", mu], verification, case)
    if mu > 0.0:
        friction = steady_ratio(history, part="contact_friction")
        quantity = "|Fx/Fy|, frictional part, over mu - 1, 1.2 <= t <= 1.7"
        error = friction / mu - 1.0
        verification(case, quantity, error, 0.0, "|error| < 0.01", FULL_SLIP, kind="consistency")
        total = steady_ratio(history)
        published = [min(IRONING_LITERATURE.values()), max(IRONING_LITERATURE.values())]
        quantity = "|Fx/Fy| in steady sliding (1.2 <= t <= 1.7)"
        source = "the published ratios (literature.IRONING_LITERATURE, seven sources)"
        verification(case, quantity, total, published, "within the range", source)
        assert friction == pytest.approx(mu, rel=0.01)
        assert total > friction
        assert published[0] <= total <= published[1]


@pytest.mark.serial
@pytest.mark.parametrize("ironing", [0.3], indirect=True, ids=["mu=0.3"])
def test_coulomb_law_while_sliding(ironing, verification):
    """At the end of the slide (t = 2) every point in contact slips, and the P1 multipliers
    obey Coulomb's law point by point: |lambda_T| exceeds mu lambda_N nowhere by more than
    5e-4 of max mu lambda_N (1.8e-4 measured), the slipping points lie on the disc's edge
    to 5e-4 (2.8e-4), and lambda_T points along the slip. Points under 5% of the peak
    pressure are left out (at the zone's ends the multiplier is zero to the projection
    error, and so is the direction of lambda_T there)."""
    check = coulomb_law(ironing["problem"], floor=0.05)
    case = case_of(0.3) + ", at t = 2, lambda_N > 0.05 max"
    for quantity, value, reference, tolerance in (
        ("largest (|lambda_T| - mu lambda_N) / max mu lambda_N", check.excess, 0.0, "< 5e-4"),
        (
            "largest ||lambda_T| - mu lambda_N| of a slipping point, same",
            check.slip_excess,
            0.0,
            "< 5e-4",
        ),
        ("smallest cosine of lambda_T and the slip", check.alignment, 1.0, "> 0.999"),
        ("slipping points / points in contact", check.slipping / check.active, 1.0, "equal"),
    ):
        verification(case, quantity, value, reference, tolerance, COULOMB)
    assert check.slipping == check.active > 20
    assert check.excess < 5e-4 and check.slip_excess < 5e-4
    assert check.alignment > 0.999


@pytest.mark.serial
@pytest.mark.parametrize("ironing", [0.3], indirect=True, ids=["mu=0.3"])
def test_forces_within_the_published_curves(ironing, verification):
    """Fy at the end of pressing and in steady sliding and Fx in steady sliding lie within
    the spread of the published curves (all for mu = 0.3); they are also held at the
    snapshot's values (regression)."""
    history = ironing["history"]
    case = case_of(0.3)
    checks = [
        (history_at(history, t, "Fy"), _published(k, 0), f"|Fy| at t = {t}")
        for k, t in enumerate((1.0, 1.5))
    ]
    checks.append((history_at(history, 1.5, "Fx"), _published(1, 1), "|Fx| at t = 1.5"))
    for value, (low, high), quantity in checks:
        verification(case, quantity, value, [low, high], "within the range", PUBLISHED)
    _check_forces(history, MEASURED["quick", 0.3], verification, case)
    for value, (low, high), _ in checks:
        assert low <= value <= high


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("ironing", [0.3], indirect=True, ids=["mu=0.3"])
def test_fine_mesh_changes_the_ratio_little(ironing, verification):
    """Halving the mesh size (the benchmark's default mesh, about 4 minutes) moves the
    frictional part of |Fx/Fy| by less than 0.2% and the total by less than 1% (a mesh
    convergence check); the fine mesh's counts, ratios, forces and energy mismatch are the
    snapshot's (regression)."""
    fine, _ = ironing_run(ironing["mu"])
    mu = ironing["mu"]
    measured = MEASURED["fine", mu]
    case = case_of(mu, "fine")
    _check_run(fine, measured, verification, case)
    _check_ratios(fine["history"], measured, verification, case)
    _check_forces(fine["history"], measured, verification, case)
    work, dissipation, stored = energy_balance(fine["history"])
    mismatch = (work - dissipation - stored) / work
    quantity = "(work - dissipation - stored) / work, 1.2 <= t <= 1.7"
    tolerance = "|difference| < 5e-5"
    verification(
        case, quantity, mismatch, measured["energy"], tolerance, SNAPSHOT, kind="regression"
    )
    assert mismatch == pytest.approx(measured["energy"], abs=5e-5)
    source = "mesh convergence: the ratio changes little when h is halved"
    changes = {}
    for part, change, name in (
        ("contact_friction", 0.002, "frictional part of |Fx/Fy|"),
        (None, 0.01, "|Fx/Fy|"),
    ):
        coarse_ratio = steady_ratio(ironing["history"], part=part)
        fine_ratio = steady_ratio(fine["history"], part=part)
        changes[part] = fine_ratio / coarse_ratio - 1.0
        quantity = f"relative change of the {name}, h = 0.05 / 0.2 to 0.025 / 0.1"
        verification(case, quantity, changes[part], 0.0, f"|change| < {change:g}", source)
    assert abs(changes["contact_friction"]) < 0.002
    assert abs(changes[None]) < 0.01


def _slide_start(comm) -> ContactProblem:
    """The quick mesh with mu = 0.3: pressed in 20 steps, then slid 0.4 in 4 steps."""
    scene = scenes.ironing(mu=0.3, h_punch=0.05, h_block=0.2, comm=comm)
    problem = ContactProblem(scene, verbose=False, petsc_options={"snes_max_it": 40})
    problem.solve(num_steps=20, t_end=1.0)
    problem.solve(num_steps=4, t_end=1.04)
    return problem


@across_ranks
def test_slide_start_on_any_number_of_ranks(verification):
    """Pressing and the first slide steps with friction: the distributed solve equals the
    solve on one rank (each rank redoes it alone) to solver tolerance, step by step."""
    world = _slide_start(MPI.COMM_WORLD)
    alone = _slide_start(MPI.COMM_SELF)
    for problem in (world, alone):
        assert problem.t == pytest.approx(1.04) and not problem.history.cutbacks
    top = world.scene.tags["punch_top"]
    force = alone.reaction(top)
    assert abs(force[0]) > 0.1 * abs(force[1])  # sliding: friction acts
    difference = np.abs(world.reaction(top) - force).max() / np.linalg.norm(force)
    contact = alone.contact_force()
    contact_difference = np.abs(world.contact_force() / contact - 1.0).max()
    case = (
        f"2D shallow ironing, mu = 0.3, h = 0.05 / 0.2, slid to t = 1.04, {world.comm.size} ranks"
    )
    source = "the same run on one rank"
    quantity = "largest |reaction difference| over |reaction|"
    verification(case, quantity, difference, 0.0, "< 1e-8", source, kind="consistency")
    quantity = "largest relative difference of the contact force"
    verification(case, quantity, contact_difference, 0.0, "< 1e-8", source, kind="consistency")
    # SNES stops at rtol 1e-9: two runs may stop an iterate apart (measured: 1e-15)
    assert difference < 1e-8
    assert contact_difference < 1e-8
    assert [s.newton_iterations for s in world.history.steps] == [
        s.newton_iterations for s in alone.history.steps
    ]
