"""Finite-strain J2 plasticity: uniaxial tension and compression of a bar to large strain
against the yield condition and against the return map of Simo & Hughes (1998), Box 9.1,
evaluated for the homogeneous state; hardening, the consistent tangent, indentation with an
imprint (against a snapshot of this code's output and Prandtl's bound), and bad input."""

import dolfinx
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import pytest
from conftest import across_ranks
from mpi4py import MPI
from scipy.optimize import brentq

from contact_ufl.loads import Dirichlet
from contact_ufl.output import ResultWriter
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples, lowest_displacement, stored_energy
from contact_ufl.scene import Body, Scene
from contact_ufl.taylor import taylor_test
from contact_ufl.verification import scenes
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.taylor_cases import smooth_field

E, NU, SIGMA_Y = 1.0, 0.3, 0.01
BAR = "unit cube in uniaxial stress (rollers), hexahedra 2 x 2 x 2, E = 1, nu = 0.3"
UNIAXIAL = "closed form: the yield condition in uniaxial stress, |tau_11| = sigma_y"
BOX = (
    "Simo & Hughes, Computational Inelasticity (1998), Box 9.1: its return map for the "
    "homogeneous uniaxial state, step by step (numpy, in this test)"
)
#: the Kirchhoff stress on the yield surface of perfect plasticity, to the Newton tolerance:
#: measured 8.4e-11 on 1 rank, 1.5e-9 on 2 (the last Newton iterate differs with the
#: partition)
YIELD_TOL = 3e-9
#: tau_11 and alpha of the hardening bar against the box's return map, and tau_11 against
#: the hardened yield surface, to the Newton tolerance: measured 2.6e-12 and 7.8e-13 on 1
#: rank, 4.9e-11 and 1.9e-11 on 2
BOX_TOL, SURFACE_TOL = 1e-10, 4e-11
#: the small-strain limit: the bilinear law at 2% strain (the finite-strain response differs
#: from it by 3.7e-4, measured)
BILINEAR_TOL = 1e-3
#: the plastic flow keeps the volume, det C_p^-1 = 1 to round-off (measured 1.0e-15)
VOLUME_TOL = 3e-15
#: the reaction of the bar unloaded below yield (measured 1.4e-13)
UNLOADED_TOL = 3e-13
#: the elastic block's remaining depth after lift-off (measured 3.0e-12)
SPRING_BACK_TOL = 6e-12
#: Taylor slopes of the algorithmic tangent in plastic flow: |slope - 2| (measured 5.8e-3)
TAYLOR_TOL = 0.01
#: a snapshot of this code's output (regression): the indentation's peak pressures over
#: sigma_y (plastic and elastic block) and the imprint over the depth, to 4 decimals (1 and 2
#: ranks agree to 1e-7)
SNAPSHOT = {"plastic peak": 2.8459, "elastic peak": 6.0225, "imprint": 0.4056}
SNAPSHOT_TOL = 2e-4


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


def uniaxial_return_map(material: J2Plasticity, stretches) -> np.ndarray:
    """``(tau_11, alpha)`` after each step of the homogeneous uniaxial stress state ``F =
    diag(l1, l2, l2)``, ``tau_22 = 0``, stretched to ``stretches`` in turn, by the return map
    of Simo & Hughes (1998), Box 9.1, written out here for diagonal tensors: the trial
    ``bbar_e = J^(-2/3) F C_p^-1 F^T``, ``s = mu dev bbar_e``, ``mubar = mu tr(bbar_e) / 3``;
    where ``f = |s| - sqrt(2/3) (sigma_y + H alpha) > 0``, ``dgamma = f / (2 mubar (1 + H /
    (3 mubar)))``, ``s`` shortened by ``2 mubar dgamma``, ``alpha += sqrt(2/3) dgamma``;
    ``tau = kappa/2 (J^2 - 1) I + s``; the history ``bbar_e = s / mu + c I`` with ``det
    bbar_e = 1``. Each step solves ``tau_22(l2) = 0`` and ``det bbar_e = 1`` by bisection."""
    mu, kappa = material.mu, material.kappa
    sigma_y, H = material.yield_stress, material.hardening
    Cp_inv = np.ones(2)  # diag(c1, c2, c2)
    alpha = 0.0

    def return_map(l1, l2):
        J = l1 * l2**2
        b = J ** (-2.0 / 3.0) * np.array([l1**2 * Cp_inv[0], l2**2 * Cp_inv[1], l2**2 * Cp_inv[1]])
        I_e = b.sum() / 3.0
        s, mubar = mu * (b - I_e), mu * I_e
        norm = np.linalg.norm(s)
        f = norm - np.sqrt(2.0 / 3.0) * (sigma_y + H * alpha)
        dgamma = f / (2.0 * mubar * (1.0 + H / (3.0 * mubar))) if f > 0.0 else 0.0
        s = s * (1.0 - 2.0 * mubar * dgamma / norm)
        return 0.5 * kappa * (J**2 - 1.0) + s, s, J, I_e, dgamma

    out = []
    for l1 in stretches:
        l2 = brentq(lambda l2, l1: return_map(l1, l2)[0][1], 0.5, 1.5, args=(l1,), xtol=1e-15)
        tau, s, J, I_e, dgamma = return_map(l1, l2)
        c = brentq(lambda c, d: np.prod(d + c) - 1.0, I_e - 0.5, I_e + 0.5, args=(s / mu,))
        Cp_inv = J ** (2.0 / 3.0) * (s[:2] / mu + c) / np.array([l1**2, l2**2])
        alpha += np.sqrt(2.0 / 3.0) * dgamma
        out.append((tau[0], alpha))
    return np.array(out)


def test_perfect_plasticity_holds_the_yield_stress(verification):
    """Without hardening, tau_11 = sigma_y at every step of the loading beyond yield (to
    stretch 1.5) and tau_11 = -sigma_y once reversed loading yields in compression: the
    analytic uniaxial solution at any strain. Newton takes at most 5 iterations per step
    (4 measured)."""
    problem = bar(J2Plasticity(E, NU, SIGMA_Y), there_and_back)
    records = uniaxial_kirchhoff(problem, there_and_back)
    loading, reversed_ = records[:10], records[11:]
    tau = np.array([t for _, t in loading] + [-t for _, t in reversed_])
    error = np.abs(tau / SIGMA_Y - 1.0).max()
    verification(
        f"{BAR}, perfect plasticity, stretch to 1.5 and back to 1.05",
        "max |tau_11 / (+-sigma_y) - 1| beyond yield, both ways",
        error,
        "tau_11 = sigma_y (tension), -sigma_y (compression)",
        f"< {YIELD_TOL:g}",
        UNIAXIAL,
    )
    assert error < YIELD_TOL
    assert all(s.newton_iterations <= 5 for s in problem.history.steps)


def test_linear_hardening_follows_the_yield_surface(verification):
    """With hardening H the bar's Kirchhoff stress and equivalent plastic strain follow the
    return map of Simo & Hughes's Box 9.1 (evaluated here for the homogeneous state, step by
    step); the stress sits on the hardened yield surface, tau_11 = sigma_y + H alpha, with
    the committed plastic strain, which grows with the stretch; the small-strain limit is the
    bilinear law (to 0.1%: at 2% strain the finite-strain response differs from it by
    0.04%)."""
    H = 0.1
    material = J2Plasticity(E, NU, SIGMA_Y, hardening=H)
    problem = bar(material, lambda t: 0.5 * t)
    alpha = problem.histories[1].alpha
    computed = []
    for k in range(1, 6):
        problem.solve(num_steps=1, t_end=0.2 * k)
        tau = problem.reaction(4)[0] * (1.0 + 0.1 * k)
        a = problem.comm.allreduce(alpha.x.array.max(initial=-np.inf), op=MPI.MAX)
        a_min = problem.comm.allreduce(alpha.x.array.min(initial=np.inf), op=MPI.MIN)
        assert a == pytest.approx(a_min, rel=1e-7)  # homogeneous, to solver tolerance
        computed.append((tau, a))
    computed = np.array(computed)
    expected = uniaxial_return_map(material, 1.0 + 0.1 * np.arange(1, 6))
    box_error = np.abs(computed / expected - 1.0).max(axis=0)
    surface_error = np.abs(computed[:, 0] / (SIGMA_Y + H * computed[:, 1]) - 1.0).max()
    case = f"{BAR}, hardening H = 0.1, stretch 1.1 to 1.5 in 5 steps"
    for quantity, error in zip(("tau_11", "alpha"), box_error, strict=True):
        verification(
            case,
            f"max relative error of {quantity} over the steps",
            error,
            expected[:, 0 if quantity == "tau_11" else 1],
            f"< {BOX_TOL:g}",
            BOX,
        )
    verification(
        case,
        "max |tau_11 / (sigma_y + H alpha) - 1|",
        surface_error,
        "tau_11 = sigma_y + H alpha",
        f"< {SURFACE_TOL:g}",
        "the return map's consistency condition (the stress on the yield surface)",
        kind="consistency",
    )
    assert np.all(box_error < BOX_TOL), box_error
    assert surface_error < SURFACE_TOL
    assert np.all(np.diff(computed[:, 1]) > 0.0)
    # plastic flow keeps the volume: det C_p^-1 = 1 at every point (the box's correction of
    # the spherical part makes it so)
    Cp_inv = problem.histories[1].Cp_inv.x.array.reshape(-1, 3, 3)
    volume = np.abs(np.linalg.det(Cp_inv) - 1.0).max(initial=0.0)
    volume = problem.comm.allreduce(volume, op=MPI.MAX)
    verification(
        case,
        "max |det C_p^-1 - 1|",
        volume,
        0.0,
        f"< {VOLUME_TOL:g}",
        "the return map's correction of the spherical part: det bbar_e = 1 (Box 9.1)",
        kind="consistency",
    )
    assert volume < VOLUME_TOL
    assert problem.comm.allreduce(np.abs(Cp_inv[:, 0, 0] - 1.0).max(initial=0.0), op=MPI.MAX) > 0.1
    small = bar(J2Plasticity(E, NU, SIGMA_Y, hardening=H), lambda t: 0.002 * t)
    small.solve(num_steps=4, t_end=10.0)  # strain 2%, twice the yield strain
    eps = 0.02
    bilinear = SIGMA_Y + E * H / (E + H) * (eps - SIGMA_Y / E)
    error = small.reaction(4)[0] * (1.0 + eps) / bilinear - 1.0
    verification(
        f"{BAR}, hardening H = 0.1, 2% strain",
        "relative difference of tau_11 from the bilinear law",
        error,
        bilinear,
        f"|error| < {BILINEAR_TOL:g}",
        "closed form: small-strain bilinear elastoplasticity, E H / (E + H) beyond yield",
    )
    assert abs(error) < BILINEAR_TOL


def test_elastic_below_yield(verification):
    """Below yield nothing flows: no plastic strain, and the bar unloads to zero force."""
    problem = bar(J2Plasticity(E, NU, SIGMA_Y), lambda t: 0.004 * (t if t <= 1.0 else 2.0 - t))
    problem.solve(num_steps=2, t_end=1.0)
    alpha = problem.histories[1].alpha.x.array
    assert problem.comm.allreduce(alpha.max(initial=0.0), op=MPI.MAX) == 0.0
    problem.solve(num_steps=2, t_end=2.0)
    force = abs(problem.reaction(4)[0])
    verification(
        f"{BAR}, stretch 1.004 (below yield) and back",
        "|reaction| after unloading",
        force,
        0.0,
        f"< {UNLOADED_TOL:g}",
        "closed form: an elastic body back at its reference shape carries no stress",
    )
    assert force < UNLOADED_TOL


def test_consistent_tangent_in_plastic_flow(verification):
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
    steps = [1e-3 * 2.0**-k for k in range(4)]
    result = taylor_test(problem, direction, steps)
    verification(
        f"{BAR}, hardening H = 0.1, flowing at stretch 1.11",
        "Taylor slopes of the residual's remainder",
        result.slopes,
        2.0,
        f"|slope - 2| < {TAYLOR_TOL:g}",
        "Taylor test: the remainder of an exact tangent falls as h^2",
    )
    assert np.all(np.abs(result.slopes - 2.0) < TAYLOR_TOL), result.slopes


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
def test_indentation_leaves_an_imprint(verification):
    """A stiff cylinder pressed 0.02 into a perfectly plastic block (sigma_y = 0.01 E) and
    lifted off: the peak contact pressure is capped below the plane-strain indentation
    hardness (Prandtl's (2 + pi) k = 2.97 sigma_y, k = sigma_y / sqrt(3), the flat punch's
    bound), where the elastic block's peak is twice as high; the plastic block keeps an
    imprint, the elastic one springs back; both lift off completely. The peaks and the
    imprint are compared with a snapshot of this code's output on this mesh (regression: not
    a converged limit, no closed form)."""
    sigma_y, depth = 0.01, 0.02
    plastic, peak, imprint = _indent_and_lift(sigma_y)
    elastic, elastic_peak, spring_back = _indent_and_lift(None)
    hardness = (2.0 + np.pi) / np.sqrt(3.0) * sigma_y
    case = "cylinder pressed 0.02 into a block (sigma_y = 0.01 E) and lifted off"
    verification(
        f"{case}, perfectly plastic block",
        "peak contact pressure over Prandtl's hardness (2 + pi) sigma_y / sqrt(3)",
        peak / hardness,
        1.0,
        "< 1",
        "Prandtl's plane-strain flat-punch pressure, an upper bound of the indentation",
    )
    source = "snapshot of this code's output on the scene's default mesh, 4 decimals"
    values = {
        "plastic peak": ("perfectly plastic block", "peak pressure / sigma_y", peak / sigma_y),
        "elastic peak": ("elastic block", "peak pressure / sigma_y", elastic_peak / sigma_y),
        "imprint": (
            "perfectly plastic block",
            "imprint depth / indentation depth",
            imprint / depth,
        ),
    }
    for key, (block, quantity, value) in values.items():
        verification(
            f"{case}, {block}",
            quantity,
            value,
            SNAPSHOT[key],
            f"|difference| < {SNAPSHOT_TOL:g}",
            source,
            kind="regression",
        )
    verification(
        f"{case}, elastic block",
        "remaining depth after lift-off",
        abs(spring_back),
        0.0,
        f"< {SPRING_BACK_TOL:g}",
        "closed form: an elastic body unloaded returns to its reference shape",
    )
    assert peak < hardness
    for key, (_, _, value) in values.items():
        assert value == pytest.approx(SNAPSHOT[key], abs=SNAPSHOT_TOL), key
    assert abs(spring_back) < SPRING_BACK_TOL
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


@across_ranks
@pytest.mark.slow  # default suite: test_restart's plastic case, this scene on 2 ranks vs 1
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
