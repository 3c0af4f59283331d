"""Verification material for contact with membranes: meshes with named groups, the closed
form of an inflated tube pressed between two plates, and the pre-tensioned drumhead.

The meshes' groups are counted over all ranks (owned entities only). The plates-and-tube
closed form is checked against its own statement (``w = 0`` at the free radius, ``F = p w``,
the rigid limit) and independently against the potential energy of the stadium-shaped tube
minimised numerically. The drumhead runs through ``ContactProblem`` (no contact): its edge
supports keep the equi-biaxial pre-stretch exactly, and under a small pressure its
deflection is the Fourier series of ``T Laplace w = -p``.
"""

from __future__ import annotations

import contact_ufl  # noqa: F401  (loads MPI and PETSc first)

# isort: split
import dolfinx
import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from mpi4py import MPI
from scipy.optimize import minimize_scalar

import contact_ufl as cu
from contact_ufl import membranes
from contact_ufl.membranes import MembraneNeoHookean
from contact_ufl.results import equilibrium_error
from contact_ufl.verification import analytic, geometries, scenes
from contact_ufl.verification import membrane_meshes as meshes

COMM = MPI.COMM_WORLD
MU, T0, R0 = 1.0, 0.01, 1.0
P = 0.5 * MU * T0 / R0
PLATES = "inflated tube between rigid plates, p = mu t0 / (2 R0)"
OWN = "the closed form's own derivation (analytic.tube_between_plates)"
EQUILIBRIUM = "the equilibrium of a converged solve: the P1 test functions sum to one"
#: a closed form met to round-off (measured at most 2.6e-15 on 1 or 2 ranks; the order of
#: the operations and the partition change the last digits)
ROUND_OFF = 1e-14
#: the inextensible limit at mu = 1e9: the stretch is 1 + p r / (4 mu t0), 1.2e-10 here, and
#: the width relatively 100 times that at r = 0.99 R0
RIGID_STRETCH, RIGID_WIDTH = 3e-10, 3e-8
#: the closed form against the minimised potential: the bounded minimiser's precision on the
#: stretch (measured 3.9e-9) and the central difference of the minimum (measured 5e-10)
POTENTIAL_STRETCH, POTENTIAL_FORCE = 1e-8, 1e-9
#: the closed form against the penalty solution, 32 cells per quarter (measured 2.4e-3,
#: 2.3e-4 and 1.5e-4)
PENALTY_FORCE, PENALTY_ARCS, PENALTY_STRETCH = 5e-3, 5e-4, 3e-4
#: the P1 polygon's free radius, 24 cells per quarter, below the closed form's by O(h^2)
#: (measured 1.3e-4)
FREE_RADIUS = 3e-4
#: the drumhead under pressure: the equilibrium to the Newton tolerance (measured 1.1e-13),
#: the deflection against the series at 8 cells per half side (measured 6.7e-3), its ratio
#: per halving (0.23), the centre at 16 cells (1.6e-3)
DRUM_BALANCE, DRUM_DEFLECTION, DRUM_RATIO, DRUM_CENTRE = 3e-13, 1e-2, 0.3, 3e-3
#: the pressurised string: the nodes on the arc at 8 and 16 cells per half (measured 2.4e-5,
#: 6.1e-6), the equilibrium to the Newton tolerance (the half string 5e-10), the sag at 8
#: cells (5.1e-4) and its ratio per halving (0.25)
ARC_CIRCLE = {8: 5e-5, 16: 1e-5}
ARC_BALANCE, ARC_SAG, ARC_RATIO = 1e-9, 1e-3, 0.3
#: the small-sag limit at p = 1e-4 T / c: the parabola is off by O((p c / T)^2) (measured
#: 4e-8)
PARABOLA = 1e-7


def owned_count(data, name: str) -> int:
    """Number of entities of the group ``name`` over all ranks (each counted once)."""
    dim, tag = data.groups[name]
    tags = data.cell_tags if dim == data.mesh.topology.dim else data.facet_tags
    owned = data.mesh.topology.index_map(dim).size_local
    return COMM.allreduce(int(np.sum(tags.indices[tags.values == tag] < owned)), MPI.SUM)


def group_coordinates(data, name: str) -> np.ndarray:
    """The coordinates of the vertices of the entities of the facet group ``name`` (local)."""
    dim, tag = data.groups[name]
    entities = data.facet_tags.find(tag)
    mesh = data.mesh
    mesh.topology.create_connectivity(dim, 0)
    nodes = dolfinx.mesh.entities_to_geometry(mesh, dim, entities)
    return mesh.geometry.x[nodes.ravel()]


# -- meshes with named groups ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("quarters", "x0", "y0"), [(1, 1, 1), (2, 1, 2), (4, 2, 2)], ids=["quarter", "half", "ring"]
)
def test_string_ring_groups(quarters, x0, y0):
    n = 6
    data = meshes.string_ring(COMM, R0, n, quarters)
    assert data.groups == {"tube": (1, 1), "x0": (0, 1), "y0": (0, 2)}
    assert owned_count(data, "tube") == quarters * n
    assert (owned_count(data, "x0"), owned_count(data, "y0")) == (x0, y0)
    for name, axis in (("x0", 0), ("y0", 1)):
        x = group_coordinates(data, name)
        assert np.allclose(x[:, axis], 0.0, atol=1e-12)
        assert np.allclose(np.linalg.norm(x, axis=1), R0)


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_tube_quarter_groups(cell):
    n, n_axial, length = 8, 3, 0.3
    data = meshes.tube_quarter(COMM, R0, n, length, n_axial, cell=cell)
    assert data.groups == {
        "tube": (2, 1),
        "x0": (1, 1),
        "y0": (1, 2),
        "z0": (1, 3),
        "z1": (1, 4),
    }
    per_quad = 1 if cell == "quadrilateral" else 2
    assert owned_count(data, "tube") == per_quad * n * n_axial
    counts = [owned_count(data, name) for name in ("x0", "y0", "z0", "z1")]
    assert counts == [n_axial, n_axial, n, n]
    for name, axis, value in (("x0", 0, 0.0), ("y0", 1, 0.0), ("z0", 2, 0.0), ("z1", 2, length)):
        assert np.allclose(group_coordinates(data, name)[:, axis], value, atol=1e-12)


@pytest.mark.parametrize("quarter", [False, True], ids=["whole", "quarter"])
def test_drumhead_groups(quarter):
    n, a = 4, 0.5
    data = meshes.drumhead(COMM, a, n, quarter)
    names = ("x0", "y0", "xmax", "ymax") if quarter else ("xmin", "xmax", "ymin", "ymax")
    assert list(data.groups) == ["membrane", *names]
    side = n if quarter else 2 * n
    assert owned_count(data, "membrane") == 2 * side**2
    assert [owned_count(data, name) for name in names] == [side] * 4
    x = group_coordinates(data, "xmax")
    assert np.allclose(x[:, 0], a) and np.allclose(x[:, 2], 0.0)


def test_drumhead_is_symmetric():
    """The diagonals point to the centre: the mesh maps onto itself under x -> -x."""
    data = meshes.drumhead(MPI.COMM_SELF, 0.5, 3)
    mesh = data.mesh
    tdim = mesh.topology.dim
    cells = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
    centroids = dolfinx.mesh.compute_midpoints(mesh, tdim, cells)
    key = np.round(centroids[:, :2], 9)
    mirrored = key * np.array([-1.0, 1.0])
    assert {tuple(k) for k in key} == {tuple(k) for k in mirrored}


# -- the plates-and-tube closed form -----------------------------------------------------------


def test_tube_touches_plates_at_the_free_radius(verification):
    """At the free radius the plates just touch: the free tube's pressure, no width."""
    r_free = analytic.tube_free_radius(MU, T0, R0, P)
    pressure = abs(analytic.tube_inflation_neo_hookean(MU, T0, R0, r_free / R0) / P - 1.0)
    result = analytic.tube_between_plates(MU, T0, R0, P, r_free)
    width = abs(result["width"]) / R0
    stretch = abs(result["stretch"] * R0 / r_free - 1.0)
    case = f"{PLATES}, at r = r_free"
    for quantity, value in (
        ("|p_free(r_free / R0) / p - 1|", pressure),
        ("|w| / R0", width),
        ("|l R0 / r_free - 1|", stretch),
    ):
        verification(case, quantity, value, 0.0, ROUND_OFF, OWN, kind="consistency")
    assert pressure < ROUND_OFF and width < ROUND_OFF and stretch < ROUND_OFF


def test_tube_between_plates_relations(verification):
    """The closed form meets the relations it is derived from: ``F = p w``, the contact
    pressure ``p``, Laplace's law ``T(l) = p r`` on the arcs and the stadium's length ``2 pi r
    + 2 w = 2 pi R0 l``; closing the plates widens the contact."""
    r_free = analytic.tube_free_radius(MU, T0, R0, P)
    r = np.linspace(0.3, 1.0, 8) * r_free
    result = analytic.tube_between_plates(MU, T0, R0, P, r)
    l, w = result["stretch"], result["width"]
    assert l.shape == w.shape == r.shape
    tension = analytic.tube_hoop_tension_neo_hookean(MU, T0, l)
    errors = {
        "largest |F - p w| / (p R0)": np.abs(result["force"] - P * w).max() / (P * R0),
        "largest |t_N / p - 1|": np.abs(result["contact_pressure"] / P - 1.0).max(),
        "largest |T(l) / (p r) - 1|": np.abs(tension / (P * r) - 1.0).max(),
        "largest |(2 pi r + 2 w) / (2 pi R0 l) - 1|": np.abs(
            (2.0 * np.pi * r + 2.0 * w) / (2.0 * np.pi * R0 * l) - 1.0
        ).max(),
    }
    case = f"{PLATES}, 0.3 r_free <= r <= r_free"
    for quantity, error in errors.items():
        verification(case, quantity, error, 0.0, ROUND_OFF, OWN, kind="consistency")
    for quantity, error in errors.items():
        assert error < ROUND_OFF, quantity
    assert np.all(np.diff(w) < 0.0) and np.all(np.diff(l) > 0.0)  # closing widens the contact


def test_tube_between_plates_rigid_limit(verification):
    """An inextensible tube (``mu = 1e9``): the stadium of the reference perimeter, ``w = pi
    (R0 - r)``, at stretch 1 (to ``p r / (4 mu t0)``, 1.2e-10 here)."""
    r = np.array([0.5, 0.8, 0.99]) * R0
    result = analytic.tube_between_plates(1e9, T0, R0, P, r)
    width = np.abs(result["width"] / (np.pi * (R0 - r)) - 1.0).max()
    stretch = np.abs(result["stretch"] - 1.0).max()
    case = f"{PLATES}, inextensible tube (mu = 1e9)"
    source = "the geometry of an inextensible tube: a stadium of perimeter 2 pi R0"
    verification(case, "largest |w / (pi (R0 - r)) - 1|", width, 0.0, RIGID_WIDTH, source)
    verification(case, "largest |l - 1|", stretch, 0.0, RIGID_STRETCH, source)
    assert width < RIGID_WIDTH and stretch < RIGID_STRETCH


def stadium_potential(l: float, r: float) -> float:
    """Energy of the stadium of half height ``r`` at the hoop stretch ``l`` (per unit length):
    stored energy ``2 pi R0 W(l)`` minus ``p`` times the enclosed area ``pi r^2 + 2 r w``."""
    W = 0.5 * MU * T0 * (l**2 + l**-2 - 2.0)
    w = np.pi * (R0 * l - r)
    return 2.0 * np.pi * R0 * W - P * (np.pi * r**2 + 2.0 * r * w)


def minimised_potential(r: float) -> tuple[float, float]:
    """The stretch minimising :func:`stadium_potential` at ``r``, and the minimum."""
    best = minimize_scalar(
        stadium_potential,
        bounds=(r / R0, 3.0),
        args=(r,),
        method="bounded",
        options={"xatol": 1e-12},
    )
    return best.x, best.fun


def test_tube_between_plates_minimises_the_potential(verification):
    """Independent of the derivation: the stretch minimises the energy at fixed plates, and
    the plate force is the virtual work of the plates, ``2 F = -d(min energy)/dr``."""
    r, h = 0.9 * R0, 1e-4
    result = analytic.tube_between_plates(MU, T0, R0, P, r)
    l_min, _ = minimised_potential(r)
    stretch = abs(l_min / result["stretch"] - 1.0)
    force = -(minimised_potential(r + h)[1] - minimised_potential(r - h)[1]) / (4.0 * h)
    force = abs(force / result["force"] - 1.0)
    case = f"{PLATES}, r = 0.9 R0"
    source = "the stadium's potential energy minimised numerically (scipy minimize_scalar)"
    verification(case, "|l / l_min - 1|", stretch, 0.0, POTENTIAL_STRETCH, source)
    quantity = "|F / (-d(min energy)/dr / 2) - 1|, central difference h = 1e-4"
    verification(case, quantity, force, 0.0, POTENTIAL_FORCE, source)
    assert stretch < POTENTIAL_STRETCH and force < POTENTIAL_FORCE


def penalty_plates(n: int, k: float, radii: list[float]) -> list[tuple[float, float, float]]:
    """The quarter string ring inflated to ``P`` (four steps), then pressed by a penalty plate
    ``y = r`` (energy ``k/2 int <y - r>_+^2 dX``) through ``radii``: a plain SNES harness
    independent of the package's contact. Returns, per radius, the plate force on the
    quarter, the largest distance of the free nodes from their arc over ``r`` (relative), and
    the mean stretch ``int J_s dX / (pi R0 / 2)``."""
    law = MembraneNeoHookean(MU, T0)
    data = meshes.string_ring(COMM, R0, n, 1)
    mesh = data.mesh
    n0 = membranes.reference_normal(mesh)
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (2,)))
    u, v = dolfinx.fem.Function(V), ufl.TestFunction(V)
    p, r = dolfinx.fem.Constant(mesh, 0.0), dolfinx.fem.Constant(mesh, 10.0)
    dx = ufl.Measure("dx", mesh, metadata={"quadrature_degree": 4})
    g = (ufl.SpatialCoordinate(mesh) + u)[1] - r
    g_plus = 0.5 * (g + abs(g))
    energy = law.strain_energy(u, n0) * dx + 0.5 * k * g_plus**2 * dx
    residual = ufl.derivative(energy, u, v) - membranes.pressure_virtual_work(u, v, n0, p) * dx
    bcs = []
    for name, axis in (("x0", 0), ("y0", 1)):
        vertices = data.facet_tags.find(data.groups[name][1])
        dofs = dolfinx.fem.locate_dofs_topological(V.sub(axis), 0, vertices)
        bcs.append(dolfinx.fem.dirichletbc(np.float64(0.0), dofs, V.sub(axis)))
    options = {"snes_rtol": 1e-10, "snes_atol": 1e-14, "snes_max_it": 50, "ksp_type": "preonly"}
    options |= {"pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
    problem = dolfinx.fem.petsc.NonlinearProblem(
        residual,
        u,
        bcs=bcs,
        J=ufl.derivative(residual, u, ufl.TrialFunction(V)),
        petsc_options_prefix="penalty_plates_",
        petsc_options=options,
    )

    def solve() -> None:
        problem.solve()
        assert problem.solver.getConvergedReason() > 0

    for fraction in (0.25, 0.5, 0.75, 1.0):
        p.value = fraction * P
        solve()
    force = dolfinx.fem.form(k * g_plus * dx)
    length = dolfinx.fem.form(membranes.area_stretch(u, n0) * dx)
    owned = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:owned, :2]
    out = []
    for value in radii:
        r.value = value
        solve()
        width = analytic.tube_between_plates(MU, T0, R0, P, value)["width"]
        x = X + u.x.array.reshape(-1, 2)[:owned]
        free = x[:, 1] < value * (1.0 - 1e-3)
        off_arc = np.abs(np.hypot(x[free, 0] - 0.5 * width, x[free, 1]) / value - 1.0)
        out.append(
            (
                COMM.allreduce(dolfinx.fem.assemble_scalar(force), MPI.SUM),
                COMM.allreduce(off_arc.max(initial=0.0), MPI.MAX),
                COMM.allreduce(dolfinx.fem.assemble_scalar(length), MPI.SUM) / (0.5 * np.pi * R0),
            )
        )
    return out


def test_tube_between_plates_against_a_penalty_solution(verification):
    """A finite-element check of the closed form (no package contact): with a stiff penalty
    plate (penetration ``p / k ~ 5e-5``), the plate force on the quarter is ``p w / 2``, the
    free arcs are circles of radius ``r`` about ``(w/2, 0)``, and the stretch is the closed
    form's (32 cells per quarter, ``r`` from 0.975 to 0.8 ``r_free``)."""
    r_free = analytic.tube_free_radius(MU, T0, R0, P)
    radii = list(r_free * np.linspace(1.0, 0.8, 9)[1:])
    forces, arcs, stretches = [], [], []
    for value, (force, off_arc, stretch) in zip(
        radii, penalty_plates(32, 100.0, radii), strict=True
    ):
        exact = analytic.tube_between_plates(MU, T0, R0, P, value)
        if value <= 0.9 * r_free:  # the width is several elements
            forces.append(abs(force / (0.5 * exact["force"]) - 1.0))
        arcs.append(off_arc)
        stretches.append(abs(stretch / exact["stretch"] - 1.0))
    case = f"{PLATES}, penalty plate k = 100, 32 cells per quarter"
    source = "a penalty-plate finite-element solution (plain SNES, not the package's contact)"
    quantity = "largest |F / (p w / 2) - 1|, r <= 0.9 r_free"
    verification(case, quantity, max(forces), 0.0, PENALTY_FORCE, source)
    quantity = "largest |distance / r - 1| of the free nodes from their arc"
    verification(case, quantity, max(arcs), 0.0, PENALTY_ARCS, source)
    verification(case, "largest |l / l_exact - 1|", max(stretches), 0.0, PENALTY_STRETCH, source)
    assert max(forces) < PENALTY_FORCE and max(arcs) < PENALTY_ARCS
    assert max(stretches) < PENALTY_STRETCH


def test_tube_between_plates_bad_input():
    r_free = analytic.tube_free_radius(MU, T0, R0, P)
    with pytest.raises(ValueError, match="not in \\(0, r_free\\]"):
        analytic.tube_between_plates(MU, T0, R0, P, [0.9, 1.01 * r_free])
    with pytest.raises(ValueError, match="limit mu t0 / R0"):
        analytic.tube_free_radius(MU, T0, R0, MU * T0 / R0)
    with pytest.raises(ValueError, match="mu must be positive"):
        analytic.tube_between_plates(-1.0, T0, R0, P, 0.9)


def test_plates_schedule():
    r_free = analytic.tube_free_radius(MU, T0, R0, P)
    schedule = scenes.PlatesSchedule(P, 1.05 * r_free, 0.9 * r_free, t_inflate=0.2)
    assert schedule.p(0.1) == pytest.approx(0.5 * P) and schedule.p(0.7) == P
    assert schedule.half_separation(0.2) == pytest.approx(1.05 * r_free)
    assert schedule.half_separation(1.0) == pytest.approx(0.9 * r_free)
    plate = schedule.plate(3, side=-1.0)
    assert plate.normal == (0.0, 1.0, 0.0) and plate.point == (0.0, -1.05 * r_free, 0.0)
    assert np.allclose(plate.motion(1.0), (0.0, 0.15 * r_free, 0.0))
    with pytest.raises(ValueError, match="r_end < r_start"):
        scenes.PlatesSchedule(P, 0.9, 1.0)


@pytest.mark.parametrize(
    ("dim", "quarters", "ends"),
    [(2, 1, (1, 1)), (2, 2, (0, 2)), (2, 4, (0, 0)), (3, 1, (1, 1))],
    ids=["ring quarter", "ring half", "whole ring", "tube quarter"],
)
def test_tube_for_plates_inflates_to_the_free_radius(dim, quarters, ends, verification):
    """Through ContactProblem (no contact yet): the inflation phase ends at ``r_free``, and
    the supports carry the hoop tension ``T = p r`` where the tube ends on them (``ends``:
    how many ends on ``"x0"`` and on ``"y0"``; the symmetric ring's supports carry
    nothing); to round-off, as the pressure's resultant on the polygon is ``p`` times its chord."""
    r_free = analytic.tube_free_radius(MU, T0, R0, P)
    schedule = scenes.PlatesSchedule(P, 1.05 * r_free, 0.9 * r_free)
    length = 0.1
    domain = scenes.tube_for_plates(schedule, dim, n=24, quarters=quarters, length=length)
    problem = cu.ContactProblem(cu.Scene(domains=[domain]), verbose=False)
    problem.solve(num_steps=4, t_end=schedule.t_inflate)
    bulk = problem.bulks[0]
    owned = bulk.V.dofmap.index_map.size_local
    X = bulk.V.tabulate_dof_coordinates()[:, :dim]
    x = (X + bulk.u.x.array.reshape(-1, dim))[:owned, :2]
    radius = np.linalg.norm(x, axis=1)
    r_min = COMM.allreduce(radius.min(initial=np.inf), MPI.MIN)
    r_max = COMM.allreduce(radius.max(initial=0.0), MPI.MAX)
    case = f"free inflation through the problem, {dim}D tube, {quarters} quarter(s), 24 cells each"
    spread = (r_max - r_min) / r_free
    source = "the symmetry of the ring: every node alike"
    quantity = "(r_max - r_min) / r_free of the nodes"
    verification(case, quantity, spread, 0.0, ROUND_OFF, source, kind="consistency")
    below = 1.0 - r_max / r_free  # the P1 polygon is stiffer: O(h^2) below
    source = "closed form of the free inflation, r_free = R0 l with p = mu t0 / R0 (1 - l^-4)"
    verification(case, "1 - r / r_free", below, "> 0", FREE_RADIUS, source)
    assert spread < ROUND_OFF  # symmetric: the nodes stay on one circle
    assert 0.0 < below < FREE_RADIUS
    tension = P * r_max * (length if dim == 3 else 1.0)
    source = "the quarter's equilibrium: the pressure's resultant on the polygon is p r"
    for (name, axis), count in zip((("x0", 0), ("y0", 1)), ends, strict=True):
        expected = -count * tension * np.eye(2)[axis]
        error = np.abs(problem.reaction(name)[:2] - expected).max() / tension
        quantity = f"|reaction of {name} + {count} p r| / (p r)"
        verification(case, quantity, error, 0.0, ROUND_OFF, source, kind="consistency")
        assert error < ROUND_OFF


# -- the pre-tensioned drumhead ----------------------------------------------------------------

STRETCH, A = 1.05, 0.5


def solve_drumhead(n: int, pressure: float, quarter: bool = False, dim: int = 3, steps: int = 1):
    domain = scenes.pretensioned_drumhead(n, A, STRETCH, pressure, quarter=quarter, dim=dim)
    problem = cu.ContactProblem(cu.Scene(domains=[domain]), verbose=False)
    scenes.pretension(problem, STRETCH)
    problem.solve(num_steps=steps)
    bulk = problem.bulks[0]
    owned = bulk.V.dofmap.index_map.size_local
    X = bulk.V.tabulate_dof_coordinates()[:, :dim]
    x = (X + bulk.u.x.array.reshape(-1, dim))[:owned]
    return problem, x


def test_drumhead_pretension_is_exact(verification):
    """No pressure: the pre-stretch is the solution; each edge carries the nominal tension
    ``mu t0 (s - s^-5)`` over its reference length ``2 a``."""
    problem, x = solve_drumhead(4, 0.0)
    assert problem.history.steps[0].newton_iterations <= 1
    X = problem.bulks[0].V.tabulate_dof_coordinates()[: len(x)]
    assert np.allclose(x[:, :2], STRETCH * X[:, :2], atol=1e-12) and np.allclose(x[:, 2], 0.0)
    reaction = problem.reaction("xmax")
    nominal = MU * T0 * (STRETCH - STRETCH**-5) * 2.0 * A
    tension = abs(reaction[0] / nominal - 1.0)
    shear = np.abs(reaction[1:]).max() / nominal
    case = "pre-tensioned drumhead, equi-biaxial stretch 1.05, 4 cells per half side"
    source = "the nominal tension of the equi-biaxially stretched Neo-Hookean membrane"
    quantity = "|edge reaction / (mu t0 (s - s^-5) 2 a) - 1|"
    verification(case, quantity, tension, 0.0, ROUND_OFF, source)
    quantity = "|in-plane shear and normal edge reaction| / tension"
    verification(case, quantity, shear, 0.0, ROUND_OFF, source)
    assert tension < ROUND_OFF and shear < ROUND_OFF


def drumhead_pressure() -> tuple[float, float, float]:
    """Tension, current side and a pressure deflecting the centre by about 0.5% of the side."""
    T = analytic.equibiaxial_tension_neo_hookean(MU, T0, STRETCH)
    L = 2.0 * A * STRETCH
    return T, L, 0.005 * T / (0.0737 * L)


def test_drumhead_deflection_under_pressure(verification):
    """Within 1% of the series of ``T Laplace w = -p`` (P1 error, falling fourfold per
    halving of h), in equilibrium, and a quarter model with symmetry supports gives the
    whole square's deflection."""
    T, L, p = drumhead_pressure()
    case = "pre-tensioned drumhead under a small pressure (sag 0.5% of the side), {} cells"
    series = "the Fourier series of T Laplace w = -p on the square"
    errors = []
    for n in (8, 16):
        problem, x = solve_drumhead(n, p)
        exact = analytic.pretensioned_square_membrane(T, p, L, x[:, 0] + L / 2, x[:, 1] + L / 2)
        w_max = COMM.allreduce(x[:, 2].max(), MPI.MAX)
        errors.append(COMM.allreduce(np.abs(x[:, 2] - exact).max(), MPI.MAX) / w_max)
        error = equilibrium_error(problem, ["xmin", "xmax", "ymin", "ymax"])
        quantity = "|supports + pressure| / |pressure|"
        verification(
            case.format(n), quantity, error, 0.0, DRUM_BALANCE, EQUILIBRIUM, kind="consistency"
        )
        assert error < DRUM_BALANCE
    quantity = "largest |w - w_series| / w_max"
    verification(case.format(8), quantity, errors[0], 0.0, DRUM_DEFLECTION, series)
    quantity = "largest deflection error at 16 over that at 8 cells"
    ratio = errors[1] / errors[0]
    verification(case.format("8 and 16"), quantity, ratio, 0.25, f"< {DRUM_RATIO}", series)
    centre = abs(w_max / analytic.pretensioned_square_membrane(T, p, L, L / 2, L / 2) - 1.0)
    quantity = "|w_max / w_series(centre) - 1|"
    verification(case.format(16), quantity, centre, 0.0, DRUM_CENTRE, series)
    assert errors[0] < DRUM_DEFLECTION and ratio < DRUM_RATIO
    assert centre < DRUM_CENTRE
    _, xq = solve_drumhead(8, p, quarter=True)
    w_quarter = COMM.allreduce(xq[:, 2].max(), MPI.MAX)
    _, x8 = solve_drumhead(8, p)
    symmetric = abs(w_quarter / COMM.allreduce(x8[:, 2].max(), MPI.MAX) - 1.0)
    quantity = "|w_max of the quarter model / w_max of the whole - 1|"
    source = "the symmetry of the square: the quarter with symmetry supports"
    verification(case.format(8), quantity, symmetric, 0.0, ROUND_OFF, source, kind="consistency")
    assert symmetric < ROUND_OFF


def test_pretension_after_the_first_solve_is_refused():
    problem, _ = solve_drumhead(2, 0.0)
    with pytest.raises(ValueError, match="before the first solve"):
        scenes.pretension(problem, STRETCH)


def test_string_drumhead_pretension_is_exact(verification):
    """The plane-strain string: its ends carry ``mu t0 (s - s^-3)`` (out-of-plane stretch 1)."""
    problem, x = solve_drumhead(4, 0.0, dim=2)
    X = problem.bulks[0].V.tabulate_dof_coordinates()[: len(x), :2]
    assert np.allclose(x[:, 0], STRETCH * X[:, 0], atol=1e-12) and np.allclose(x[:, 1], 0.0)
    tension = analytic.tube_hoop_tension_neo_hookean(MU, T0, STRETCH)
    error = np.abs(problem.reaction("xmax") - [tension, 0.0]).max() / tension
    case = "pre-tensioned string, stretch 1.05, 4 cells per half"
    source = "the nominal tension of the Neo-Hookean string in plane strain, mu t0 (s - s^-3)"
    quantity = "|end reaction - (mu t0 (s - s^-3), 0)| / tension"
    verification(case, quantity, error, 0.0, ROUND_OFF, source)
    assert error < ROUND_OFF


@pytest.mark.parametrize("quarter", [False, True], ids=["whole", "half"])
def test_string_drumhead_is_a_circular_arc(quarter, verification):
    """Under a follower pressure the stretched string is an arc of radius ``T / p``: the
    nodes lie on the closed form's circle and its sag converges as ``h^2``."""
    T = analytic.tube_hoop_tension_neo_hookean(MU, T0, STRETCH)
    chord = STRETCH * A
    p = 0.4 * T / chord  # sag about a tenth of the chord
    exact = analytic.pressurised_string(MU, T0, A, chord, p)
    centre = np.array([0.0, -exact["radius"] * np.cos(exact["half_angle"])])
    model = "half" if quarter else "whole"
    case = f"pressurised string ({model}), stretch 1.05, sag c / 10, {{}} cells per half"
    arc = "closed form of the pressurised string: an arc of radius T / p"
    errors = []
    for n in (8, 16):
        problem, x = solve_drumhead(n, p, quarter=quarter, dim=2, steps=2)
        on_circle = np.abs(np.linalg.norm(x - centre, axis=1) / exact["radius"] - 1.0)
        on_circle = COMM.allreduce(on_circle.max(initial=0.0), MPI.MAX)
        quantity = "largest |distance from the centre / radius - 1| of the nodes"
        verification(case.format(n), quantity, on_circle, 0.0, ARC_CIRCLE[n], arc)
        assert on_circle < ARC_CIRCLE[n]
        sag = COMM.allreduce(x[:, 1].max(initial=0.0), MPI.MAX)
        errors.append(abs(sag / exact["sag"] - 1.0))
        supports = ["x0", "xmax"] if quarter else ["xmin", "xmax"]
        error = equilibrium_error(problem, supports)
        quantity = "|supports + pressure| / |pressure|"
        verification(
            case.format(n), quantity, error, 0.0, ARC_BALANCE, EQUILIBRIUM, kind="consistency"
        )
        assert error < ARC_BALANCE
    verification(case.format(8), "|sag / sag_exact - 1|", errors[0], 0.0, ARC_SAG, arc)
    quantity = "sag error at 16 over that at 8 cells"
    ratio = errors[1] / errors[0]
    verification(case.format("8 and 16"), quantity, ratio, 0.25, f"< {ARC_RATIO}", arc)
    assert errors[0] < ARC_SAG and ratio < ARC_RATIO


def test_pressurised_string_limits(verification):
    """Small pressure: the parabola's sag ``p c^2 / (2 T)``; bad input refused."""
    chord = STRETCH * A
    T = analytic.tube_hoop_tension_neo_hookean(MU, T0, STRETCH)
    p = 1e-4 * T / chord
    sag = analytic.pressurised_string(MU, T0, A, chord, p)["sag"]
    error = abs(sag / (p * chord**2 / (2 * T)) - 1.0)
    case = "pressurised string, p = 1e-4 T / c"
    source = "the small-sag limit of a taut string under a pressure: the parabola p c^2 / (2 T)"
    verification(case, "|sag / (p c^2 / (2 T)) - 1|", error, 0.0, PARABOLA, source)
    assert error < PARABOLA
    with pytest.raises(ValueError, match="slack"):
        analytic.pressurised_string(MU, T0, A, 0.9 * A, p)


@pytest.mark.parametrize("quarter", [False, True], ids=["whole", "quarter"])
def test_hemisphere_indenter_groups(quarter):
    data = geometries.hemisphere_3d(radius=0.25, gap=0.01, quarter=quarter)
    names = ["indenter_contact", "indenter_top"]
    names += ["indenter_x0", "indenter_y0"] if quarter else []
    assert data.groups == {"indenter": (3, 1)} | {k: (2, 11 + i) for i, k in enumerate(names)}
    assert all(owned_count(data, name) > 0 for name in names)
    x = group_coordinates(data, "indenter_contact")
    assert np.allclose(np.linalg.norm(x - [0.0, 0.0, 0.26], axis=1), 0.25, atol=1e-9)
    lowest = COMM.allreduce(x[:, 2].min(initial=1.0), MPI.MIN)
    assert np.isclose(lowest, 0.01)
