"""Speed against error: the 2D Hertz problem on a sequence of meshes.

Prints a table and writes one JSON record per mesh: dofs, h, p0_error, a_error,
newton_iterations, wall_s (solve time), search_s (time in the closest-point projection).

    python benchmarks/hertz.py --json benchmarks/results/hertz.json [--quick]
    mpirun -n 2 python benchmarks/hertz.py --json ...
"""

import argparse
import json
import time

from mpi4py import MPI

from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import Hertz2D, fit_elliptic_profile

FULL = [0.02, 0.01, 0.005, 0.0025, 0.00125]
QUICK = [0.02, 0.01, 0.005]


def run(h: float, depth: float, steps: int) -> dict:
    hertz = scenes.hertz_2d(h_contact=h, depth=depth)
    problem = ContactProblem(hertz.scene, verbose=False)
    start = time.perf_counter()
    problem.solve(num_steps=steps)
    wall = time.perf_counter() - start
    samples = contact_samples(problem)
    exact = Hertz2D(problem.contact_force()[1], hertz.radius, hertz.E_star)
    a, p0, _ = fit_elliptic_profile(samples.x[:, 0], samples.pressure)
    return {
        "dofs": problem.layout.global_size,
        "h": h,
        "a_over_h": exact.a / h,
        "p0_error": p0 / exact.p0 - 1.0,
        "a_error": a / exact.a - 1.0,
        "newton_iterations": sum(r.newton_iterations for r in problem.history.steps),
        "wall_s": wall,
        "search_s": problem.search_time,
        "ranks": problem.comm.size,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="three coarse meshes (< 1 min)")
    parser.add_argument("--depth", type=float, default=0.005)
    parser.add_argument("--steps", type=int, default=4)
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    records = []
    header = (
        f"{'h':>8} {'dofs':>8} {'a/h':>6} {'a err':>9} {'p0 err':>9} {'newton':>6} "
        f"{'wall s':>8} {'search s':>8}"
    )
    if comm.rank == 0:
        print(header)
    for h in QUICK if args.quick else FULL:
        r = run(h, args.depth, args.steps)
        records.append(r)
        if comm.rank == 0:
            print(
                f"{r['h']:8.5f} {r['dofs']:8d} {r['a_over_h']:6.1f} {r['a_error']:+9.4f} "
                f"{r['p0_error']:+9.4f} {r['newton_iterations']:6d} {r['wall_s']:8.2f} "
                f"{r['search_s']:8.3f}",
                flush=True,
            )
    if comm.rank == 0:
        with open(args.json, "w") as f:
            json.dump(records, f, indent=2)


if __name__ == "__main__":
    main()
