"""3D ironing (Puso & Laursen 2004, example 2) on the quick mesh, serial.

The die is pressed 1.4 into the slab in 5 steps and slid 0.4 in 2 more, with mu = 0.3
(about two minutes). The published force histories are curves with no digitised values
reachable here (:data:`contact_ufl.verification.literature.IRONING_3D`), so the checks are
those no publication is needed for: every step converges, the support balances the contact
force, the frictional part of the force opposes the sliding and is bounded by mu times the
normal part, and the pressing force grows with the depth. The whole path of the quick
benchmark (``benchmarks/ironing_3d.py --quick``) is a slow test.
"""

import numpy as np
import pytest

from contact_ufl.verification.literature import IRONING_3D
from contact_ufl.verification.runs import ironing_3d_run

QUICK = dict(h_die=0.6, h_slab=0.75)


@pytest.fixture(scope="module")
def slide_start():
    """mu = 0.3: pressed 1.4 in 5 steps, then slid 0.4 in 2."""
    run, _ = ironing_3d_run(0.3, press_steps=5, slide_steps=2, t_end=1.1, **QUICK)
    return run


@pytest.mark.serial
def test_every_step_converges(slide_start):
    """SNES's converged reason at every accepted step, no cut-back, to t = 1.1."""
    history = slide_start["history"]
    assert len(history) == 7 and history[-1]["time"] == pytest.approx(1.1)
    assert all(r["converged"] for r in history)
    assert all(r["snes_reason"].startswith("CONVERGED") for r in history)
    assert not slide_start["cutbacks"]


@pytest.mark.serial
def test_pressing_force_grows_and_balances(slide_start):
    """While pressing the slab pushes the die up harder at every step (Fz < 0: the support
    holds the die down), the force across the slab (y) is nil by symmetry, and at every
    step the support balances the contact force to 1e-8 of the largest force (action equals
    reaction: a check of the post-processing)."""
    history = slide_start["history"]
    Fz = np.array([r["Fz"] for r in history[:5]])
    assert np.all(Fz > 0.0) or np.all(Fz < 0.0)
    assert np.all(np.diff(np.abs(Fz)) > 0.0)
    scale = max(abs(r["Fz"]) for r in history)
    for r in history:
        assert abs(r["Fy"]) < 1e-2 * scale
        total = np.add(r["contact_normal"], r["contact_friction"])
        assert np.linalg.norm(total + [r["Fx"], r["Fy"], r["Fz"]]) < 1e-8 * scale


@pytest.mark.serial
def test_friction_opposes_the_sliding(slide_start):
    """Sliding in +x, the frictional part of the contact force on the die points in -x
    and is a sizeable fraction of mu times the pressing force; before sliding (t <= 1) it
    is small."""
    history = slide_start["history"]
    slid = history[-1]
    friction_x = slid["contact_friction"][0]
    assert friction_x < 0.0
    assert abs(friction_x) > 0.3 * 0.3 * abs(slid["Fz"])
    pressed = history[4]
    assert abs(pressed["contact_friction"][0]) < abs(friction_x)


@pytest.mark.serial
def test_no_published_numbers_are_invented():
    """The literature entry says what is missing instead of holding numbers."""
    assert IRONING_3D["forces"] == {}
    assert IRONING_3D["status"].startswith("TODO")
