"""Shallow ironing (large frictional sliding) on coarse meshes, serial (about 90 s).

The published geometry (:func:`contact_ufl.verification.geometries.ironing_2d`): the indenter
is pressed 0.8 into the block and slid 10 along it. Checked against the published force curves and
against two properties no publication is needed for: the frictional part of the force
ratio is mu, and the work done on the indenter is the frictional dissipation plus the
change of stored energy.
"""

import numpy as np
import pytest

from contact_ufl.verification.literature import IRONING_FORCES, IRONING_LITERATURE
from contact_ufl.verification.runs import energy_balance, history_at, ironing_run, steady_ratio

COARSE = dict(h_punch=0.05, h_block=0.2, slide_steps=100)


@pytest.fixture(scope="module", params=[0.0, 0.3], ids=["mu=0", "mu=0.3"])
def ironing(request):
    run, _ = ironing_run(request.param, **COARSE)
    return run


def _published(k: int, j: int) -> tuple[float, float]:
    values = [forces[k][j] for forces in IRONING_FORCES.values()]
    return min(values), max(values)


@pytest.mark.serial
def test_every_step_converged_to_the_end(ironing):
    history = ironing["history"]
    assert history[-1]["time"] == pytest.approx(2.0)
    assert all(r["converged"] for r in history)


@pytest.mark.serial
def test_contact_force_balances_the_support(ironing):
    """The reaction on the indenter's top balances the integrated contact tractions
    (normal plus frictional part) at every step: action equals reaction."""
    for r in ironing["history"][1:]:
        total = np.add(r["contact_normal"], r["contact_friction"])
        assert np.linalg.norm(total + [r["Fx"], r["Fy"]]) < 1e-6 * abs(r["Fy"]) + 1e-3


@pytest.mark.serial
def test_work_is_dissipation_plus_stored_energy(ironing):
    """Over the steady sliding the support's work equals the frictional dissipation plus
    the change of elastic energy (to the time discretisation, 100 steps over the slide)."""
    work, dissipation, stored = energy_balance(ironing["history"])
    assert work > 0.0
    assert abs(work - dissipation - stored) < 0.02 * work
    if ironing["mu"] > 0.0:
        assert dissipation > 0.9 * work  # sliding dissipates, storing little


@pytest.mark.serial
def test_global_friction_coefficient(ironing):
    """mu = 0: no tangential force in steady sliding. mu = 0.3: the frictional part of
    |Fx/Fy| is mu within 3%; with the pressure on the indenter's inclined front the total
    lies in the published range (0.30 to 0.53 at t = 1.5)."""
    history, mu = ironing["history"], ironing["mu"]
    if mu == 0.0:
        assert steady_ratio(history) < 0.02
        return
    assert steady_ratio(history, part="contact_friction") == pytest.approx(mu, rel=0.03)
    total = steady_ratio(history)
    assert total > steady_ratio(history, part="contact_friction")
    assert min(IRONING_LITERATURE.values()) <= total <= max(IRONING_LITERATURE.values())


@pytest.mark.serial
@pytest.mark.parametrize("ironing", [0.3], indirect=True, ids=["mu=0.3"])
def test_forces_within_the_published_curves(ironing):
    """Fy at the end of pressing and in steady sliding and Fx in steady sliding lie within
    the spread of the published curves (all for mu = 0.3)."""
    history = ironing["history"]
    for k, t in enumerate((1.0, 1.5)):
        low, high = _published(k, 0)
        assert low <= history_at(history, t, "Fy") <= high
    low, high = _published(1, 1)
    assert low <= history_at(history, 1.5, "Fx") <= high


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("ironing", [0.3], indirect=True, ids=["mu=0.3"])
def test_fine_mesh_changes_the_ratio_little(ironing):
    """Halving the mesh size (the benchmark's default mesh, about 4 minutes) moves the
    frictional part of |Fx/Fy| by less than 1% and the total by less than 3%."""
    fine, _ = ironing_run(ironing["mu"])
    for part in ("contact_friction", None):
        coarse_ratio = steady_ratio(ironing["history"], part=part)
        fine_ratio = steady_ratio(fine["history"], part=part)
        assert fine_ratio == pytest.approx(coarse_ratio, rel=0.01 if part else 0.03)
