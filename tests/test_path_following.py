"""Past a limit point: the inflation of a Neo-Hookean balloon controlled by its volume.

Under a prescribed pressure an incompressible Neo-Hookean spherical membrane has a pressure
maximum, ``p = 2 mu t0 / R (1/l - 1/l^7)`` is largest at the stretch ``l = 7^(1/6)``:
load control cannot pass it. Controlled by its enclosed volume (the pressure an unknown,
:class:`contact_ufl.control.VolumeControl`) the inflation goes through it, and the pressure
follows the closed form on both sides.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.control import VolumeControl
from contact_ufl.taylor import taylor_test
from contact_ufl.verification import analytic, scenes

COMM = MPI.COMM_WORLD
MU, T0, R = 1.0, 0.01, 1.0
STRETCH_END = 1.6  # beyond the maximum at 7^(1/6) = 1.383
P_MAX = analytic.sphere_inflation_neo_hookean(MU, T0, R, 7.0 ** (1.0 / 6.0))
CASE = "Neo-Hookean spherical membrane octant (n = 32), volume-controlled to stretch 1.6"
BALLOON = "closed form: p = 2 mu t0 / R (1/l - 1/l^7) of the inflated sphere"
#: the pressure along the path against the closed form (measured 6.7e-4: the faceted
#: sphere), and its largest value over the 12 steps against the closed-form maximum
#: (measured 9.5e-5)
PATH_TOL, PEAK_TOL = 1e-3, 2e-4
#: to the Newton tolerance: the prescribed volume met at the end (measured 4.8e-14), and
#: equilibrium (measured 2.8e-13)
VOLUME_TOL, EQUILIBRIUM_TOL = 1e-13, 6e-13
#: Taylor slopes of the bordered tangent: |slope - 2| (measured 4.4e-4)
TAYLOR_TOL = 1e-3


def balloon(control) -> cu.Scene:
    """The sphere octant of :func:`~contact_ufl.verification.scenes.inflated_sphere` with
    the pressure load replaced by ``control`` (or a pressure, for load control)."""
    (domain,) = scenes.inflated_sphere(n=32, law=cu.MembraneNeoHookean(MU, T0)).domains
    return cu.Scene(domains=[dataclasses.replace(domain, loads=[control])])


@pytest.fixture(scope="module")
def inflated():
    ratio = STRETCH_END**3 - 1.0
    problem = cu.ContactProblem(
        balloon(VolumeControl("membrane", lambda t: 1.0 + ratio * t)), verbose=False
    )
    (control,) = problem.controls
    path = []

    def record(problem, step):
        stretch = (control.volume() / control.reference_volume) ** (1.0 / 3.0)
        path.append((stretch, control.pressure))

    problem.solve(num_steps=12, callback=record)
    return problem, np.array(path)


def test_volume_control_passes_the_pressure_maximum(inflated, verification):
    """Every step converges; the pressure rises to its maximum and falls past it, and
    follows the closed form within PATH_TOL (the faceted sphere) on both sides."""
    problem, path = inflated
    assert len(problem.history.steps) == 12 and not problem.history.cutbacks
    stretch, pressure = path.T
    peak = np.argmax(pressure)
    assert 0 < peak < len(pressure) - 1  # a maximum inside the path
    assert np.all(np.diff(pressure[peak:]) < 0.0) and np.all(np.diff(pressure[: peak + 1]) > 0)
    exact = analytic.sphere_inflation_neo_hookean(MU, T0, R, stretch)
    path_error = np.abs(pressure / exact - 1.0).max()
    peak_error = abs(pressure.max() / P_MAX - 1.0)
    volume_error = abs(stretch[-1] / STRETCH_END - 1.0)
    verification(
        CASE,
        "max relative error of the pressure along the path",
        path_error,
        "p(l) at the computed stretches",
        f"< {PATH_TOL:g}",
        BALLOON,
    )
    verification(
        CASE,
        "relative error of the largest pressure",
        peak_error,
        P_MAX,
        f"< {PEAK_TOL:g}",
        f"{BALLOON}: its maximum at l = 7^(1/6)",
    )
    verification(
        CASE,
        "relative error of the final stretch (V / V0)^(1/3)",
        volume_error,
        STRETCH_END,
        f"< {VOLUME_TOL:g}",
        "the prescribed volume",
        kind="consistency",
    )
    assert path_error < PATH_TOL
    assert peak_error < PEAK_TOL
    assert volume_error < VOLUME_TOL


def test_volume_control_equilibrium(inflated, verification):
    """The unknown pressure's resultant balances the symmetry supports."""
    problem, _ = inflated
    from contact_ufl.results import equilibrium_error

    error = equilibrium_error(problem, ["x0", "y0", "z0"])
    verification(
        CASE,
        "equilibrium error of the pressure and the support reactions",
        error,
        0.0,
        f"< {EQUILIBRIUM_TOL:g}",
        "equilibrium of the converged solve",
        kind="consistency",
    )
    assert error < EQUILIBRIUM_TOL


def test_load_control_stops_at_the_maximum(verification):
    """The same balloon under a prescribed pressure 2% above the maximum, in 4 steps: the
    three steps below the maximum converge, and no step beyond it."""
    pressure = cu.FollowerPressure("membrane", lambda t: 1.02 * P_MAX * t)
    problem = cu.ContactProblem(balloon(pressure), verbose=False)
    with pytest.raises(cu.ConvergenceError, match="limit point"):
        problem.solve(num_steps=4, max_cutbacks=3)
    assert all("limit point" in c.why for c in problem.history.cutbacks)
    reached = problem.history.steps[-1].t if problem.history.steps else 0.0
    verification(
        "Neo-Hookean spherical membrane octant (n = 32), pressure-controlled to 1.02 p_max",
        "largest converged pressure over the closed-form maximum p_max",
        reached * 1.02,
        1.0,
        "in [0.765, 1)",
        f"{BALLOON}: no equilibrium above its maximum",
    )
    assert reached >= 0.75  # the steps below the maximum converged
    assert reached * 1.02 < 1.0  # stopped below the maximum


def test_taylor_with_the_pressure_unknown(inflated, verification):
    """The bordered tangent (load vector column, volume row): Taylor slope 2 along a
    direction that changes the displacement and the pressure."""
    problem, _ = inflated
    solver = problem.solver
    dz = solver.x.duplicate()
    rng = np.random.default_rng(COMM.rank)
    dz.array[:] = 1e-2 * rng.standard_normal(len(dz.array))
    dz.array[problem.dirichlet_rows] = 0.0
    result = taylor_test(problem, dz, [1e-2 * 2.0**-k for k in range(4)])
    verification(
        f"{CASE}, at the end",
        "Taylor slopes of the residual's remainder (displacement and pressure)",
        result.slopes,
        2.0,
        f"|slope - 2| < {TAYLOR_TOL:g}",
        "Taylor test: the remainder of an exact tangent falls as h^2",
    )
    assert np.all(np.abs(result.slopes - 2.0) < TAYLOR_TOL), result.slopes


def test_volume_control_needs_a_membrane():
    scene = scenes.patch()
    bad = dataclasses.replace(scene, loads=[VolumeControl("upper_top", 2.0)])
    with pytest.raises(cu.ContactInputError, match="needs a membrane"):
        cu.ContactProblem(bad, verbose=False)
