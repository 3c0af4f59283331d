"""3D ironing (large frictional sliding of a die over a slab): Puso & Laursen 2004, example 2.

A Neo-Hookean slab 9 x 4 x 3 (E = 1, nu = 0.3) clamped at its bottom, and a die 1000
times stiffer whose bottom is a cylinder of radius 3 across the slab (5.2 wide, the slab 4):
the die's top is pressed down 1.4 (pseudo-time 0 to 1), then moved 4 along the slab (1 to 2),
with mu = 0 and mu = 0.3, the smoothed master normal (node fans) on the slab's top.
(:func:`contact_ufl.verification.scenes.ironing_3d`; the data are those of the LLNL Smith
example ``die-on-slab``, which reproduces the publication.)

Prints the forces on the die's top and writes JSON: a list of runs, each with ``mu``,
``history`` (records ``time``, ``Fx``, ``Fy``, ``Fz``, ``newton_iterations``,
``converged``, contact force parts, energies) and ``cutbacks``.

Status: the pressing converges (tests/test_ironing_3d.py); the sliding on the quick mesh
did not finish within ten minutes in a first try (TODO: find why; no results file yet).
The comparison with the published force histories is a TODO: no digitised numbers of the
published curves were reachable (see :data:`contact_ufl.verification.literature.IRONING_3D`).

    python benchmarks/ironing_3d.py --json benchmarks/results/ironing_3d.json [--quick]
"""

import argparse
import json
import time

from mpi4py import MPI

from contact_ufl.verification.literature import IRONING_3D
from contact_ufl.verification.runs import ironing_3d_run

#: Meshes and steps: ``--quick`` (a few minutes on one core) and the default.
QUICK = dict(h_die=0.6, h_slab=0.75, press_steps=10, slide_steps=20)
DEFAULT = dict(h_die=0.3, h_slab=0.5, press_steps=10, slide_steps=40)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="coarse meshes, larger steps")
    parser.add_argument("--mu", type=float, nargs="+", default=[0.0, 0.3])
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    options = QUICK if args.quick else DEFAULT
    runs = []
    for mu in args.mu:
        start = time.perf_counter()
        run, problem = ironing_3d_run(mu, **options)
        run["wall_s"] = time.perf_counter() - start
        run["search_s"] = problem.search_time
        run["options"] = options
        runs.append(run)
        if comm.rank == 0:
            steps = run["history"]
            its = sum(r["newton_iterations"] for r in steps)
            print(
                f"mu = {mu}: {run['unknowns']} unknowns, {len(steps)} steps, "
                f"{len(run['cutbacks'])} cut-backs, {its} Newton iterations, "
                f"wall {run['wall_s']:.0f} s (search {run['search_s']:.1f} s)"
            )
            print(f"{'t':>6} {'Fx':>10} {'Fy':>10} {'Fz':>10} {'|Fx/Fz|':>8} {'newton':>6}")
            for r in steps:
                print(
                    f"{r['time']:6.3f} {r['Fx']:10.4f} {r['Fy']:10.4f} {r['Fz']:10.4f} "
                    f"{abs(r['Fx'] / r['Fz']):8.4f} {r['newton_iterations']:6d}"
                )
    if comm.rank == 0:
        print(f"published force histories: {IRONING_3D['status']}")
        with open(args.json, "w") as f:
            json.dump(runs, f, indent=2)


if __name__ == "__main__":
    main()
