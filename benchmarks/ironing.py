"""Shallow ironing (2D, large frictional sliding): Yang, Laursen & Meng 2005; Poulios &
Renard 2015.

A Neo-Hookean block 12 x 4 clamped at its bottom and a ten times stiffer indenter with a
rounded bottom (radius 0.75): the indenter's top is pressed down 1.0 (pseudo-time 0 to 1),
then moved 10 along the block (1 to 2), with mu = 0 and mu = 0.3. The master normal is the
smoothed one (the indenter slides over many master vertices).

Prints the forces on the indenter and |Fx/Fy| against the published global friction
coefficients, and writes JSON: a list of runs, each with ``mu``, ``history`` (records
``time``, ``Fx``, ``Fy``, ``newton_iterations``, ``converged``) and ``cutbacks``.

    python benchmarks/ironing.py --json benchmarks/results/ironing.json [--quick]
"""

import argparse
import json
import time

from mpi4py import MPI

from contact_ufl.verification import IRONING_LITERATURE, ironing_run, steady_ratio


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="coarse meshes, larger steps")
    parser.add_argument("--mu", type=float, nargs="+", default=[0.0, 0.3])
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    mesh = dict(h_punch=0.05, h_block=0.2, slide_steps=100) if args.quick else {}
    runs = []
    for mu in args.mu:
        start = time.perf_counter()
        run, problem = ironing_run(mu, **mesh)
        run["wall_s"] = time.perf_counter() - start
        run["search_s"] = problem.search_time
        run["steady_abs_Fx_over_Fy"] = steady_ratio(run["history"])
        runs.append(run)
        if comm.rank == 0:
            steps = run["history"]
            its = sum(r["newton_iterations"] for r in steps)
            print(
                f"mu = {mu}: {run['unknowns']} unknowns, {len(steps)} steps, "
                f"{len(run['cutbacks'])} cut-backs, {its} Newton iterations, "
                f"wall {run['wall_s']:.0f} s (search {run['search_s']:.1f} s)"
            )
            print(f"{'t':>6} {'Fx':>11} {'Fy':>11} {'|Fx/Fy|':>8} {'newton':>6}")
            for r in steps[:: max(1, len(steps) // 20)]:
                print(
                    f"{r['time']:6.3f} {r['Fx']:11.4e} {r['Fy']:11.4e} "
                    f"{abs(r['Fx'] / r['Fy']):8.4f} {r['newton_iterations']:6d}"
                )
            print(f"steady sliding (1.2 <= t <= 1.7): |Fx/Fy| = {run['steady_abs_Fx_over_Fy']:.4f}")
    if comm.rank == 0:
        print("published |Fx/Fy| at t = 1.5 with mu = 0.3:")
        for source, value in IRONING_LITERATURE.items():
            print(f"  {value:.2f}  {source}")
        with open(args.json, "w") as f:
            json.dump(runs, f, indent=2)


if __name__ == "__main__":
    main()
