"""Effectivity of the residual error estimate (:mod:`contact_ufl.estimate`) against a true
error, under mesh refinement.

The true error is measured in the energy norm of the linearised elasticity at the reference
configuration, ``||e||_E = (int Grad e : C : Grad e dX)^1/2`` (``C`` of each body's ``E``,
``nu``), with ``e = u_ref - u_h``. On the patch test ``u_ref`` is the exact solution (a
homogeneous stretch, the roots of the Neo-Hookean plane-strain uniaxial stress) and the
integral is taken on the mesh of ``u_h``. Elsewhere ``u_ref`` is a P2 solve of the same
geometry (curved mesh) on a finer mesh through the same load steps, and the integral is
taken on its mesh: ``Grad u_h`` is moved there pointwise, body by body
(``create_interpolation_data`` and ``interpolate_nonmatching``), sampled at the points of a
quadrature rule of its cells (``error``). ``error_interpolated`` is the same norm with
``u_h`` itself interpolated into the reference space: that smooths the kinks of ``u_h``
over the reference cells across them and comes out lower the coarser the reference (2D
Hertz, s = 1/2: 15% lower against a reference at s = 1/4, 7% at s = 1/8, where ``error``
changed by 0.04%). The effectivity is ``eta / error``.

Cases, each on four meshes refined by a common factor ``s`` of all their sizes (the
grading stays the same family):

* ``hertz_2d``: the 2D Hertz scene of ``tests/test_estimate.py`` (Neo-Hookean, depth 0.02
  in 2 steps, ``h_contact = 0.04 s``, ``h_far = 0.2 s``); reference P2 at ``s = 1/8``;
* ``patch``: the 2D contact patch test (``h_upper = s / 10``, ``h_lower = s / 7``, the
  default contact rule); the exact solution;
* ``cattaneo``: Cattaneo-Mindlin (mu = 0.3, depth 0.005 in 4 steps, then the shift 0.0015
  in 4, ``h_contact = 0.01 s`` within 0.12 of the contact, ``h_far = 0.2 s``);
  reference P2 at ``s = 1/4``;
* ``hertz_3d`` (``--cases hertz_3d``, not by default, its own results file): the 3D
  quarter model, linear elastic (depth 0.01 in 2 steps, ``h_contact = 0.025 s``,
  ``h_far = 0.25 s``); reference P2 at ``s = 1`` (24,856 unknowns). On finer P2 meshes
  (``s`` = 0.85, 0.7) the contact states cycle from the first step, which is cut back
  again and again (unfinished after 10 minutes), and on the P1 mesh at ``s = 4`` (the
  contact radius one cell) they do too; the P1 error at ``s = 3.4`` is below that at
  ``s = 2.8`` (not yet refining), hence the meshes from ``s = 2.8``.
  The reference moved one step coarser (``s = 1.4``) changes the error at ``s`` = 2.8 and
  2 by 0.4%.

Each record: case, s, h_contact, unknowns, eta and its parts (``part_<term>``, each
term's eta^2), the errors, the effectivity, the error of the stored energy
``(2 |W_h - W_ref|)^1/2`` and ``eta`` over it, the solution's energy norm, the solve's and
the estimate's wall times, the reference (unknowns, s, wall time), and with the package's
weights (:data:`contact_ufl.estimate.WEIGHTS`, fitted to these records by :func:`fit`) the
weighted estimate and its effectivity (``eta_weighted``, ``effectivity_weighted``).
``--fit FILE`` prints the weights :func:`fit` finds for the records of a results file.

    python benchmarks/estimate_effectivity.py --json benchmarks/results/estimate_effectivity.json
    python benchmarks/estimate_effectivity.py --cases hertz_3d \
        --json benchmarks/results/estimate_effectivity_3d.json
    python benchmarks/estimate_effectivity.py --quick --cases hertz_2d patch --json FILE
    python benchmarks/estimate_effectivity.py --fit benchmarks/results/estimate_effectivity.json

One rank (the transfer to the reference mesh is written for one).
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import dolfinx_solver  # noqa: F401  (the MPI library before DOLFINx)

# isort: split
import basix.ufl
import dolfinx
import numpy as np
import resultfile
import ufl
from mpi4py import MPI
from scipy.optimize import fsolve

from contact_ufl.estimate import TERMS, WEIGHTS
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes

#: mesh factors s of each case (the reference's last), and the quick run's
SIZES = {
    "hertz_2d": ((2.0, 1.0, 0.5, 0.25), 0.125),
    "patch": ((1.0, 0.5, 0.25, 0.125), None),
    "cattaneo": ((2.0, 1.0, 0.7, 0.5), 0.25),
    "hertz_3d": ((2.8, 2.0, 1.7, 1.4), 1.0),
}
QUICK = {
    "hertz_2d": ((2.0, 1.0, 0.5), 0.25),
    "patch": ((1.0, 0.5, 0.25), None),
    "cattaneo": ((2.0, 1.0), 0.5),
    "hertz_3d": ((2.8, 2.0), 1.4),
}
PATCH_PRESSURE = 0.01
#: the rule on the reference cells at whose points the coarse gradient is sampled
QUADRATURE_DEGREE = 4


@dataclasses.dataclass
class Solved:
    """A converged solve: the problem, its mesh factor and degree, and its wall time."""

    problem: ContactProblem
    s: float
    h_contact: float
    degree: int
    wall_s: float


def _solve(case: str, s: float, degree: int) -> Solved:
    """Build and solve the scene of ``case`` at mesh factor ``s`` with displacements of
    ``degree`` (on a mesh of geometry order ``degree``)."""
    start = time.perf_counter()
    if case == "hertz_2d":
        h = 0.04 * s
        scene = scenes.hertz_2d(h_contact=h, h_far=0.2 * s, depth=0.02, order=degree).scene
        problem = ContactProblem(scene, degree=degree, verbose=False)
        problem.solve(num_steps=2)
    elif case == "cattaneo":
        h = 0.01 * s
        scene = scenes.hertz_2d(
            h_contact=h,
            h_far=0.2 * s,
            depth=0.005,
            mu=0.3,
            shift=0.0015,
            refine_radius=0.12,
            order=degree,
        ).scene
        problem = ContactProblem(scene, degree=degree, verbose=False)
        problem.solve(num_steps=4, t_end=1.0)
        problem.solve(num_steps=4, t_end=2.0)
    elif case == "patch":
        h = 0.1 * s
        scene = scenes.patch(2, PATCH_PRESSURE, h_upper=0.1 * s, h_lower=s / 7.0)
        problem = ContactProblem(scene, verbose=False, petsc_options={"snes_rtol": 1e-12})
        problem.solve(num_steps=1)
    elif case == "hertz_3d":
        h = 0.025 * s
        hertz = scenes.hertz_3d(h_contact=h, h_far=0.25 * s, depth=0.01, order=degree)
        problem = ContactProblem(hertz.scene, degree=degree, verbose=False)
        problem.solve(num_steps=2)
    else:
        raise ValueError(f"unknown case {case!r}")
    return Solved(problem, s, h, degree, time.perf_counter() - start)


def _lame(bulk) -> tuple[dolfinx.fem.Function, dolfinx.fem.Function]:
    """The shear modulus and first Lame parameter of each cell's body (DG0)."""
    space = dolfinx.fem.functionspace(bulk.V.mesh, ("DG", 0))
    mu, lmbda = dolfinx.fem.Function(space), dolfinx.fem.Function(space)
    for body in bulk.bodies:
        cells = bulk.domain.cell_tags.find(body.tag)
        mu.x.array[cells] = body.material.mu
        lmbda.x.array[cells] = body.material.lmbda
    return mu, lmbda


def energy_norm(bulk, grad_e, quadrature_degree: int | None = None) -> float:
    """``(int Grad e : C : Grad e dX)^1/2`` over the mesh of ``bulk``, ``C`` the linear
    elasticity of each body's ``E``, ``nu``, of the expression ``grad_e`` of ``Grad e``
    (the rule of degree ``quadrature_degree``, default twice the displacement's)."""
    mu, lmbda = _lame(bulk)
    eps = ufl.sym(grad_e)
    if quadrature_degree is None:
        quadrature_degree = 2 * bulk.V.ufl_element().degree
    dx = ufl.dx(domain=bulk.V.mesh, metadata={"quadrature_degree": quadrature_degree})
    form = (2.0 * mu * ufl.inner(eps, eps) + lmbda * ufl.tr(eps) ** 2) * dx
    value = dolfinx.fem.assemble_scalar(dolfinx.fem.form(form))
    return float(np.sqrt(bulk.comm.allreduce(value, MPI.SUM)))


def _body_submesh(coarse, body):
    """The submesh of the cells of ``body`` in bulk ``coarse`` and those cells (parent
    numbers, in the submesh's order)."""
    mesh = coarse.V.mesh
    tdim = mesh.topology.dim
    cells = coarse.domain.cell_tags.find(body.tag)
    sub, entity_map, _, _ = dolfinx.mesh.create_submesh(mesh, tdim, cells)
    parents = entity_map.sub_topology_to_topology(
        np.arange(sub.topology.index_map(tdim).size_local, dtype=np.int32), inverse=False
    )
    return sub, parents


def _move(source, target: dolfinx.fem.Function, cells, padding: float) -> None:
    """Interpolate ``source`` pointwise into ``target`` on its mesh's ``cells`` (another
    mesh of the same body), looking the points up within ``padding`` of ``source``'s cells.
    Raises if a point is found in no cell."""
    V = target.function_space
    gdim = V.mesh.geometry.dim
    x = ufl.SpatialCoordinate(V.mesh)
    x = dolfinx.fem.Expression(x, V.element.interpolation_points).eval(V.mesh, cells)
    points = np.zeros((x.size // gdim, 3))
    points[:, :gdim] = x.reshape(-1, gdim)
    mesh = source.function_space.mesh
    owners = dolfinx.geometry.determine_point_ownership(mesh, points, padding).src_owner
    if np.any(np.asarray(owners) < 0):
        raise RuntimeError(f"{np.sum(np.asarray(owners) < 0)} points in no cell")
    data = dolfinx.fem.create_interpolation_data(V, source.function_space, cells, padding)
    target.interpolate_nonmatching(source, cells, data)


def transfer(coarse, fine, padding: float, quadrature_degree: int):
    """Bulk ``coarse``'s displacement on bulk ``fine``'s mesh (the same geometry, another
    mesh), body by body (each body's points looked up among that body's coarse cells only:
    near a contact point the other body is as close as the polygon's chord), within
    ``padding`` of them (points of a curved boundary outside the coarse polygon).

    Returns the displacement interpolated into ``fine``'s space, and its gradient at the
    quadrature points of degree ``quadrature_degree`` of ``fine``'s cells (a quadrature
    element). The second is the one to integrate: the interpolant smears each kink of the
    coarse displacement over the fine cells across it, which adds to the error's norm;
    the gradient sampled at quadrature points is only a quadrature of it."""
    mesh = fine.V.mesh
    gdim = mesh.geometry.dim
    element = basix.ufl.quadrature_element(
        mesh.basix_cell(), value_shape=(gdim, gdim), degree=quadrature_degree
    )
    moved = dolfinx.fem.Function(fine.V)
    gradient = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, element))
    degree = coarse.V.ufl_element().degree
    for body in coarse.bodies:
        sub, parents = _body_submesh(coarse, body)
        u = dolfinx.fem.Function(dolfinx.fem.functionspace(sub, coarse.V.ufl_element()))
        u.interpolate(coarse.u, cells0=parents, cells1=np.arange(len(parents), dtype=np.int32))
        G = dolfinx.fem.Function(dolfinx.fem.functionspace(sub, ("DG", degree - 1, (gdim, gdim))))
        G.interpolate(
            dolfinx.fem.Expression(ufl.grad(u), G.function_space.element.interpolation_points)
        )
        targets = fine.domain.cell_tags.find(body.tag)
        _move(u, moved, targets, padding)
        _move(G, gradient, targets, padding)
    moved.x.scatter_forward()
    gradient.x.scatter_forward()
    return moved, gradient


def _record(solved: Solved, error: float, W_ref: float) -> dict:
    """The record of a mesh: its estimate with unit weights and its parts (and its time),
    error and effectivities."""
    problem = solved.problem
    start = time.perf_counter()
    estimate = problem.error_estimate()
    estimate_s = time.perf_counter() - start
    # the terms with unit weights (the records' parts), and with the package's weights
    parts = {t: estimate.parts[t] / WEIGHTS[t] for t in TERMS}
    eta = float(np.sqrt(sum(parts.values())))
    W_h = problem.stored_energy()
    energy_error = float(np.sqrt(2.0 * abs(W_h - W_ref)))
    weighted = estimate.estimate
    return {
        "s": solved.s,
        "h_contact": solved.h_contact,
        "unknowns": problem.layout.global_size,
        "eta": eta,
        **{f"part_{t}": parts[t] for t in TERMS},
        "error": error,
        "effectivity": eta / error,
        "energy_error": energy_error,
        "energy_effectivity": eta / energy_error,
        "energy": estimate.energy,
        "eta_weighted": weighted,
        "effectivity_weighted": weighted / error,
        "weights": dict(WEIGHTS),
        "wall_s": solved.wall_s,
        "estimate_s": estimate_s,
    }


def _patch_exact(E: float = 1.0, nu: float = 0.3) -> np.ndarray:
    """The patch test's exact deformation gradient ``diag(a, b)``: plane-strain Neo-Hookean
    (``psi`` of :class:`~contact_ufl.materials.NeoHookean`) under the nominal uniaxial
    stress ``P_yy = -p``, ``P_xx = 0``; the roots of
    ``mu (a - 1/a) + lambda ln(ab) / a = 0`` and ``mu (b - 1/b) + lambda ln(ab) / b = -p``."""
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))

    def stress(x):
        a, b = x
        J = np.log(a * b)
        return [mu * (a - 1 / a) + lmbda * J / a, mu * (b - 1 / b) + lmbda * J / b + PATCH_PRESSURE]

    a, b = fsolve(stress, [1.0, 1.0], xtol=1e-15)
    if max(abs(r) for r in stress((a, b))) > 1e-15:
        raise RuntimeError("the patch test's stretch did not converge")
    return np.diag([a, b])


def _patch_energy(F: np.ndarray, E: float = 1.0, nu: float = 0.3, area: float = 1.0) -> float:
    """The stored energy of the homogeneous state ``F`` over the two blocks (area 1)."""
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    J = np.linalg.det(F)
    psi = 0.5 * mu * (np.trace(F.T @ F) - 2 - 2 * np.log(J)) + 0.5 * lmbda * np.log(J) ** 2
    return float(psi * area)


def run_case(case: str, sizes, reference_s, log) -> dict:
    """The records of ``case`` on the meshes ``sizes`` against its reference."""
    reference = None
    if case == "patch":
        F = _patch_exact()
        W_ref = _patch_energy(F)
        grad = ufl.as_matrix((F - np.eye(2)).tolist())
        reference = {"kind": "exact homogeneous solution", "F": np.diag(F).tolist()}
    else:
        fine = _solve(case, reference_s, 2)
        W_ref = fine.problem.stored_energy()
        (fine_bulk,) = fine.problem.bulks
        reference = {
            "kind": "P2 solve",
            "s": reference_s,
            "h_contact": fine.h_contact,
            "degree": 2,
            "unknowns": fine.problem.layout.global_size,
            "wall_s": fine.wall_s,
            "energy": float(np.sqrt(2.0 * W_ref)),
        }
        log(
            f"{case}: reference P2 s = {reference_s}, {reference['unknowns']} unknowns, "
            f"{fine.wall_s:.1f} s"
        )
    records = []
    for s in sizes:
        solved = _solve(case, s, 1)
        (bulk,) = solved.problem.bulks
        interpolated = None
        if case == "patch":
            error = energy_norm(bulk, grad - ufl.grad(bulk.u))
        else:
            # twice the sagitta of the coarsest chords of the curved surface (R = 1)
            padding = 0.25 * ((0.2 if case != "hertz_3d" else 0.25) * s) ** 2
            moved, gradient = transfer(bulk, fine_bulk, padding, QUADRATURE_DEGREE)
            error = energy_norm(fine_bulk, ufl.grad(fine_bulk.u) - gradient, QUADRATURE_DEGREE)
            interpolated = energy_norm(fine_bulk, ufl.grad(fine_bulk.u - moved))
        record = {"case": case, **_record(solved, error, W_ref), "reference": reference}
        record["error_interpolated"] = interpolated
        records.append(record)
        log(
            f"{case:9s} s={s:<6g} h={solved.h_contact:<8.5g} n={record['unknowns']:<7d} "
            f"eta={record['eta']:.3e} err={error:.3e} ({interpolated or 0:.3e}) "
            f"eff={record['effectivity']:.2f} "
            f"W-eff={record['energy_effectivity']:.2f} w-eff={record['effectivity_weighted']:.2f}"
            f" wall={solved.wall_s:.1f}s"
        )
        solved.problem.close()
    return records


#: the groups of terms that :func:`fit` weights by one factor each
GROUPS = {
    "residual": ("bulk", "jump", "boundary"),
    "contact": ("traction", "penetration", "complementarity", "cone"),
}


def weighted_effectivity(record: dict, weights: dict[str, float]) -> float:
    """The effectivity of ``record`` with the factors ``weights`` on its terms' eta^2 (the
    terms not named: 1)."""
    eta2 = sum(weights.get(t, 1.0) * record[f"part_{t}"] for t in TERMS)
    return float(np.sqrt(eta2) / record["error"])


def fit(records: list[dict], low: float = 1.0, high: float = 3.0) -> dict:
    """The factors of :data:`GROUPS` (a log grid, 0.01 to 10) that put the effectivities of
    all ``records`` farthest inside ``[low, high]`` in the log sense (the largest
    ``|ln(effectivity / sqrt(low high))|`` least), with the effectivities they give and
    each case's spread (largest over smallest)."""
    grid = np.logspace(-2, 1, 61)
    centre = np.sqrt(low * high)
    best = None
    for a in grid:
        for b in grid:
            weights = {t: w for w, g in ((a, "residual"), (b, "contact")) for t in GROUPS[g]}
            eff = np.array([weighted_effectivity(r, weights) for r in records])
            worst = float(np.abs(np.log(eff / centre)).max())
            if best is None or worst < best[0]:
                best = (worst, float(a), float(b), eff)
    _, a, b, eff = best
    spread = {}
    for case in dict.fromkeys(r["case"] for r in records):
        values = [e for e, r in zip(eff, records, strict=True) if r["case"] == case]
        spread[case] = max(values) / min(values)
    return {
        "residual": a,
        "contact": b,
        "inside": bool(eff.min() >= low and eff.max() <= high),
        "effectivity": eff.tolist(),
        "spread": spread,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json")
    parser.add_argument("--quick", action="store_true", help="three coarser meshes a case")
    parser.add_argument(
        "--cases",
        nargs="+",
        default=["hertz_2d", "patch", "cattaneo"],
        choices=tuple(SIZES),
        help="hertz_3d: not by default (its P2 reference is the slowest)",
    )
    parser.add_argument(
        "--fit", metavar="RESULTS", help="only fit the weights to the records of a results file"
    )
    args = parser.parse_args()
    if args.fit:
        found = fit(resultfile.load(args.fit))
        print(found)
        return
    if not args.json:
        parser.error("--json is required")
    comm = MPI.COMM_WORLD
    if comm.size > 1:
        parser.error("one rank only")
    table = QUICK if args.quick else SIZES
    records = []
    for case in args.cases:
        sizes, reference_s = table[case]
        records += run_case(case, sizes, reference_s, lambda line: print(line, flush=True))
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
