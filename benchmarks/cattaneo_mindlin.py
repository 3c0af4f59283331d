"""Cattaneo-Mindlin (2D): stick-zone half-width and shear traction against Johnson 7.1.

A Neo-Hookean half disc pressed on an identical block (Hertz), then its top is moved
sideways in steps (Q < mu P). For each tangential load level: Q / (mu P), the stick-zone
half-width against c = a sqrt(1 - Q/(mu P)) (key ``stick_zone_error``), the RMS error of the
shear traction inside |x| < 0.8 a relative to mu p0, Newton iterations and times.

    python benchmarks/cattaneo_mindlin.py --json benchmarks/results/cattaneo_mindlin.json
"""

import argparse
import time

import resultfile
from mpi4py import MPI

from contact_ufl.verification.runs import cattaneo_mindlin_run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--h", type=float, nargs="+", default=[0.005, 0.0025])
    parser.add_argument("--quick", action="store_true", help="only the coarse mesh")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    runs = []
    for h in args.h[:1] if args.quick else args.h:
        start = time.perf_counter()
        levels, problem = cattaneo_mindlin_run(h)
        runs.append(
            {
                "h": h,
                "dofs": problem.layout.global_size,
                "levels": levels,
                "wall_s": time.perf_counter() - start,
                "search_s": problem.search_time,
            }
        )
        if comm.rank == 0:
            print(
                f"h = {h}  dofs = {problem.layout.global_size}  "
                f"wall {runs[-1]['wall_s']:.1f} s  search {problem.search_time:.2f} s"
            )
            print(
                f"{'Q/muP':>7} {'c':>8} {'c exact':>8} {'c err':>7} {'shear err':>9} {'newton':>6}"
            )
            for r in levels:
                print(
                    f"{r['Q_over_muP']:7.3f} {r['c']:8.5f} {r['c_exact']:8.5f} "
                    f"{r['stick_zone_error']:+7.3f} {r['shear_error']:9.3f} "
                    f"{r['newton_iterations']:6d}"
                )
    if comm.rank == 0:
        resultfile.write(args.json, runs)


if __name__ == "__main__":
    main()
