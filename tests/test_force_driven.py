"""Bodies held only by contact, pushed by a force (issue: force-driven contact).

A body whose only support in the contact direction is the contact itself is free until it
touches: at the start of the first step its tangent is singular and no Newton step finds the
contact. The solver's closing iterate (:meth:`contact_ufl.newton.NewtonSolver.solve_step`)
ties the points nearest the master surface for one iterate; the solution is that of the
same equations, so it must equal the displacement-driven solution that carries the same
force (2D Hertz, stiff realistic moduli), and the closed form of the patch test (3D, from a
gap).
"""

import numpy as np
import pytest
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.results import contact_samples
from contact_ufl.verification import scenes

E_STEEL = scenes.E_STEEL


def hertz_scene(driven_by: str, value: float, gap: float = 0.0) -> cu.Scene:
    """The 2D Hertz half disc on a block (:func:`scenes.hertz_2d_driven`)."""
    return scenes.hertz_2d_driven(driven_by, value, gap=gap)


def solved(scene: cu.Scene, steps: int = 2) -> cu.ContactProblem:
    problem = cu.ContactProblem(scene, verbose=False)
    problem.solve(num_steps=steps)
    return problem


def peak_and_width(problem) -> tuple[float, float]:
    samples = contact_samples(problem)
    pressed = samples.x[samples.lambda_N > 1e-3 * samples.lambda_N.max(), 0]
    return float(samples.lambda_N.max()), float(np.ptp(pressed))


@pytest.fixture(scope="module")
def displacement_driven():
    return solved(hertz_scene("displacement", 0.002))


@pytest.fixture(scope="module")
def force(displacement_driven):
    """The contact force of the displacement-driven scene."""
    return displacement_driven.contact_force()[1]


def test_force_driven_hertz_equals_displacement_driven(displacement_driven, force):
    """The same force through a dead traction: the same contact zone and peak pressure
    (measured 4e-5: the top's boundary condition is far from the contact)."""
    problem = solved(hertz_scene("force", force))
    assert not problem.history.cutbacks and len(problem.history.steps) == 2
    assert problem.contact_force()[1] == pytest.approx(force, rel=1e-8)
    peak, width = peak_and_width(problem)
    peak0, width0 = peak_and_width(displacement_driven)
    assert abs(peak / peak0 - 1.0) < 1e-3
    assert abs(width / width0 - 1.0) < 1e-3
    assert problem.active_points() == displacement_driven.active_points()


def test_force_driven_hertz_from_a_gap(displacement_driven, force):
    """The disc starts 1e-3 above the block (half the depth of the displacement-driven
    scene): the same load closes the gap and gives the same peak (measured 0.2%: the
    meshes differ)."""
    problem = solved(hertz_scene("force", force, gap=1e-3))
    assert not problem.history.cutbacks
    peak, _ = peak_and_width(problem)
    assert abs(peak / peak_and_width(displacement_driven)[0] - 1.0) < 5e-3


def test_without_the_closing_iterate_the_first_step_fails():
    """The same scene, the closing iterate switched off: no step converges."""
    problem = cu.ContactProblem(hertz_scene("force", 8e7), verbose=False)
    problem.solver.close_gaps = False
    with pytest.raises(cu.ConvergenceError, match="from t = 0 "):
        problem.solve(num_steps=2, max_cutbacks=1)


@pytest.mark.parametrize(
    "cell, degree, subdivisions, tolerance",
    [("tetrahedron", 2, 4, 1e-2), ("hexahedron", 3, 2, 3e-2)],
)
def test_force_driven_patch_3d_from_a_gap(cell, degree, subdivisions, tolerance):
    """A steel block pressed by a dead pressure onto another from a gap of 1e-3 (a tenth of
    an element): lambda_N is the pressure (closed form; tolerances of the touching patch
    test), and equals the touching start's to solver tolerance."""
    pressure = 1e-4 * E_STEEL

    def run(gap):
        scene = scenes.patch_3d_pressed(
            pressure, gap, cell=cell, quadrature_degree=degree, subdivisions=subdivisions
        )
        problem = solved(scene, steps=1)
        assert not problem.history.cutbacks
        return problem.contacts[0].lambda_N.x.array.copy(), problem

    lam, problem = run(1e-3)
    assert np.abs(lam / pressure - 1.0).max() < tolerance
    touching, _ = run(0.0)
    difference = np.abs(lam - touching).max() / pressure
    assert problem.comm.allreduce(difference, op=MPI.MAX) < 1e-6
