"""The cost of a Newton iteration and its parts, with contact and without (issue 12, item 4).

Solves each scene with :class:`~contact_ufl.problem.ContactProblem` and reads the solver's
:class:`~contact_ufl.newton.NewtonTimings` (seconds on rank 0, reset after the solver is
made, so the set-up is not counted):

* 2D Hertz (:func:`contact_ufl.verification.scenes.hertz_2d`, P1, depth 0.02 in two load
  steps), ``h_contact`` from 0.02 down to 0.0025;
* 3D two-beam scene (:func:`contact_ufl.verification.scenes.beams`, hexahedra, three load
  steps to a third of the demo's load).

Each scene is solved again as a *bulk* problem on the same mesh with the contact pair removed
(Hertz: the disc's arc held fixed instead, so the disc is squeezed; beams: the upper beam
bends freely). The bulk problem still goes through the contact solver, whose ``T`` is then
the identity; its per-iteration cost counted here is residual assembly + Jacobian assembly
+ linear solve (the identity PtAP and the empty search, which a plain bulk Newton does not
do, are left out). The ratio is contact / bulk seconds per Newton iteration (issue 12's target:
at most 1.3 at 100,000 unknowns in 2D and at the largest 3D size).

    python benchmarks/newton_cost.py --json benchmarks/results/newton_cost.json [--quick]

Records: ``scene``, ``size`` (h_contact or divisions), ``case`` (``contact`` or ``bulk``),
``dofs``, ``newton_iterations``, ``new_patterns`` (Jacobians on a new sparsity pattern:
symbolic PtAP and factorisation redone), ``wall_s`` and, per Newton iteration, ``total_s`` (SNES
time), ``search_s``, ``residual_assembly_s``, ``jacobian_assembly_s``, ``ptap_s``,
``linear_solve_s``, ``bulk_s`` (residual + Jacobian assembly + linear solve); contact records
add ``ratio`` (their ``total_s`` over the bulk record's ``bulk_s``).
"""

import argparse
import dataclasses
import json
import time

from mpi4py import MPI

from contact_ufl.loads import Dirichlet
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes

HERTZ_FULL = [0.02, 0.01, 0.005, 0.0025]
HERTZ_QUICK = [0.02, 0.01]
BEAMS_FULL = [3, 4]
BEAMS_QUICK = [3]
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


def run(make, size, contact: bool) -> dict:
    """Solve one scene and return its record."""
    scene, steps, t_end = make(size, contact)
    problem = ContactProblem(scene, verbose=False)
    timings = problem.solver.timings
    timings.reset()
    start = time.perf_counter()
    problem.solve(num_steps=steps, t_end=t_end)
    wall = time.perf_counter() - start
    per = timings.per_iteration()
    record = {
        "analyses": timings.analyses,
        "scene": make.__name__,
        "size": size,
        "case": "contact" if contact else "bulk",
        "dofs": problem.layout.global_size,
        "newton_iterations": timings.iterations,
        "new_patterns": timings.new_patterns,
        "wall_s": wall,
        "total_s": per["total"],
        **{f"{name}_s": per[name] for name in PARTS},
        "bulk_s": per["residual_assembly"] + per["jacobian_assembly"] + per["linear_solve"],
        "ranks": problem.comm.size,
    }
    return record


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="two 2D sizes, one 3D (< 1 min)")
    args = parser.parse_args()
    cases = [
        (hertz, HERTZ_QUICK if args.quick else HERTZ_FULL),
        (beams, BEAMS_QUICK if args.quick else BEAMS_FULL),
    ]
    rank0 = MPI.COMM_WORLD.rank == 0
    header = (
        f"{'scene':>6} {'size':>7} {'case':>7} {'dofs':>8} {'its':>4} {'new':>4} {'ms/it':>7} "
        + " ".join(f"{p[:8]:>8}" for p in PARTS)
        + f" {'ratio':>6}"
    )
    if rank0:
        print(header, flush=True)
    records = []
    for make, sizes in cases:
        for size in sizes:
            bulk = run(make, size, contact=False)
            with_contact = run(make, size, contact=True)
            with_contact["ratio"] = with_contact["total_s"] / bulk["bulk_s"]
            for r in (with_contact, bulk):
                records.append(r)
                if rank0:
                    ratio = f"{r['ratio']:6.2f}" if "ratio" in r else f"{'':>6}"
                    print(
                        f"{r['scene']:>6} {r['size']:7g} {r['case']:>7} {r['dofs']:8d} "
                        f"{r['newton_iterations']:4d} {r['new_patterns']:4d} "
                        f"{1e3 * r['total_s']:7.1f} "
                        + " ".join(f"{1e3 * r[p + '_s']:8.1f}" for p in PARTS)
                        + f" {ratio}",
                        flush=True,
                    )
    if rank0:
        with open(args.json, "w") as f:
            json.dump(records, f, indent=1)


if __name__ == "__main__":
    main()
