"""3D ironing (Puso & Laursen 2004, example 2) on the quick mesh of
benchmarks/ironing_3d.py, serial: the die pressed 1.4 into the slab in 10 steps, then slid 4
along it in 20, with mu = 0 and mu = 0.3 (about three minutes each: slow-marked).

The published force histories are curves with no digitised values
(:data:`contact_ufl.verification.literature.IRONING_3D`), so the checks are those that need
no publication: every step converges without cut-back, the support balances the contact
force, the frictionless history has the mirror symmetry of the slab, and with friction the
ratio of the frictional to the normal force is Coulomb's mu.
"""

import numpy as np
import pytest

from contact_ufl.verification import scenes
from contact_ufl.verification.literature import IRONING_3D, IRONING_FORCES
from contact_ufl.verification.runs import (
    coulomb_ratio_3d,
    history_at,
    ironing_3d_run,
    ironing_plane_strain_run,
)

QUICK = dict(h_die=0.6, h_slab=0.75, press_steps=10, slide_steps=20)

#: Bounds on the mirror asymmetry of the frictionless history, relative to |Fz| (measured
#: 1.4e-3 for Fx and 4.0e-3 for Fz: the mesh is not symmetric). A history that depended on
#: the path (as with friction) would miss them by far: |Fx(1) + Fx(2)| would be about
#: 2 |Fx(1)| = 5.7e-2 |Fz|.
FX_SYM, FZ_SYM = 5e-3, 1e-2


@pytest.fixture(scope="module")
def runs():
    """mu -> the run (records of the 30 steps); made on first use."""
    made = {}

    def run(mu: float) -> dict:
        if mu not in made:
            made[mu] = ironing_3d_run(mu, **QUICK)[0]
        return made[mu]

    return run


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_every_step_converges(runs, mu):
    """SNES's converged reason at every accepted step, no cut-back, to t = 2 (the slide's
    end), with few Newton iterations per step (3 to 6 measured)."""
    run = runs(mu)
    history = run["history"]
    assert len(history) == 30 and history[-1]["time"] == pytest.approx(2.0)
    assert all(r["converged"] for r in history)
    assert all(r["snes_reason"].startswith("CONVERGED") for r in history)
    assert not run["cutbacks"]
    assert max(r["newton_iterations"] for r in history) <= 10


@pytest.mark.slow
@pytest.mark.serial
def test_pressing_force_grows_and_balances(runs):
    """While pressing (mu = 0) the slab pushes the die up harder at every step, the force
    across the slab (y) is nil by symmetry, and at every step the contact force on the slab
    (the slave) equals the force of the support on the die's top to 1e-6 of the largest
    force (action equals reaction: a check of the post-processing; the bound is SNES's
    absolute tolerance, about 1e-6 here)."""
    history = runs(0.0)["history"]
    pressing = history[:10]
    Fz = np.array([r["Fz"] for r in pressing])
    assert np.all(Fz < 0.0)  # the support holds the die down
    assert np.all(np.diff(np.abs(Fz)) > 0.0)
    scale = max(abs(r["Fz"]) for r in history)
    for r in history:
        assert abs(r["Fy"]) < 1e-2 * scale
        total = np.add(r["contact_normal"], r["contact_friction"])
        assert np.linalg.norm(total - [r["Fx"], r["Fy"], r["Fz"]]) < 1e-6 * scale


@pytest.mark.slow
@pytest.mark.serial
def test_frictionless_history_is_mirror_symmetric(runs):
    """mu = 0: the frictionless elastic state depends on the die's position only, and the
    slab is symmetric about its middle x = 4.5, where the die is at t = 1.5: Fx(1) = -Fx(2),
    Fz(1) = Fz(2) (the die 2.5 from either end) and Fx(1.5) = 0, up to the mesh, which is
    not symmetric (bounds FX_SYM and FZ_SYM of |Fz|)."""
    history = runs(0.0)["history"]
    fz = abs(history_at(history, 1.0, "Fz"))
    fx1, fx2 = history[9]["Fx"], history[-1]["Fx"]
    assert abs(fx1) > 0.01 * fz  # the die 2.5 from the left end is pushed towards it
    assert abs(fx1 + fx2) < FX_SYM * fz
    assert abs(history_at(history, 1.0, "Fz") - history_at(history, 2.0, "Fz")) < FZ_SYM * fz
    assert abs(history[19]["Fx"]) < FX_SYM * fz


@pytest.mark.slow
@pytest.mark.serial
def test_coulomb_ratio_in_steady_sliding(runs):
    """mu = 0.3: over the steady slide (1.5 <= t <= 1.9) the frictional force along the
    slide over the normal force's vertical part is mu where the whole contact slides along
    x (:func:`coulomb_ratio_3d`; measured 0.2994, a little less since the slab's top also
    slips across the slide where it bulges), and at no step above it; the total |Fx / Fz|
    exceeds it by the ploughing (the slab pushing back on the die's front; by 0.03 to 0.06)."""
    history = runs(0.3)["history"]
    ratio = coulomb_ratio_3d(history)
    assert 0.99 * 0.3 < ratio <= 0.3
    sliding = [r for r in history if r["time"] > 1.0]
    assert all(abs(r["contact_friction"][0] / r["contact_normal"][2]) <= 0.3 for r in sliding)
    steady = [r for r in history if 1.5 <= r["time"] <= 1.9]
    assert all(abs(r["Fx"] / r["Fz"]) > ratio + 0.01 for r in steady)


def test_slave_choice_is_checked():
    """A wrong slave name is a clear error (before any mesh is made)."""
    with pytest.raises(ValueError, match="slave must be 'slab' or 'die'"):
        scenes.ironing_3d(slave="punch")


def test_no_published_numbers_are_invented():
    """The literature entry says what was found and holds no numbers."""
    assert IRONING_3D["forces"] == {}
    assert IRONING_3D["status"].startswith("curves only")
    assert len(IRONING_3D["sources"]) >= 3


def test_frictional_pressing_keeps_the_solver_pattern():
    """Regression: the 3D ironing with mu = 0.3 on the quick mesh, pressed in 0.1 steps past
    the seventh, where a pairing whose gathers lay in the union of two earlier patterns (but
    in neither alone) put a new nonzero outside the solver matrix's pattern and stopped the
    run. Every step converges, without cut-back."""
    from contact_ufl.problem import ContactProblem

    scene = scenes.ironing_3d(mu=0.3, h_die=0.6, h_slab=0.75)
    problem = ContactProblem(scene, verbose=False, petsc_options={"snes_max_it": 40})
    problem.solve(num_steps=8, t_end=0.8, max_cutbacks=0)
    assert len(problem.history.steps) == 8
    assert not problem.history.cutbacks


# -- the 2D shallow ironing extruded: plane strain solved by the 3D machinery ----------------


def test_extruded_ironing_equals_the_plane_one():
    """The 2D shallow ironing (mu = 0.3) on its quick quadrilateral mesh, pressed in five
    steps, in 2D and extruded through 0.1 by one layer of hexahedra with u_z = 0 on both
    faces (:func:`scenes.ironing_plane_strain`), with the facet master normal: the extruded
    problem is the plane-strain one, so its forces per unit thickness equal the 2D ones to
    the solver's tolerance (measured: 1e-14 of |fy|, the same Newton iterates; the bound
    1e-6 of |fy| is what two solutions converged to SNES's rtol, 1e-9 of a step's first
    residual, may differ by where one stops an iterate earlier: measured up to 2e-7 over 20
    pressing steps and the slide to t = 1.1), with friction acting (its part of the force
    along the block is 10% of |fy| at t = 1), no force across the plane, and every step
    converged in the same number of Newton iterations, give or take one.
    Regression: the contact held every component of lambda_T at the slave nodes where u_z
    is prescribed (all of them here), leaving only the penalty part eps_T s_T of the
    friction: the frictional force 21% low and fx off by 2% of |fy| at t = 1."""
    options = dict(mu=0.3, press_steps=5, slide_steps=0, t_end=1.0, master_normal="facet")
    plane = ironing_plane_strain_run(thickness=None, **options)[0]["history"]
    extruded = ironing_plane_strain_run(thickness=0.1, **options)[0]["history"]
    assert len(plane) == len(extruded) == 5
    assert all(r["converged"] for r in plane + extruded)
    scale = max(abs(r["fy"]) for r in plane)
    for a, b in zip(plane, extruded, strict=True):
        assert abs(a["fx"] - b["fx"]) < 1e-6 * scale
        assert abs(a["fy"] - b["fy"]) < 1e-6 * scale
        assert abs(b["Fz"]) < 1e-9 * scale * 0.1
        assert abs(a["newton_iterations"] - b["newton_iterations"]) <= 1
    friction = extruded[-1]["contact_friction"][0] / 0.1
    assert abs(friction) > 0.05 * abs(extruded[-1]["fy"])
    assert abs(friction - plane[-1]["contact_friction"][0]) < 1e-6 * scale


#: The published forces at t = 1.0 and 1.5 (mu = 0.3): (time, key, index in IRONING_FORCES).
PUBLISHED = [(1.0, "fy", 0, 0), (1.0, "fx", 0, 1), (1.5, "fy", 1, 0), (1.5, "fx", 1, 1)]


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("mu", [0.0, 0.3], ids=["mu=0", "mu=0.3"])
def test_extruded_ironing_slides_as_the_plane_one(mu):
    """The quick run of benchmarks/ironing_plane_strain.py (smoothed normal, 20 + 100 steps;
    11 and 19 minutes for the extruded runs on a shared machine): every accepted step of
    the extruded run converged (its cut-backs, 1 measured with each mu, are retried steps,
    none accepted unconverged), no force across the plane, and its force history per unit
    thickness follows the 2D run on the same plane mesh within 1e-2 of max |fy| (measured:
    4.4e-3 for fx and 9.8e-4 for fy with mu = 0.3, 8.5e-4 and 1.6e-4 with mu = 0; the
    two smoothed normals average the nodal
    normals differently, which the facet normal does not: see
    test_extruded_ironing_equals_the_plane_one). With mu = 0.3 its forces at t = 1 and 1.5
    lie within the spread of the six publications of IRONING_FORCES."""
    options = dict(mu=mu, h_punch=0.05, h_block=0.2, press_steps=20, slide_steps=100)
    plane = ironing_plane_strain_run(thickness=None, **options)[0]
    run = ironing_plane_strain_run(thickness=0.1, **options)[0]
    history = run["history"]
    assert history[-1]["time"] == pytest.approx(2.0)
    assert all(r["converged"] for r in history)
    assert len(run["cutbacks"]) <= 2
    scale = max(abs(r["fy"]) for r in plane["history"])
    assert max(abs(r["Fz"]) for r in history) < 1e-9 * scale * 0.1
    at = {round(r["time"], 9): r for r in plane["history"]}
    common = [(at[round(r["time"], 9)], r) for r in history if round(r["time"], 9) in at]
    assert len(common) >= 100
    for key in ("fx", "fy"):
        assert max(abs(a[key] - b[key]) for a, b in common) < 1e-2 * scale
    if mu == 0.3:
        for t, key, k, j in PUBLISHED:
            values = [forces[k][j] for forces in IRONING_FORCES.values()]
            assert min(values) <= history_at(history, t, key) <= max(values)
