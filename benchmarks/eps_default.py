"""The default augmentation parameter under refinement (issue 12, item 3).

The default ``eps_N = E / L`` (E the softer body's Young's modulus, L the diameter of the
slave surface; ``eps_T = eps_N``) is a length of the scene, not of the mesh. This benchmark
shows on a sequence of meshes that with it

* the Newton iterations per load step do not grow under refinement, and
* the result does not depend on eps: the same scene solved with ``10 eps`` and ``eps / 10``
  gives the contact force and the peak pressure of the default, to differences that live
  in the elements cut by the edge of the contact zone and fall under refinement;

and, for comparison, the same with the scenes' own ``eps_N = E / h_contact``.

Scenes (small-strain :class:`~contact_ufl.materials.LinearElastic` bulk, one load step):

* ``--dim 2``: the plane-strain Hertz half disc on a block
  (:func:`contact_ufl.verification.scenes.hertz_2d`, depth 0.02), ``h_contact`` from 0.02
  down to 0.0025 (to 0.005 with ``--quick``);
* ``--dim 3``: the quarter ball on a block (:func:`contact_ufl.verification.scenes.hertz_3d`,
  depth 0.01), ``h_contact`` from 0.05 down to 0.01 (to 0.025 with ``--quick``).

``--degree 2`` solves with P2 displacements (``ContactProblem(degree=2)``) on the
curved (degree-2) mesh: in 2D on :data:`MESHES_P2` (twice the P1 sizes), in 3D with the
contact rule of degree 4 on the coarser meshes :data:`MESHES_3D_P2`; ``--h`` gives the
meshes.

    python benchmarks/eps_default.py --json benchmarks/results/eps_default_2d.json
    python benchmarks/eps_default.py --dim 3 --json benchmarks/results/eps_default_3d.json
    python benchmarks/eps_default.py --degree 2 --json benchmarks/results/eps_default_2d_p2.json
    python benchmarks/eps_default.py --dim 3 --degree 2 --json \
        benchmarks/results/eps_default_3d_p2.json

Records, one per mesh and eps: ``dim``, ``degree``, ``h_contact``, ``dofs``, ``eps`` (the
case, :data:`EPS_CASES`), ``eps_factor`` (``eps_N`` over the default's), ``eps_N``,
``newton_max``, ``newton_mean`` (iterations per load step), ``steps``, ``cutbacks``,
``force`` (the contact force's component along the approach; 3D: the quarter model's),
``p0`` (the peak of the Hertz profile fitted to the computed pressure), ``p0_error``
(against Hertz's peak pressure under the computed force), ``peak`` (the largest nodal
multiplier), ``force_change``, ``p0_change``, ``peak_change`` (relative to the default's on
the same mesh), ``wall_s``, ``ranks``, ``iterates`` (per Newton iterate of all tries:
iterate, residual norm, slave points in contact, points that changed status since the
previous iterate; see :func:`trace_iterates`).
"""

import argparse
import dataclasses
import time
from collections.abc import Callable, Sequence

import numpy as np
import resultfile
from mpi4py import MPI

from contact_ufl.materials import LinearElastic
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import Hertz2D, fit_elliptic_profile
from contact_ufl.verification.runs import hertz_3d_errors

MESHES = {2: [0.02, 0.01, 0.005, 0.0025], 3: [0.05, 0.035, 0.025, 0.0175, 0.0125, 0.01]}
#: 2D P2: twice the P1 sizes (about the P1 meshes' unknowns), on the curved mesh
MESHES_P2 = {2: [0.04, 0.02, 0.01, 0.005]}
QUICK = {2: [0.02, 0.01, 0.005], 3: [0.05, 0.035, 0.025]}
MESHES_3D_P2 = [0.07, 0.05, 0.035, 0.025]
"""3D with ``--degree 2``: coarser meshes (a / h_contact ~ 1.5 to 4; 8,000 to 25,000
unknowns); with ``--quick`` the first three."""
EPS_CASES = ("default", "10 default", "default / 10", "E / h")
"""The eps of the runs on each mesh: the default, ten times it, a tenth of it, and the
scenes' own ``E / h_contact`` (for comparison: the eps that grows under refinement)."""
STEPS = 1


def hertz_scene(dim: int, h: float, degree: int = 1):
    """The Hertz scene of dimension ``dim`` with a linear elastic bulk (its ``eps_N`` the
    scene's ``E / h_contact``), and its analytic data; on the curved (degree-2) mesh when
    the displacement's ``degree`` is 2."""
    if dim == 2:
        hertz = scenes.hertz_2d(h_contact=h, depth=0.02, order=degree)
        hertz.scene.bodies = [
            dataclasses.replace(b, material=LinearElastic(b.material.E, b.material.nu))
            for b in hertz.scene.bodies
        ]
        return hertz
    return scenes.hertz_3d(h_contact=h, depth=0.01, order=degree)


def fitted_p0(problem: ContactProblem, hertz) -> tuple[float, float]:
    """The peak of the Hertz profile fitted to the computed pressure, and its error against
    Hertz's peak under the computed force (2D: :func:`fit_elliptic_profile`; 3D:
    :func:`hertz_3d_errors`)."""
    if problem.gdim == 2:
        samples = contact_samples(problem)
        _, p0, _ = fit_elliptic_profile(samples.x[:, 0], samples.pressure)
        exact = Hertz2D(problem.contact_force()[1], hertz.radius, hertz.E_star).p0
        return p0, p0 / exact - 1.0
    errors = hertz_3d_errors(problem, hertz)
    return errors["p0"] * (1.0 + errors["p0_error"]), errors["p0_error"]


def trace_iterates(problem: ContactProblem) -> list[list]:
    """Record, at every Newton iterate of the problem's solves (all tries), ``[iterate,
    residual norm, slave points in contact, points that changed status since the previous
    iterate]`` (summed over the ranks; -1 changed at the first iterate). Returns the list
    the records go to."""
    trace, previous = [], []
    c = problem.contacts[0]

    def monitor(snes, its, norm):
        active = c.active()
        changed = int((active != previous[0]).sum()) if previous else 0
        previous[:] = [active]
        counts = problem.comm.allreduce(np.array([active.sum(), changed]), op=MPI.SUM)
        trace.append([its, float(norm), int(counts[0]), int(counts[1]) if trace else -1])

    problem.solver.snes.setMonitor(monitor)  # in addition to the solver's own
    return trace


def run(dim: int, h: float, degree: int, case: str, eps_default: float | None) -> dict:
    """Solve one mesh with the eps of ``case`` (:data:`EPS_CASES`; ``eps_default`` the
    default's value on this mesh, unknown for ``"default"`` itself)."""
    hertz = hertz_scene(dim, h, degree)
    scene = hertz.scene
    if case != "E / h":
        eps = {"default": None, "10 default": 10.0, "default / 10": 0.1}[case]
        eps = eps and eps * eps_default
        scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=eps)
    problem = ContactProblem(scene, degree=degree, verbose=False)
    trace = trace_iterates(problem)
    start = time.perf_counter()
    problem.solve(num_steps=STEPS)
    wall = time.perf_counter() - start
    newton = [s.newton_iterations for s in problem.history.steps]
    c = problem.contacts[0]
    eps_N = float(c.normal.eps_N.value)
    force = float(problem.contact_force()[dim - 1])
    peak = problem.comm.allreduce(c.normal.lambda_N.x.array.max(initial=0.0), op=MPI.MAX)
    p0, p0_error = fitted_p0(problem, hertz)
    return {
        "dim": dim,
        "degree": degree,
        "h_contact": h,
        "dofs": problem.layout.global_size,
        "eps": case,
        "eps_factor": 1.0 if eps_default is None else eps_N / eps_default,
        "eps_N": eps_N,
        "newton_max": max(newton),
        "newton_mean": sum(newton) / len(newton),
        "steps": len(newton),
        "cutbacks": len(problem.history.cutbacks),
        "force": force,
        "p0": p0,
        "p0_error": p0_error,
        "peak": peak,
        "wall_s": wall,
        "ranks": problem.comm.size,
        "iterates": trace,
    }


def compared_to_default(
    solve: Callable[[str, float | None], dict], cases: Sequence[str], quantities: Sequence[str]
) -> list[dict]:
    """The records ``solve(case, eps_default)`` of ``cases`` on one mesh, the first the
    default (``eps_default`` None; the others get its ``eps_N``), each with ``<q>_change``,
    its quantity ``q`` relative to the default's, for each of ``quantities``."""
    default = solve(cases[0], None)
    records = [default] + [solve(case, default["eps_N"]) for case in cases[1:]]
    for r in records:
        for q in quantities:
            r[f"{q}_change"] = r[q] / default[q] - 1.0
    return records


def mesh_records(dim: int, h: float, degree: int) -> list[dict]:
    """The runs of :data:`EPS_CASES` on one mesh, with the changes against the default."""

    def solve(case: str, eps_default: float | None) -> dict:
        return run(dim, h, degree, case, eps_default)

    return compared_to_default(solve, EPS_CASES, ("force", "p0", "peak"))


HEADER = (
    f"{'h':>7} {'dofs':>7} {'eps':>12} {'eps/def':>7} {'eps_N':>8} {'its max':>7} {'mean':>5} "
    f"{'force':>12} {'p0':>10} {'p0 err':>8} {'dF':>9} {'dp0':>9} {'dpeak':>9} {'wall':>6}"
)


def row(r: dict) -> str:
    return (
        f"{r['h_contact']:7g} {r['dofs']:7d} {r['eps']:>12} {r['eps_factor']:7.3g} "
        f"{r['eps_N']:8.3g} "
        f"{r['newton_max']:7d} {r['newton_mean']:5.1f} {r['force']:12.6e} {r['p0']:10.4e} "
        f"{r['p0_error']:8.1e} {r['force_change']:9.1e} {r['p0_change']:9.1e} "
        f"{r['peak_change']:9.1e} {r['wall_s']:6.1f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="three meshes")
    parser.add_argument("--degree", type=int, choices=(1, 2), default=1)
    parser.add_argument("--dim", type=int, choices=(2, 3), default=2)
    parser.add_argument("--h", type=float, nargs="+", default=None, help="h_contact list")
    args = parser.parse_args()
    rank0 = MPI.COMM_WORLD.rank == 0
    if rank0:
        print(f"Hertz {args.dim}D, P{args.degree}, {STEPS} load step(s)\n{HEADER}", flush=True)
    records = []
    meshes = (QUICK if args.quick else MESHES)[args.dim]
    if args.degree == 2 and args.dim == 2 and not args.quick:
        meshes = MESHES_P2[2]
    if args.degree == 2 and args.dim == 3:
        meshes = MESHES_3D_P2[:3] if args.quick else MESHES_3D_P2
    for h in args.h or meshes:
        for r in mesh_records(args.dim, h, args.degree):
            records.append(r)
            if rank0:
                print(row(r), flush=True)
    if rank0:
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
