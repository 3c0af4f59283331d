"""Observed Taylor slopes of the full residual (bulk + contact, both bodies, lambda_N).

A consistent tangent gives slope 2; freezing the projected point (``--frozen``) gives 1.

    python benchmarks/taylor.py --json benchmarks/results/taylor.json
"""

import argparse

import resultfile
from mpi4py import MPI

from contact_ufl.taylor import taylor_test
from contact_ufl.verification.taylor_cases import curved_case


def run(dim: int, frozen: bool) -> dict:
    problem, dz, steps = curved_case(dim, num_steps=5)
    problem.contacts[0].kinematics.frozen_projection = frozen
    result = taylor_test(problem, dz, steps)
    return {
        "dim": dim,
        "frozen_projection": frozen,
        "h": result.h.tolist(),
        "remainder": result.first.tolist(),
        "slopes": result.slopes.tolist(),
        "active_points": problem.active_points(),
        "facets_changed": result.facets_changed,
        "active_changed": result.active_changed,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--frozen", action="store_true", help="also run with a frozen projection")
    args = parser.parse_args()
    records = [run(dim, False) for dim in (2, 3)]
    if args.frozen:
        records += [run(dim, True) for dim in (2, 3)]
    if MPI.COMM_WORLD.rank == 0:
        for r in records:
            slopes = " ".join(f"{s:.4f}" for s in r["slopes"])
            print(
                f"{r['dim']}D frozen={r['frozen_projection']!s:5} active={r['active_points']:5d}"
                f" slopes: {slopes}  (facets changed: {r['facets_changed']})"
            )
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
