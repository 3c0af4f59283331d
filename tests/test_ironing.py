"""Shallow ironing (large frictional sliding), coarse meshes: slow, run with ``-m slow``."""

import pytest

from contact_ufl.verification import IRONING_LITERATURE, ironing_run, steady_ratio

COARSE = dict(h_punch=0.05, h_block=0.2, slide_steps=100)


@pytest.mark.slow
@pytest.mark.serial
def test_frictionless_ironing_has_no_tangential_force():
    run, _ = ironing_run(0.0, **COARSE)
    assert run["history"][-1]["time"] == pytest.approx(2.0)
    assert all(r["converged"] for r in run["history"])
    assert steady_ratio(run["history"]) < 0.02


@pytest.mark.slow
@pytest.mark.serial
def test_frictional_ironing_global_friction_coefficient():
    """|Fx/Fy| in steady sliding lies in the published range for mu = 0.3 (0.30-0.53)."""
    run, _ = ironing_run(0.3, **COARSE)
    assert run["history"][-1]["time"] == pytest.approx(2.0)
    ratio = steady_ratio(run["history"])
    published = IRONING_LITERATURE.values()
    assert min(published) <= ratio <= max(published)
