"""Finite-strain J2 plasticity: uniaxial tension and compression of a bar to large strain
against the yield condition, hardening, the consistent tangent, indentation with an
imprint, and bad input."""

import dolfinx
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import pytest
from conftest import assert_taylor_slopes
from mpi4py import MPI

from contact_ufl.loads import Dirichlet
from contact_ufl.output import ResultWriter
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples, lowest_displacement, stored_energy
from contact_ufl.scene import Body, Scene
from contact_ufl.verification import scenes
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.taylor_cases import smooth_field

E, NU, SIGMA_Y = 1.0, 0.3, 0.01


def bar(material, stretch):
    """The unit cube on rollers at x = 0, y = 0, z = 0 (homogeneous uniaxial stress), its
    face x = 1 moved by ``stretch(t)``; tag 4 is that face."""
    mesh = dolfinx.mesh.create_unit_cube(MPI.COMM_WORLD, 2, 2, 2, dolfinx.mesh.CellType.hexahedron)
    sides = [lambda x, k=k, v=v: np.isclose(x[k], v) for k, v in ((0, 0), (1, 0), (2, 0), (0, 1))]
    cells, facets = tag_single_body(mesh, sides)
    rollers = [Dirichlet(k + 1, 0.0, component=k) for k in range(3)]
    scene = Scene(
        mesh,
        cells,
        facets,
        [Body(1, material)],
        dirichlet=[*rollers, Dirichlet(4, stretch, component=0)],
    )
    return ContactProblem(scene, verbose=False)


def there_and_back(t: float) -> float:
    """Stretch to 1.5 (t = 0 to 1), then back to 1.05 (t = 1 to 1.9)."""
    return 0.5 * (t if t <= 1.0 else 2.0 - t)


def uniaxial_kirchhoff(problem, stretch) -> list[tuple[float, float]]:
    """Per converged step: the stretch and the Kirchhoff stress tau_11 = R lambda_1 (the
    reaction R on the unit reference area, Cauchy R / (l2 l3), tau = J sigma)."""
    records = []

    def record(problem, step):
        l1 = 1.0 + stretch(step.t)
        records.append((l1, problem.reaction(4)[0] * l1))

    problem.solve(num_steps=10, t_end=1.0, callback=record)
    problem.solve(num_steps=9, t_end=1.9, callback=record)
    return records


def test_perfect_plasticity_holds_the_yield_stress():
    """Without hardening, tau_11 = sigma_y at every step of the loading beyond yield (to
    stretch 1.5) and tau_11 = -sigma_y once reversed loading yields in compression: the
    analytic uniaxial solution at any strain. Newton takes at most 5 iterations per step
    (4 measured)."""
    problem = bar(J2Plasticity(E, NU, SIGMA_Y), there_and_back)
    records = uniaxial_kirchhoff(problem, there_and_back)
    loading, reversed_ = records[:10], records[11:]
    for _, tau in loading:
        assert tau == pytest.approx(SIGMA_Y, rel=1e-8)
    for _, tau in reversed_:
        assert tau == pytest.approx(-SIGMA_Y, rel=1e-8)
    assert all(s.newton_iterations <= 5 for s in problem.history.steps)


def test_linear_hardening_follows_the_yield_surface():
    """With hardening H the converged stress sits on the hardened yield surface,
    tau_11 = sigma_y + H alpha with the committed equivalent plastic strain, which grows
    with the stretch; the small-strain limit is the bilinear law (to 0.1%: at 2% strain
    the finite-strain response differs from it by 0.04%)."""
    H = 0.1
    problem = bar(J2Plasticity(E, NU, SIGMA_Y, hardening=H), lambda t: 0.5 * t)
    alpha = problem.histories[1].alpha
    previous = 0.0
    for k in range(1, 6):
        problem.solve(num_steps=1, t_end=0.2 * k)
        l1 = 1.0 + 0.1 * k
        tau = problem.reaction(4)[0] * l1
        a = problem.comm.allreduce(alpha.x.array.max(initial=-np.inf), op=MPI.MAX)
        a_min = problem.comm.allreduce(alpha.x.array.min(initial=np.inf), op=MPI.MIN)
        assert a == pytest.approx(a_min, rel=1e-7)  # homogeneous, to solver tolerance
        assert tau == pytest.approx(SIGMA_Y + H * a, rel=1e-8)
        assert a > previous
        previous = a
    # plastic flow keeps the volume: det C_p^-1 = 1 at every point
    Cp_inv = problem.histories[1].Cp_inv.x.array.reshape(-1, 3, 3)
    assert np.allclose(np.linalg.det(Cp_inv), 1.0, rtol=0.0, atol=1e-12)
    assert problem.comm.allreduce(np.abs(Cp_inv[:, 0, 0] - 1.0).max(initial=0.0), op=MPI.MAX) > 0.1
    small = bar(J2Plasticity(E, NU, SIGMA_Y, hardening=H), lambda t: 0.002 * t)
    small.solve(num_steps=4, t_end=10.0)  # strain 2%, twice the yield strain
    eps = 0.02
    bilinear = SIGMA_Y + E * H / (E + H) * (eps - SIGMA_Y / E)
    assert small.reaction(4)[0] * (1.0 + eps) == pytest.approx(bilinear, rel=1e-3)


def test_elastic_below_yield():
    """Below yield nothing flows: no plastic strain, and the bar unloads to zero force."""
    problem = bar(J2Plasticity(E, NU, SIGMA_Y), lambda t: 0.004 * (t if t <= 1.0 else 2.0 - t))
    problem.solve(num_steps=2, t_end=1.0)
    alpha = problem.histories[1].alpha.x.array
    assert problem.comm.allreduce(alpha.max(initial=0.0), op=MPI.MAX) == 0.0
    problem.solve(num_steps=2, t_end=2.0)
    assert abs(problem.reaction(4)[0]) < 1e-12


def test_consistent_tangent_in_plastic_flow():
    """The tangent of the return map (ufl.derivative through the radial return): the Taylor
    remainder is second order at a state flowing plastically with hardening."""
    problem = bar(J2Plasticity(E, NU, SIGMA_Y, hardening=0.1), lambda t: 0.1 * t)
    problem.solve(num_steps=2, t_end=1.0)  # committed history of a plastic state
    x = problem.V.tabulate_dof_coordinates()
    values = problem.u.x.array.reshape(-1, 3)
    values[:, 0] += 0.01 * x[:, 0]  # further stretch: every point flows
    fem_petsc.assign([problem.u], problem.solver.x)
    direction = problem.solver.x.duplicate()
    field = dolfinx.fem.Function(problem.V)
    field.x.array[:] = smooth_field(x.T, 1.0, 3).T.ravel()
    fem_petsc.assign([field], direction)
    assert_taylor_slopes(problem, direction, [1e-3 * 2.0**-k for k in range(4)], unchanged=False)


def test_bad_plastic_input():
    with pytest.raises(ValueError, match="yield stress"):
        J2Plasticity(E, NU, 0.0)
    with pytest.raises(ValueError, match="hardening"):
        J2Plasticity(E, NU, SIGMA_Y, hardening=-1.0)
    with pytest.raises(ValueError, match="Poisson"):
        J2Plasticity(E, 0.5, SIGMA_Y)
    problem = bar(J2Plasticity(E, NU, SIGMA_Y), lambda t: 0.0)
    with pytest.raises(ValueError, match="elastoplastic"):
        stored_energy(problem)


def _indent_and_lift(yield_stress, comm=MPI.COMM_WORLD):
    """Press the cylinder in 8 steps, lift it off in 8: the problem, the peak contact
    pressure at the deepest point and the depth of the imprint."""
    scene = scenes.plastic_indentation(yield_stress=yield_stress, comm=comm)
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=8, t_end=1.0)
    peak = contact_samples(problem).pressure.max()
    problem.solve(num_steps=8, t_end=2.0)
    return problem, peak, -lowest_displacement(problem, "block_contact")


@pytest.mark.serial  # 2 ranks: test_indentation_on_any_number_of_ranks
def test_indentation_leaves_an_imprint():
    """A stiff cylinder pressed 0.02 into a perfectly plastic block (sigma_y = 0.01 E) and
    lifted off: the peak contact pressure is capped below the plane-strain indentation
    hardness (Prandtl's (2 + pi) k = 2.97 sigma_y, k = sigma_y / sqrt(3), the flat
    punch's bound), at 2.846 sigma_y, where the elastic block reaches 6.024 sigma_y; the
    plastic block keeps an imprint of 40.6% of the depth, the elastic one springs back to
    1e-11; both lift off completely. The values are this mesh's (to 0.002 sigma_y and 0.2%
    of the depth), not a converged limit."""
    sigma_y, depth = 0.01, 0.02
    plastic, peak, imprint = _indent_and_lift(sigma_y)
    elastic, elastic_peak, spring_back = _indent_and_lift(None)
    assert elastic_peak / sigma_y == pytest.approx(6.024, abs=0.002)
    hardness = (2.0 + np.pi) / np.sqrt(3.0) * sigma_y
    assert peak < hardness
    assert peak / sigma_y == pytest.approx(2.846, abs=0.002)
    assert imprint / depth == pytest.approx(0.406, abs=0.002)
    assert abs(spring_back) < 1e-11
    # the history moves in the block only: the elastic disc has no plastic strain
    (history,) = plastic.histories.values()
    disc = plastic.scene.cell_tags.find(plastic.scene.tags["cylinder"])
    dofs = history.alpha.function_space.dofmap.list[disc]
    assert plastic.comm.allreduce(history.alpha.x.array[dofs].max(initial=0.0), op=MPI.MAX) == 0
    assert plastic.comm.allreduce(history.alpha.x.array.max(initial=0.0), op=MPI.MAX) > 0.01
    for problem in (plastic, elastic):
        assert problem.t == pytest.approx(2.0)
        assert problem.active_points() == 0
        assert np.linalg.norm(problem.contact_force()) == 0.0


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares a distributed solve")
def test_indentation_on_any_number_of_ranks():
    """The plastic indentation and lift-off distributed equals the solve on one rank (each
    rank redoes it alone), to solver tolerance: peak pressure, imprint, plastic strain and
    the contact force of every step. (The Newton iterations may differ by one in a step:
    round-off moves an intermediate iterate across the yield surface.)"""
    world, peak, imprint = _indent_and_lift(0.01)
    alone, peak_alone, imprint_alone = _indent_and_lift(0.01, comm=MPI.COMM_SELF)
    assert peak == pytest.approx(peak_alone, rel=1e-7)
    assert imprint == pytest.approx(imprint_alone, rel=1e-7)
    (history,) = world.histories.values()
    alpha = world.comm.allreduce(history.alpha.x.array.max(initial=0.0), op=MPI.MAX)
    (history_alone,) = alone.histories.values()
    assert alpha == pytest.approx(history_alone.alpha.x.array.max(), rel=1e-7)
    forces = [[s.contact_force for s in p.history.steps] for p in (world, alone)]
    scale = max(np.linalg.norm(f) for f in forces[1])
    assert len(forces[0]) == len(forces[1]) == 16
    assert np.allclose(*forces, rtol=0, atol=1e-7 * scale)


def test_plastic_strain_is_written(tmp_path_factory):
    """The results writer writes the cell means of the equivalent plastic strain; in the
    homogeneous bar they equal the history at every point."""
    folder = tmp_path_factory.mktemp("plastic") if MPI.COMM_WORLD.rank == 0 else None
    folder = MPI.COMM_WORLD.bcast(folder)
    problem = bar(J2Plasticity(E, NU, SIGMA_Y, hardening=0.1), lambda t: 0.1 * t)
    writer = ResultWriter(problem, folder)
    problem.solve(num_steps=2, t_end=1.0, callback=writer)
    writer.close()
    history = problem.histories[1]
    alpha = problem.comm.allreduce(history.alpha.x.array.max(initial=-np.inf), op=MPI.MAX)
    assert alpha > 0.0
    assert np.allclose(history.plastic_strain.x.array, alpha, rtol=1e-7)
    assert (folder / "plastic_strain_1.bp").exists()
