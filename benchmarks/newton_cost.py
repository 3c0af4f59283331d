"""The cost of a Newton iteration and its parts, with contact and without (issue 12, item 4).

Solves each scene with :class:`~contact_ufl.problem.ContactProblem` and reads the solver's
:class:`~contact_ufl.newton.NewtonTimings` (seconds on rank 0, reset after the solver is
made, so the set-up is not counted):

* 2D Hertz (:func:`contact_ufl.verification.scenes.hertz_2d`, P1, depth 0.02 in two load
  steps), ``h_contact`` from 0.02 down to 0.0025;
* 3D two-beam scene (:func:`contact_ufl.verification.scenes.beams`, hexahedra, three load
  steps to a third of the demo's load);
* 3D Hertz, sphere on a block (:func:`contact_ufl.verification.scenes.hertz_3d`, P1
  tetrahedra, two load steps), ``h_contact`` 0.025 and 0.0125 (the benchmark's meshes).

Each scene is solved again as a *bulk* problem on the same mesh with the contact pair removed
(Hertz: the disc's arc, or the sphere's cap, held fixed instead, so the body is squeezed;
beams: the upper beam bends freely). The bulk problem still goes through the contact
solver, whose ``T`` is then the identity; its per-iteration cost counted here is residual
assembly + Jacobian assembly + linear solve (the identity PtAP and the empty search, which a
plain bulk Newton does not do, are left out). The ratio is contact / bulk seconds per Newton
iteration (issue 12's target: at most 1.3 at 100,000 unknowns in 2D and at the largest 3D size).

    python benchmarks/newton_cost.py --json benchmarks/results/newton_cost.json [--quick]
        [--repeat N] [--scenes hertz beams hertz3d]

The machine may be loaded: ``--repeat N`` solves each bulk / contact pair N times,
interleaved, and keeps the fastest run of each (least disturbed); the process CPU time is
recorded beside the wall times, and the load average at the start of each run.

Records: ``scene``, ``size`` (h_contact or divisions), ``case`` (``contact`` or ``bulk``),
``dofs``, ``newton_iterations``, ``new_patterns`` (Jacobians on a new pairing: a symbolic
PtAP), ``analyses`` (symbolic analyses of the factorisation: the solver matrix's pattern was
new or grew), ``wall_s``, ``cpu_s`` (process CPU time of the solve), ``load`` (1-minute load
average at the start) and, per Newton iteration, ``total_s`` (SNES time), ``search_s``,
``residual_assembly_s``, ``jacobian_assembly_s``, ``ptap_s``, ``linear_solve_s``,
``analysis_s`` and ``factorisation_s`` (PETSc's ``MatLUFactorSym`` and ``MatLUFactorNum``
events: MUMPS's analysis and numeric factorisation, inside ``linear_solve_s``), ``cpu_per_it_s``
and ``bulk_s`` (residual + Jacobian assembly + linear solve); contact records add ``ratio``
(their ``total_s`` over the bulk record's ``bulk_s``) and ``cpu_ratio`` (their
``cpu_per_it_s`` over the bulk record's).
"""

import argparse
import dataclasses
import json
import os
import time

from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl.loads import Dirichlet
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes

HERTZ_FULL = [0.02, 0.01, 0.005, 0.0025]
HERTZ_QUICK = [0.02, 0.01]
BEAMS_FULL = [3, 4]
BEAMS_QUICK = [3]
HERTZ3D_FULL = [0.025, 0.0125]
HERTZ3D_QUICK = [0.025]
PARTS = ("search", "residual_assembly", "jacobian_assembly", "ptap", "linear_solve")


def hertz(h: float, contact: bool):
    """The 2D Hertz scene, or its bulk counterpart (no contact, the arc held fixed)."""
    scene = scenes.hertz_2d(h_contact=h, depth=0.02).scene
    if not contact:
        arc = Dirichlet(scene.tags["cylinder_contact"], (0.0, 0.0))
        scene = dataclasses.replace(scene, contacts=[], dirichlet=[*scene.dirichlet, arc])
    return scene, 2, 1.0


def beams(divisions: int, contact: bool):
    """The two-beam scene (a third of the demo's load), or the same without contact."""
    scene = scenes.beams(divisions=divisions).scene
    if not contact:
        scene = dataclasses.replace(scene, contacts=[])
    return scene, 3, 1.0 / 3.0


def hertz3d(h: float, contact: bool):
    """The 3D Hertz scene, or its bulk counterpart (no contact, the sphere's cap held fixed)."""
    scene = scenes.hertz_3d(h_contact=h).scene
    if not contact:
        cap = Dirichlet(scene.tags["sphere_contact"], (0.0, 0.0, 0.0))
        scene = dataclasses.replace(scene, contacts=[], dirichlet=[*scene.dirichlet, cap])
    return scene, 2, 1.0


MAKERS = {"hertz": hertz, "beams": beams, "hertz3d": hertz3d}
FACTOR_EVENTS = {"analysis": "MatLUFactorSym", "factorisation": "MatLUFactorNum"}


def _event_seconds() -> dict[str, float]:
    """Seconds so far in PETSc's factorisation events (this rank)."""
    return {k: PETSc.Log.Event(e).getPerfInfo()["time"] for k, e in FACTOR_EVENTS.items()}


def run(make, size, contact: bool) -> dict:
    """Solve one scene and return its record."""
    scene, steps, t_end = make(size, contact)
    problem = ContactProblem(scene, verbose=False)
    timings = problem.solver.timings
    timings.reset()
    load = os.getloadavg()[0]
    events = _event_seconds()
    cpu = time.process_time()
    start = time.perf_counter()
    problem.solve(num_steps=steps, t_end=t_end)
    wall = time.perf_counter() - start
    cpu = time.process_time() - cpu
    events = {k: v - events[k] for k, v in _event_seconds().items()}
    per = timings.per_iteration()
    n = max(timings.iterations, 1)
    record = {
        "scene": make.__name__,
        "size": size,
        "case": "contact" if contact else "bulk",
        "dofs": problem.layout.global_size,
        "newton_iterations": timings.iterations,
        "new_patterns": timings.new_patterns,
        "analyses": timings.analyses,
        "wall_s": wall,
        "cpu_s": cpu,
        "load": load,
        "total_s": per["total"],
        **{f"{name}_s": per[name] for name in PARTS},
        **{f"{name}_s": t / n for name, t in events.items()},
        "cpu_per_it_s": cpu / n,
        "bulk_s": per["residual_assembly"] + per["jacobian_assembly"] + per["linear_solve"],
        "ranks": problem.comm.size,
    }
    return record


def fastest(records: list[dict]) -> dict:
    """The record of least CPU time per iteration (the least disturbed run), with the
    spread of that time over the runs."""
    best = dict(min(records, key=lambda r: r["cpu_per_it_s"]))
    best["runs"] = len(records)
    best["cpu_per_it_max_s"] = max(r["cpu_per_it_s"] for r in records)
    return best


COLUMNS = (*PARTS, "analysis", "factorisation")


def row(r: dict) -> str:
    """A line of the table (milliseconds per Newton iteration)."""
    ratios = " ".join(f"{r[k]:6.2f}" if k in r else f"{'':>6}" for k in ("ratio", "cpu_ratio"))
    return (
        f"{r['scene']:>7} {r['size']:7g} {r['case']:>7} {r['dofs']:8d} "
        f"{r['newton_iterations']:4d} {r['new_patterns']:4d} {r['analyses']:4d} "
        f"{1e3 * r['total_s']:7.1f} "
        + " ".join(f"{1e3 * r[p + '_s']:8.1f}" for p in COLUMNS)
        + f" {1e3 * r['cpu_per_it_s']:7.1f} {r['load']:5.2f} {ratios}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="two 2D sizes, one 3D each")
    parser.add_argument("--repeat", type=int, default=1, help="interleaved runs per case")
    parser.add_argument("--scenes", nargs="+", default=list(MAKERS), choices=list(MAKERS))
    parser.add_argument("--sizes", nargs="+", type=float, help="sizes (default: the scene's)")
    args = parser.parse_args()
    PETSc.Log.begin()
    sizes = {
        "hertz": HERTZ_QUICK if args.quick else HERTZ_FULL,
        "beams": BEAMS_QUICK if args.quick else BEAMS_FULL,
        "hertz3d": HERTZ3D_QUICK if args.quick else HERTZ3D_FULL,
    }
    cases = [(MAKERS[name], args.sizes or sizes[name]) for name in args.scenes]
    rank0 = MPI.COMM_WORLD.rank == 0
    header = (
        f"{'scene':>7} {'size':>7} {'case':>7} {'dofs':>8} {'its':>4} {'new':>4} {'ana':>4} "
        f"{'ms/it':>7} "
        + " ".join(f"{p[:8]:>8}" for p in COLUMNS)
        + f" {'cpu/it':>7} {'load':>5} {'ratio':>6} {'cpu_r':>6}"
    )
    if rank0:
        print(header, flush=True)
    records = []
    for make, sizes in cases:
        for size in sizes:
            size = int(size) if make is beams else size
            runs = [(run(make, size, False), run(make, size, True)) for _ in range(args.repeat)]
            bulk = fastest([b for b, _ in runs])
            with_contact = fastest([c for _, c in runs])
            with_contact["ratio"] = with_contact["total_s"] / bulk["bulk_s"]
            with_contact["cpu_ratio"] = with_contact["cpu_per_it_s"] / bulk["cpu_per_it_s"]
            for r in (with_contact, bulk):
                records.append(r)
                if rank0:
                    print(row(r), flush=True)
    if rank0:
        with open(args.json, "w") as f:
            json.dump(records, f, indent=1)


if __name__ == "__main__":
    main()
