"""The hard-case suite (issue 13, item 7): every hard case that exists today, and the
planned ones listed as not implemented.

For each case: steps, cut-backs, Newton iterations per accepted step (max and mean), whether
every step converged (SNES's converged reasons), wall time, and, where a step failed, why:
the SNES reason of every failed try, with the number of inverted cells (det F < 0), of
contact points in contact and of those whose contact status differs from the last accepted
step, at the failed state. A case stopped by a ``ConvergenceError`` is
recorded as ``stopped`` with the error, not raised. See
:mod:`contact_ufl.verification.hard_cases`.

    python benchmarks/hard_cases.py --json benchmarks/results/hard_cases.json [--quick]
"""

import argparse
import json
from pathlib import Path

from mpi4py import MPI

from contact_ufl.verification.hard_cases import NOT_IMPLEMENTED, cases, run_case


def why(record: dict) -> str:
    """The failed tries in one line: reason (count), and the most inverted cells seen."""
    failures = record["failures"]
    if not failures:
        return ""
    reasons = [f["reason"] for f in failures]
    counts = ", ".join(f"{r} x{reasons.count(r)}" for r in sorted(set(reasons)))
    inverted = max(f["inverted_cells"] for f in failures)
    changes = [f["status_changes"] for f in failures if f["status_changes"] is not None]
    changed = f"; status changes <= {max(changes)}" if changes else ""
    return f"{counts}; inverted cells <= {inverted}{changed}"


def print_table(records: list[dict], header: bool = True) -> None:
    if header:
        print(
            f"{'case':26} {'status':10} {'t':>6} {'steps':>5} {'cuts':>4} {'newton':>10} "
            f"{'all conv':>8} {'wall s':>7}  why"
        )
    for r in records:
        if r["status"] == "not implemented":
            print(f"{r['name']:26} not implemented: {r['description']}")
            continue
        newton = f"{r['newton_max']}/{r['newton_mean']:.1f}"
        print(
            f"{r['name']:26} {r['status']:10} {r['t_reached']:6.3f} {r['steps']:5d} "
            f"{r['cutbacks']:4d} {newton:>10} {str(r['all_converged']):>8} "
            f"{r['wall_s']:7.1f}  {why(r)}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="coarse meshes, larger steps")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    records = []
    for case in cases(quick=args.quick):
        records.append(run_case(case))
        if comm.rank == 0:
            print_table(records[-1:], header=len(records) == 1)
    records += [
        {"name": name, "status": "not implemented", "description": text}
        for name, text in NOT_IMPLEMENTED.items()
    ]
    if comm.rank == 0:
        print()
        print_table(records)
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        with open(args.json, "w") as f:
            json.dump({"quick": args.quick, "ranks": comm.size, "cases": records}, f, indent=1)


if __name__ == "__main__":
    main()
