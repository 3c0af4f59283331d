"""Membranes and strings: the orientation of the reference normal, and free inflation under a
follower pressure against the closed forms of :mod:`contact_ufl.verification.analytic`.

The inflation harness is a plain ``NonlinearProblem`` (SNES Newton, MUMPS LU) stepping the
pressure, on symmetry models with supports normal to the symmetry planes: a sphere octant
(triangles), a quarter tube of one element along its axis held at axial stretch 1
(quadrilaterals), and a quarter ring of string in 2D (intervals, plane strain per unit
depth: the same closed form as the tube). The stretch is the mean current radius of the
nodes over ``R`` (the nodes start on the circle or sphere). P1 facets make the model stiffer
than the smooth shell by ``O(h^2)``: the error falls fourfold per halving of ``h``; on the
finest meshes the pressure is within 0.2% of the closed form (measured 0.08% to 0.14%).
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
from petsc4py import PETSc

from contact_ufl import membranes as mb
from contact_ufl.errors import ContactInputError
from contact_ufl.verification import analytic
from contact_ufl.verification import membrane_meshes as meshes

R, T0, MU = 1.0, 0.01, 1.0
E_SVK, NU_SVK = 1.0, 0.3
#: the largest relative error of the inflation pressure against its closed form on the
#: finest mesh of each test (measured 0.08% to 0.14%)
REL_TOL = 2e-3
#: a closed form of the kinematics, to round-off (measured at most 1.2e-15 on 1 or 2 ranks:
#: the sums over the cells change with the partition)
ROUND_OFF = 1e-14
INFLATION = "closed form of the homogeneous inflation, p = W'(l) / (R l^2) (sphere)"
TUBE = "closed form of the homogeneous inflation, p = W'(l) / (R l) (tube at axial stretch 1)"
TAYLOR = "Taylor's theorem: the remainder of an exact derivative is O(h^2)"
#: fractions of the incompressible Neo-Hookean sphere's pressure maximum (at l = 7^(1/6))
SPHERE_P_MAX = float(analytic.sphere_inflation_neo_hookean(MU, T0, R, 7.0 ** (1.0 / 6.0)))
SPHERE_STEPS = SPHERE_P_MAX * np.array([0.25, 0.5, 0.7, 0.85, 0.93, 0.97, 0.99])


def _supports(V: dolfinx.fem.FunctionSpace, axes: dict[int, object]) -> list:
    """Zero displacement component ``k`` on the nodes where ``axes[k]`` (a marker) holds."""
    mesh = V.mesh
    mesh.topology.create_connectivity(0, mesh.topology.dim)
    bcs = []
    for k, marker in axes.items():
        vertices = dolfinx.mesh.locate_entities(mesh, 0, marker)
        dofs = dolfinx.fem.locate_dofs_topological(V.sub(k), 0, vertices)
        bcs.append(dolfinx.fem.dirichletbc(np.float64(0.0), dofs, V.sub(k)))
    return bcs


def _on_plane(k: int):
    return lambda x: np.isclose(x[k], 0.0)


def mean_radial_stretch(u: dolfinx.fem.Function, axes: int) -> float:
    """Mean over the nodes (all ranks) of the current distance from the origin in the first
    ``axes`` coordinates, over ``R``."""
    V = u.function_space
    gdim = V.mesh.geometry.dim
    owned = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:owned, :gdim]
    x = X + u.x.array.reshape(-1, gdim)[:owned]
    r = np.linalg.norm(x[:, :axes], axis=1)
    comm = V.mesh.comm
    return comm.allreduce(r.sum()) / comm.allreduce(owned) / R


def inflate(mesh, law, pressures, axes: dict[int, object], radial: int) -> np.ndarray:
    """Step the follower pressure through ``pressures``; return the stretch after each step.

    Residual ``dPi/du [v] - int p cof(F) n0 . v dA`` with ``Pi = int W(u, n0) dA``, tangent
    by ``ufl.derivative``; SNES Newton with MUMPS, converged to ``rtol = 1e-10`` each step.
    """
    gdim = mesh.geometry.dim
    n0 = mb.reference_normal(mesh)
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (gdim,)))
    u, v = dolfinx.fem.Function(V), ufl.TestFunction(V)
    p = dolfinx.fem.Constant(mesh, 0.0)
    dx = ufl.Measure("dx", mesh, metadata={"quadrature_degree": 2})
    residual = ufl.derivative(law.strain_energy(u, n0) * dx, u, v)
    residual -= mb.pressure_virtual_work(u, v, n0, p) * dx
    problem = dolfinx.fem.petsc.NonlinearProblem(
        residual,
        u,
        bcs=_supports(V, axes),
        J=ufl.derivative(residual, u, ufl.TrialFunction(V)),
        petsc_options_prefix="membrane_inflation_",
        petsc_options={
            "snes_type": "newtonls",
            "snes_linesearch_type": "none",
            "snes_rtol": 1e-10,
            "snes_atol": 1e-14,
            "snes_max_it": 25,
            "ksp_type": "preonly",
            "pc_type": "lu",
            "pc_factor_mat_solver_type": "mumps",
        },
    )
    stretches = []
    for value in pressures:
        p.value = value
        problem.solve()
        reason = problem.solver.getConvergedReason()
        assert reason > 0, f"Newton diverged at p = {value} (reason {reason})"
        stretches.append(mean_radial_stretch(u, radial))
    return np.array(stretches)


def relative_errors(pressures, closed_form, stretches) -> np.ndarray:
    """``|p - p_exact(l)| / p_exact(l)`` at each computed stretch ``l``."""
    exact = closed_form(stretches)
    return np.abs(np.asarray(pressures) - exact) / exact


def sphere_errors(n: int, law, closed_form, pressures, reverse: bool = False) -> np.ndarray:
    mesh = meshes.sphere_octant(MPI.COMM_WORLD, R, n, reverse=reverse)
    axes = {k: _on_plane(k) for k in range(3)}
    stretches = inflate(mesh, law, pressures, axes, radial=3)
    assert np.all(np.diff(stretches) > 0.0) and stretches[0] > 1.0  # inflates outward
    return relative_errors(pressures, closed_form, stretches)


def tube_errors(n: int, law, closed_form, pressures, cell="quadrilateral", reverse=False):
    mesh = meshes.tube_sector(MPI.COMM_WORLD, R, n, 0.1, cell=cell, reverse=reverse)
    axes = {0: _on_plane(0), 1: _on_plane(1), 2: lambda x: np.full(x.shape[1], True)}
    stretches = inflate(mesh, law, pressures, axes, radial=2)
    assert np.all(np.diff(stretches) > 0.0) and stretches[0] > 1.0
    return relative_errors(pressures, closed_form, stretches)


def ring_errors(n: int, law, closed_form, pressures, reverse: bool = False) -> np.ndarray:
    mesh = meshes.ring_sector(MPI.COMM_WORLD, R, n, reverse=reverse)
    stretches = inflate(mesh, law, pressures, {0: _on_plane(0), 1: _on_plane(1)}, radial=2)
    assert np.all(np.diff(stretches) > 0.0) and stretches[0] > 1.0
    return relative_errors(pressures, closed_form, stretches)


NH = mb.MembraneNeoHookean(MU, T0)
SVK = mb.MembraneSVK(E_SVK, NU_SVK, T0)


def nh_sphere(l):
    return analytic.sphere_inflation_neo_hookean(MU, T0, R, l)


def svk_sphere(l):
    return analytic.sphere_inflation_svk(E_SVK, NU_SVK, T0, R, l)


def nh_tube(l):
    return analytic.tube_inflation_neo_hookean(MU, T0, R, l)


def svk_tube(l):
    return analytic.tube_inflation_svk(E_SVK, NU_SVK, T0, R, l)


CNH = mb.MembraneCompressibleNeoHookean(E_SVK, NU_SVK, T0)


def cnh_sphere(l):
    return analytic.sphere_inflation_compressible_neo_hookean(E_SVK, NU_SVK, T0, R, l)


def cnh_tube(l):
    return analytic.tube_inflation_compressible_neo_hookean(E_SVK, NU_SVK, T0, R, l)


# -- orientation -------------------------------------------------------------------------------

BUILDERS = {
    "sphere octant, triangles": lambda reverse: meshes.sphere_octant(MPI.COMM_WORLD, R, 6, reverse),
    "tube sector, quadrilaterals": lambda reverse: meshes.tube_sector(
        MPI.COMM_WORLD, R, 6, 0.2, reverse=reverse
    ),
    "tube sector, triangles": lambda reverse: meshes.tube_sector(
        MPI.COMM_WORLD, R, 6, 0.2, cell="triangle", reverse=reverse
    ),
    "ring sector, intervals": lambda reverse: meshes.ring_sector(MPI.COMM_WORLD, R, 6, reverse),
}


def cell_values(mesh, expr) -> np.ndarray:
    """``expr`` at the cell midpoints of the owned cells."""
    W = dolfinx.fem.functionspace(mesh, ("DG", 0))
    f = dolfinx.fem.Function(W)
    f.interpolate(dolfinx.fem.Expression(expr, W.element.interpolation_points))
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    return f.x.array[W.dofmap.list[:owned, 0]]


def global_min(values: np.ndarray) -> float:
    return MPI.COMM_WORLD.allreduce(float(values.min()) if values.size else np.inf, op=MPI.MIN)


@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize("name", list(BUILDERS))
def test_normal_outward_whatever_vertex_order(name, reverse):
    """On every cell, on every rank, ``n0`` is the outward radial direction (``n0 . x/|x|``
    close to 1 on these coarse sectors of circles and spheres), with every other cell's
    vertex order reversed or not; with reversed cells the orientation flips some signs."""
    mesh = BUILDERS[name](reverse)
    s = mb.cell_orientation(mesh)
    n0 = mb.reference_normal(mesh, orientation=s)
    x = ufl.SpatialCoordinate(mesh)
    radial = x if mesh.geometry.dim == 2 else ufl.as_vector((x[0], x[1], x[2]))
    if name.startswith("tube"):
        radial = ufl.as_vector((x[0], x[1], 0.0))
    cosine = cell_values(mesh, ufl.dot(n0, radial) / ufl.sqrt(ufl.dot(radial, radial)))
    assert global_min(cosine) > 0.98
    assert global_min(s.x.array) == (-1.0 if reverse else 1.0)


def test_moebius_strip_raises():
    with pytest.raises(ContactInputError, match="cannot be oriented consistently"):
        mb.cell_orientation(meshes.moebius_strip(MPI.COMM_WORLD))


def test_flat_membrane_needs_a_side():
    """A flat membrane has no outward side of its own: an error unless ``outward`` (a point)
    or ``direction`` is given; then ``n0`` is the unit normal on that side."""
    mesh = meshes.flat_square(MPI.COMM_WORLD)
    with pytest.raises(ContactInputError, match="cannot tell the outward side"):
        mb.cell_orientation(mesh)
    for kwargs in ({"direction": (0.0, 0.0, -2.0)}, {"outward": (0.5, 0.5, 1.0)}):
        n0 = mb.reference_normal(mesh, **kwargs)
        assert global_min(cell_values(mesh, -n0[2])) == pytest.approx(1.0, abs=1e-14)
    with pytest.raises(ContactInputError, match="zero vector"):
        mb.cell_orientation(mesh, direction=(0.0, 0.0, 0.0))
    with pytest.raises(ContactInputError, match="either"):
        mb.cell_orientation(mesh, outward=(0.0, 0.0, 1.0), direction=(0.0, 0.0, 1.0))


def test_not_a_membrane_raises():
    mesh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    with pytest.raises(ContactInputError, match="membrane mesh must have"):
        mb.cell_orientation(mesh)


def test_non_manifold_raises():
    """Three triangles on one edge (a T-junction of membranes) cannot have one normal."""
    import basix.ufl

    x = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1.0]])
    cells = np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]], dtype=np.int64)
    if MPI.COMM_WORLD.rank:
        x, cells = x[:0], cells[:0]
    element = basix.ufl.element("Lagrange", "triangle", 1, shape=(3,))
    mesh = dolfinx.mesh.create_mesh(MPI.COMM_WORLD, cells, element, x, max_facet_to_cell_links=3)
    with pytest.raises(ContactInputError, match="not a manifold"):
        mb.cell_orientation(mesh)


# -- kinematics --------------------------------------------------------------------------------


def integral(mesh, expr) -> float:
    dx = ufl.Measure("dx", mesh, metadata={"quadrature_degree": 2})
    local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(expr * dx))
    return mesh.comm.allreduce(local)


@pytest.mark.parametrize("name", list(BUILDERS))
def test_homogeneous_kinematics(name, verification):
    """A dilation ``x = l X`` stretches every flat cell by ``l`` in the plane: ``J_s = l^2``
    (``l`` for a string), ``tr C_s = 2 l^2`` (``l^2``), ``n = n0``, and the incompressible
    thickness stretch ``1/J_s``. A rigid rotation ``Q`` leaves ``J_s = 1``, turns the normal
    to ``Q n0`` and stores no energy in any law."""
    mesh = BUILDERS[name](True)
    gdim, tdim = mesh.geometry.dim, mesh.topology.dim
    n0 = mb.reference_normal(mesh)
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (gdim,)))
    u = dolfinx.fem.Function(V)
    area = integral(mesh, 1.0)

    def mean(expr) -> float:
        return integral(mesh, expr) / area

    l = 1.3
    u.interpolate(lambda X: (l - 1.0) * X[:gdim])
    n = mb.current_normal(u, n0)
    errors = {
        "mean J_s / l^d - 1, dilation": mean(mb.area_stretch(u, n0)) / l**tdim - 1.0,
        "mean tr C_s / (d l^2) - 1, dilation": mean(ufl.tr(mb.membrane_cauchy_green(u, n0)))
        / (tdim * l**2)
        - 1.0,
        "mean thickness stretch * l^d - 1, dilation": mean(NH.thickness_stretch(u, n0)) * l**tdim
        - 1.0,
        "RMS |n - n0|, dilation": np.sqrt(mean(ufl.dot(n - n0, n - n0))),
    }
    c, s = np.cos(0.7), np.sin(0.7)
    Q = np.array([[c, -s], [s, c]]) if gdim == 2 else np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    u.interpolate(lambda X: Q @ X[:gdim] - X[:gdim])
    turned = mb.current_normal(u, n0) - ufl.dot(ufl.as_matrix(Q.tolist()), n0)
    errors["mean J_s - 1, rotation"] = mean(mb.area_stretch(u, n0)) - 1.0
    errors["RMS |n - Q n0|, rotation"] = np.sqrt(mean(ufl.dot(turned, turned)))
    errors["|energy| / (E t0 A), rotation, any law"] = max(
        abs(mean(law.strain_energy(u, n0))) / (law.E * T0) for law in (NH, SVK, CNH)
    )
    case = f"membrane kinematics, {name}"
    source = "the kinematics of a homogeneous dilation x = l X and of a rigid rotation"
    for quantity, error in errors.items():
        verification(case, quantity, abs(error), 0.0, ROUND_OFF, source)
    for quantity, error in errors.items():
        assert abs(error) < ROUND_OFF, quantity


def _residual_at(r_form, u, w, h):
    """The residual vector at ``u + h w`` (``u`` is left unchanged)."""
    u0 = u.x.array.copy()
    u.x.array[:] = u0 + h * w.x.array
    b = dolfinx.fem.petsc.assemble_vector(r_form)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    u.x.array[:] = u0
    return b


def test_tangent_is_consistent(verification):
    """The Jacobian (``ufl.derivative``, with the pressure's load stiffness) is the derivative
    of the residual: ``|r(u + h w) - r(u) - h K w|`` falls as ``h^2`` (Taylor), on reversed
    cells of a sphere octant, for each law."""
    mesh = meshes.sphere_octant(MPI.COMM_WORLD, R, 4, reverse=True)
    n0 = mb.reference_normal(mesh)
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (3,)))
    u, w = dolfinx.fem.Function(V), dolfinx.fem.Function(V)
    u.interpolate(lambda X: 0.2 * X + 0.05 * np.sin(3.0 * X[[1, 2, 0]]))
    w.interpolate(lambda X: np.cos(2.0 * X[[2, 0, 1]]))
    v = ufl.TestFunction(V)
    dx = ufl.Measure("dx", mesh, metadata={"quadrature_degree": 2})
    for law in (NH, SVK, CNH):
        residual = ufl.derivative(law.strain_energy(u, n0) * dx, u, v)
        residual -= mb.pressure_virtual_work(u, v, n0, 0.05) * dx
        r_form = dolfinx.fem.form(residual)
        K = dolfinx.fem.petsc.assemble_matrix(
            dolfinx.fem.form(ufl.derivative(residual, u, ufl.TrialFunction(V)))
        )
        K.assemble()
        Kw = K.createVecLeft()
        K.mult(w.x.petsc_vec, Kw)
        r0 = _residual_at(r_form, u, w, 0.0)
        remainders = []
        for h in (1e-2, 5e-3, 2.5e-3):
            rh = _residual_at(r_form, u, w, h)
            rh.axpy(-1.0, r0)
            rh.axpy(-h, Kw)
            remainders.append(rh.norm())
        rates = np.log2(np.array(remainders[:-1]) / remainders[1:])
        case = f"membrane tangent, sphere octant, {type(law).__name__}, follower pressure"
        quantity = "slopes of the Taylor remainder |r(u + h w) - r(u) - h K w|"
        verification(case, quantity, rates, 2.0, "|slope - 2| < 0.01", TAYLOR)
        assert np.all(np.abs(rates - 2.0) < 0.01), (type(law).__name__, remainders)


# -- free inflation ----------------------------------------------------------------------------


def record_inflation(verification, case, errors, tolerance, source=INFLATION) -> None:
    """Record the largest relative pressure error of an inflation against its closed form."""
    quantity = "largest |p / p_exact(l) - 1| over the steps"
    verification(case, quantity, float(np.max(errors)), 0.0, tolerance, source)


def record_convergence(verification, case, worst, bound, source=INFLATION) -> None:
    """Record the ratios of the errors of successive meshes (4 for O(h^2))."""
    ratios = np.array(worst[:-1]) / np.array(worst[1:])
    quantity = "ratio of the largest errors per halving of h"
    verification(case, quantity, ratios, 4.0, f"> {bound}", source)


def test_sphere_inflation_neo_hookean(verification):
    """Incompressible Neo-Hookean sphere octant up to 99% of the pressure maximum: the
    pressure against the stretch within 0.2% of ``2 mu t0/R (1/l - 1/l^7)`` on 32 cells per
    quarter arc (measured 0.14%), the error falling about fourfold per halving of the mesh
    size (O(h^2): the flat P1 facets)."""
    worst = [sphere_errors(n, NH, nh_sphere, SPHERE_STEPS).max() for n in (8, 16, 32)]
    case = "free inflation, Neo-Hookean sphere octant, to 99% of the pressure maximum"
    record_inflation(verification, f"{case}, 32 cells per arc", worst[-1], REL_TOL)
    record_convergence(verification, f"{case}, 8, 16, 32 cells per arc", worst, 3.5)
    assert worst[-1] < REL_TOL
    assert worst[0] / worst[1] > 3.5 and worst[1] / worst[2] > 3.5, worst


@pytest.mark.parametrize(
    "law, closed_form", [(SVK, svk_sphere), (CNH, cnh_sphere)], ids=["svk", "compressible_nh"]
)
def test_sphere_inflation_compressible(law, closed_form, verification):
    """The compressible laws with the thickness condensed, to stretch 1.4 (SVK 1.3), 32
    cells per quarter arc."""
    top = 1.3 if law is SVK else 1.4
    pressures = closed_form(np.linspace(1.0, top, 5)[1:])
    errors = sphere_errors(32, law, closed_form, pressures)
    case = f"free inflation, {type(law).__name__} sphere octant, 32 cells per arc"
    record_inflation(verification, case, errors, REL_TOL)
    assert errors.max() < REL_TOL


def test_tube_inflation(verification):
    """A quarter tube of quadrilaterals at axial stretch 1, Neo-Hookean to hoop stretch 2:
    ``p = mu t0/R (1 - l^-4)`` within 0.2% on 16 cells per quarter (measured 0.12%), the
    error falling fourfold per halving; SVK on triangles, ``p = t0 E (l^2 - 1) / (2 (1 -
    nu^2) R)``."""
    pressures = nh_tube(np.array([1.1, 1.3, 1.6, 2.0]))
    worst = [tube_errors(n, NH, nh_tube, pressures).max() for n in (8, 16)]
    case = "free inflation, Neo-Hookean quarter tube (quadrilaterals), to hoop stretch 2"
    record_inflation(verification, f"{case}, 16 cells per quarter", worst[-1], REL_TOL, TUBE)
    record_convergence(verification, f"{case}, 8 and 16 cells per quarter", worst, 3.9, TUBE)
    assert worst[-1] < REL_TOL and worst[0] / worst[1] > 3.9, worst
    svk = tube_errors(16, SVK, svk_tube, svk_tube(np.array([1.1, 1.2, 1.3])), cell="triangle")
    case = "free inflation, MembraneSVK quarter tube (triangles), 16 cells per quarter"
    record_inflation(verification, case, svk, REL_TOL, TUBE)
    assert svk.max() < REL_TOL


@pytest.mark.parametrize(
    "law, closed_form", [(NH, nh_tube), (CNH, cnh_tube)], ids=["nh", "compressible_nh"]
)
def test_string_ring_inflation(law, closed_form, verification):
    """A quarter ring of string in 2D (plane strain, per unit depth, 16 cells) follows the
    tube's closed form to hoop stretch 2."""
    pressures = closed_form(np.array([1.1, 1.3, 1.6, 2.0]))
    errors = ring_errors(16, law, closed_form, pressures, reverse=True)
    case = f"free inflation, {type(law).__name__} quarter string ring, 16 cells"
    record_inflation(verification, case, errors, REL_TOL, TUBE)
    assert errors.max() < REL_TOL


def test_inflation_independent_of_vertex_order(verification):
    """Reversing every other cell changes nothing: the same stretches to round-off."""
    axes = {k: _on_plane(k) for k in range(3)}
    stretches = [
        inflate(meshes.sphere_octant(MPI.COMM_WORLD, R, 8, reverse), NH, SPHERE_STEPS[:3], axes, 3)
        for reverse in (False, True)
    ]
    assert np.all(stretches[0] > 1.0)
    change = np.abs(stretches[1] / stretches[0] - 1.0).max()
    case = "free inflation, Neo-Hookean sphere octant, 8 cells per arc"
    quantity = "largest |l_reversed / l - 1|, every other cell reversed"
    source = "the oriented normal: the same problem whatever the vertex order"
    verification(case, quantity, change, 0.0, ROUND_OFF, source, kind="consistency")
    assert change < ROUND_OFF
