"""Shallow ironing (large frictional sliding) on coarse meshes, serial (about 50 s).

The published geometry (:func:`contact_ufl.verification.geometries.ironing_2d`): the indenter
is pressed 0.8 into the block and slid 10 along it. Checked against the published force curves and
against two properties no publication is needed for: the frictional part of the force
ratio is mu, and the work done on the indenter is the frictional dissipation plus the
change of stored energy. The numbers of the README's table (``benchmarks/ironing.py
--quick`` and, marked slow, the benchmark's default mesh) are held at the precision they
are printed with there. A shortened frictional run (pressing and the first slide steps)
also runs on 2 ranks, against the same run on one rank.
"""

import numpy as np
import pytest
from conftest import across_ranks
from mpi4py import MPI

from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes
from contact_ufl.verification.literature import IRONING_FORCES, IRONING_LITERATURE
from contact_ufl.verification.runs import energy_balance, history_at, ironing_run, steady_ratio

COARSE = dict(h_punch=0.05, h_block=0.2, slide_steps=100)

#: The README's table, as measured (``benchmarks/results/ironing_quick.json`` and
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


@pytest.fixture(scope="module", params=[0.0, 0.3], ids=["mu=0", "mu=0.3"])
def ironing(request):
    run, _ = ironing_run(request.param, **COARSE)
    return run


def _published(k: int, j: int) -> tuple[float, float]:
    values = [forces[k][j] for forces in IRONING_FORCES.values()]
    return min(values), max(values)


def _check_run(run: dict, measured: dict) -> None:
    """Every accepted step converged by SNES's own reason, every cut-back was a Newton
    failure whose step was reached later, and the counts are those of the README."""
    history = run["history"]
    assert history[-1]["time"] == pytest.approx(2.0)
    assert all(r["converged"] for r in history)
    assert all(r["snes_reason"].startswith("CONVERGED") for r in history)
    times = np.array([r["time"] for r in history])
    assert np.all(np.diff(times) > 0.0)
    for cutback in run["cutbacks"]:
        assert cutback["reason"].startswith("DIVERGED"), cutback
        assert np.abs(times - cutback["time"]).min() < 1e-12  # reached with smaller steps
    assert run["unknowns"] == measured["unknowns"]
    assert len(history) == measured["steps"]
    assert len(run["cutbacks"]) == measured["cutbacks"]
    newton = sum(r["newton_iterations"] for r in history)
    assert newton == pytest.approx(measured["newton"], rel=0.02)


def _check_ratios(history: list[dict], mu: float, measured: dict) -> None:
    """|Fx/Fy| in steady sliding and its two parts, at the README's three decimals."""
    for part, key in (
        (None, "ratio"),
        ("contact_friction", "friction"),
        ("contact_normal", "normal"),
    ):
        assert steady_ratio(history, part=part) == pytest.approx(measured[key], abs=5e-4), key
    if mu > 0.0:
        assert steady_ratio(history, part="contact_friction") == pytest.approx(mu, rel=0.01)


def _check_forces(history: list[dict], measured: dict) -> None:
    """Fy at t = 1.0, Fy and Fx at t = 1.5, at the README's three digits."""
    values = [history_at(history, 1.0, "Fy"), history_at(history, 1.5, "Fy")]
    values.append(history_at(history, 1.5, "Fx"))
    assert values == pytest.approx(measured["forces"], abs=0.005e8)


@pytest.mark.serial
def test_every_step_converged_to_the_end(ironing):
    """SNES's converged reason of every accepted step, the cut-backs (none on the quick mesh
    since a failed full-step try is followed by one from the predicted state,
    :attr:`NewtonSolver.predictor <contact_ufl.newton.NewtonSolver.predictor>`; 3 with
    friction before) and the numbers of accepted steps, unknowns and Newton iterations
    (within 2%) of the README's table."""
    _check_run(ironing, MEASURED["quick", ironing["mu"]])


@pytest.mark.serial
def test_contact_force_balances_the_support(ironing):
    """The reaction on the indenter's top balances the integrated contact tractions
    (normal plus frictional part) at every step, to 1e-8 of the largest force: action
    equals reaction. This holds by construction (equilibrium of the indenter in any
    converged solve, to the solver tolerance): a check of the post-processing, not a
    verification of the solution."""
    scale = max(abs(r["Fy"]) for r in ironing["history"])
    for r in ironing["history"][1:]:
        total = np.add(r["contact_normal"], r["contact_friction"])
        assert np.linalg.norm(total + [r["Fx"], r["Fy"]]) < 1e-8 * scale


@pytest.mark.serial
def test_work_is_dissipation_plus_stored_energy(ironing):
    """Over the steady sliding the support's work equals the frictional dissipation plus
    the change of elastic energy to 0.5% (the time discretisation, 100 steps over the
    slide); the mismatch is the README's (+0.46% and +0.38%, to 0.005%)."""
    work, dissipation, stored = energy_balance(ironing["history"])
    assert work > 0.0
    mismatch = (work - dissipation - stored) / work
    assert abs(mismatch) < 0.005
    assert mismatch == pytest.approx(MEASURED["quick", ironing["mu"]]["energy"], abs=5e-5)
    if ironing["mu"] > 0.0:
        assert dissipation > 0.9 * work  # sliding dissipates, storing little


@pytest.mark.serial
def test_global_friction_coefficient(ironing):
    """mu = 0: almost no tangential force in steady sliding (0.003). mu = 0.3: the
    frictional part of |Fx/Fy| is mu within 1% (0.302); with the pressure on the
    indenter's inclined front (0.024) the total (0.326) lies in the published range
    (0.30 to 0.53 at t = 1.5)."""
    history, mu = ironing["history"], ironing["mu"]
    _check_ratios(history, mu, MEASURED["quick", mu])
    if mu > 0.0:
        total = steady_ratio(history)
        assert total > steady_ratio(history, part="contact_friction")
        assert min(IRONING_LITERATURE.values()) <= total <= max(IRONING_LITERATURE.values())


@pytest.mark.serial
@pytest.mark.parametrize("ironing", [0.3], indirect=True, ids=["mu=0.3"])
def test_forces_within_the_published_curves(ironing):
    """Fy at the end of pressing and in steady sliding and Fx in steady sliding lie within
    the spread of the published curves (all for mu = 0.3), at the README's values."""
    history = ironing["history"]
    for k, t in enumerate((1.0, 1.5)):
        low, high = _published(k, 0)
        assert low <= history_at(history, t, "Fy") <= high
    low, high = _published(1, 1)
    assert low <= history_at(history, 1.5, "Fx") <= high
    _check_forces(history, MEASURED["quick", 0.3])


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("ironing", [0.3], indirect=True, ids=["mu=0.3"])
def test_fine_mesh_changes_the_ratio_little(ironing):
    """Halving the mesh size (the benchmark's default mesh, about 4 minutes) moves the
    frictional part of |Fx/Fy| by less than 0.2% and the total by less than 1%; the
    fine mesh's numbers are the README's."""
    fine, _ = ironing_run(ironing["mu"])
    measured = MEASURED["fine", ironing["mu"]]
    _check_run(fine, measured)
    _check_ratios(fine["history"], ironing["mu"], measured)
    _check_forces(fine["history"], measured)
    work, dissipation, stored = energy_balance(fine["history"])
    assert (work - dissipation - stored) / work == pytest.approx(measured["energy"], abs=5e-5)
    for part, change in (("contact_friction", 0.002), (None, 0.01)):
        coarse_ratio = steady_ratio(ironing["history"], part=part)
        fine_ratio = steady_ratio(fine["history"], part=part)
        assert fine_ratio == pytest.approx(coarse_ratio, rel=change)


def _slide_start(comm) -> ContactProblem:
    """The quick mesh with mu = 0.3: pressed in 20 steps, then slid 0.4 in 4 steps."""
    scene = scenes.ironing(mu=0.3, h_punch=0.05, h_block=0.2, comm=comm)
    problem = ContactProblem(scene, verbose=False, petsc_options={"snes_max_it": 40})
    problem.solve(num_steps=20, t_end=1.0)
    problem.solve(num_steps=4, t_end=1.04)
    return problem


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares a distributed solve")
@across_ranks
def test_slide_start_on_any_number_of_ranks():
    """Pressing and the first slide steps with friction: the distributed solve equals the
    solve on one rank (each rank redoes it alone) to solver tolerance, step by step."""
    world = _slide_start(MPI.COMM_WORLD)
    alone = _slide_start(MPI.COMM_SELF)
    for problem in (world, alone):
        assert problem.t == pytest.approx(1.04) and not problem.history.cutbacks
    top = world.scene.tags["punch_top"]
    force = alone.reaction(top)
    assert abs(force[0]) > 0.1 * abs(force[1])  # sliding: friction acts
    assert np.allclose(world.reaction(top), force, rtol=0, atol=1e-7 * np.linalg.norm(force))
    assert np.allclose(world.contact_force(), alone.contact_force(), rtol=1e-7, atol=0)
    assert [s.newton_iterations for s in world.history.steps] == [
        s.newton_iterations for s in alone.history.steps
    ]
