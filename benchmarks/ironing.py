"""Shallow ironing (2D, large frictional sliding): Yang, Laursen & Meng 2005; Poulios &
Renard 2015.

A Neo-Hookean block 12 x 4 clamped at its bottom and a ten times stiffer indenter 1.2 wide
with a rounded bottom (radius 0.75, 0.2 above the block): the indenter's top is pressed
down 1.0 (pseudo-time 0 to 1), then moved 10 along the block (1 to 2), with mu = 0 and
mu = 0.3. The master normal is the
smoothed one (the indenter slides over many master vertices).

Prints the forces on the indenter and |Fx/Fy| against the published forces and global
friction coefficients, the split of |Fx/Fy| into its frictional part (mu, where the
indenter slides) and the part of the normal pressure on the indenter's inclined front, and
the energy balance of the steady sliding (work = frictional dissipation + change of stored
energy). Writes JSON: a list of runs, each with ``mu``, ``history`` (records ``time``,
``Fx``, ``Fy``, ``newton_iterations``, ``converged``, and the contact force parts, energies
and prescribed displacement of each step) and ``cutbacks``.

    python benchmarks/ironing.py --json benchmarks/results/ironing.json [--quick]
"""

import argparse
import time

import resultfile
from mpi4py import MPI

from contact_ufl.verification.literature import IRONING_FORCES, IRONING_LITERATURE
from contact_ufl.verification.runs import energy_balance, history_at, ironing_run, steady_ratio


def print_forces(history: list[dict]) -> None:
    """|Fy|, |Fx| at the end of pressing and in steady sliding, against the published
    range (:data:`IRONING_FORCES`, mu = 0.3)."""
    print(f"{'':8} {'here':>10} {'published (mu = 0.3)':>24}")
    for k, t in enumerate((1.0, 1.5)):
        for j, key in enumerate(("Fy", "Fx")):
            published = [forces[k][j] for forces in IRONING_FORCES.values()]
            print(
                f"{key}({t}) {history_at(history, t, key):10.4e} "
                f"{min(published):11.4e} - {max(published):10.4e}"
            )


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
        run["steady_friction_part"] = steady_ratio(run["history"], part="contact_friction")
        run["steady_normal_part"] = steady_ratio(run["history"], part="contact_normal")
        work, dissipation, stored = energy_balance(run["history"])
        run["steady_energy"] = {"work": work, "dissipation": dissipation, "stored": stored}
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
            print(
                f"steady sliding (1.2 <= t <= 1.7): |Fx/Fy| = {run['steady_abs_Fx_over_Fy']:.4f}"
                f" = {run['steady_friction_part']:.4f} (friction) "
                f"+ {run['steady_normal_part']:.4f} (normal pressure, ploughing)"
            )
            print(
                f"energy over it: work {work:.4e} = dissipation {dissipation:.4e} + stored "
                f"{stored:.4e} (mismatch {(work - dissipation - stored) / work:+.2%})"
            )
            if mu == 0.3:
                print_forces(steps)
    if comm.rank == 0:
        print("published |Fx/Fy| at t = 1.5 with mu = 0.3:")
        for source, value in IRONING_LITERATURE.items():
            print(f"  {value:.2f}  {source}")
        resultfile.write(args.json, runs)


if __name__ == "__main__":
    main()
