"""The hard-case suite (issue 13, item 7): every hard case that exists today, and the
planned ones listed as not implemented.

The cases: 2D ironing (mu = 0 and 0.3), the two-beam showcase (mu = 0 and 0.3), force-driven
contact in 2D and 3D, deep indentation in 2D (and 3D in the full suite) with the facet and
the smoothed master normal, a ring squeezed until its hole closes on itself (self-contact),
and a balloon past its pressure maximum (a limit point): through it under volume control,
and under load control, which is expected to stop there with a "limit point" diagnosis
(``expected stop``, not a failure of the suite).

For each case: steps, cut-backs, Newton iterations per accepted step (max and mean), whether
every step converged (SNES's converged reasons), wall time, and, where a step failed, why:
the SNES reason of every failed try, with the number of inverted cells (det F < 0), of
contact points in contact and of those whose contact status differs from the last accepted
step, at the failed state, and the diagnosis (inverted elements, active-set cycling, a
limit point). A case stopped by a ``ConvergenceError`` is recorded as ``stopped`` (or
``expected stop``) with the error, not raised. See
:mod:`contact_ufl.verification.hard_cases`.

    python benchmarks/hard_cases.py --json benchmarks/results/hard_cases.json [--quick]
        [--cases NAME [NAME ...]]

``--cases`` runs only the named cases, in the order given (the others are recorded as
``"not run"``). The JSON is written after every case, in the suite's order, so a run that is
stopped (a time-out) keeps the cases it finished; the cases it did not reach are recorded as
``"not run"`` with why, never with numbers of an earlier run.
"""

import argparse

import resultfile
from mpi4py import MPI

from contact_ufl.verification.hard_cases import NOT_IMPLEMENTED, cases, run_case

CAUSES = {
    "inverted elements": "inverted elements",
    "active-set cycling": "active-set cycling",
    "limit point": "limit point",
    "status changing in": "slow, contact state changing",
}
"""Short names of the diagnoses of :meth:`contact_ufl.strategies.StepSolver.diagnose`, by a
text each contains."""


def cause(why: str) -> str:
    """The short name of a failed try's diagnosis (``"no convergence"`` for the others)."""
    return next((name for key, name in CAUSES.items() if key in why), "no convergence")


def why(record: dict) -> str:
    """The failed tries in one line: the diagnoses and reasons (count), the most inverted
    cells and contact status changes seen."""
    failures = record["failures"]
    if not failures:
        return ""
    causes = [cause(f["why"]) for f in failures]
    reasons = [f["reason"] for f in failures]
    counts = ", ".join(f"{r} x{causes.count(r)}" for r in sorted(set(causes)))
    counts += " (" + ", ".join(f"{r} x{reasons.count(r)}" for r in sorted(set(reasons))) + ")"
    inverted = max(f["inverted_cells"] for f in failures)
    changes = [f["status_changes"] for f in failures if f["status_changes"] is not None]
    changed = f"; status changes <= {max(changes)}" if changes else ""
    return f"{counts}; inverted cells <= {inverted}{changed}"


def print_table(records: list[dict], header: bool = True) -> None:
    """Print one line per record (with a header line if ``header``)."""
    if header:
        print(
            f"{'case':34} {'status':13} {'t':>6} {'steps':>5} {'cuts':>4} {'newton':>10} "
            f"{'all conv':>8} {'wall s':>7}  why"
        )
    for r in records:
        if r["status"] in ("not implemented", "not run"):
            print(f"{r['name']:34} {r['status']}: {r['description']}")
            continue
        newton = f"{r['newton_max']}/{r['newton_mean']:.1f}"
        print(
            f"{r['name']:34} {r['status']:13} {r['t_reached']:6.3f} {r['steps']:5d} "
            f"{r['cutbacks']:4d} {newton:>10} {str(r['all_converged']):>8} "
            f"{r['wall_s']:7.1f}  {why(r)}"
        )


NOT_SELECTED = "not run this time (not in --cases)"
NOT_REACHED = "not run this time (the run ended before this case)"


def write(path: str, quick: bool, ranks: int, records: list[dict]) -> None:
    """Write the report to ``path``: ``quick``, ``ranks`` and ``records`` (the suite's order)."""
    resultfile.write(path, {"quick": quick, "ranks": ranks, "cases": records}, ranks=ranks)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="coarse meshes, larger steps")
    parser.add_argument("--cases", nargs="+", metavar="NAME", help="run only these, in order")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    suite = {case.name: case for case in cases(quick=args.quick)}
    selected = args.cases or list(suite)
    unknown = [name for name in selected if name not in suite]
    if unknown:
        parser.error(f"unknown case(s) {unknown}; the cases are {list(suite)}")
    records = {
        name: {
            "name": name,
            "status": "not run",
            "description": NOT_REACHED if name in selected else NOT_SELECTED,
        }
        for name in suite
    }
    records |= {
        name: {"name": name, "status": "not implemented", "description": text}
        for name, text in NOT_IMPLEMENTED.items()
    }
    for i, name in enumerate(selected):
        records[name] = run_case(suite[name])
        if comm.rank == 0:
            print_table([records[name]], header=i == 0)
            write(args.json, args.quick, comm.size, list(records.values()))
    if comm.rank == 0:
        print()
        print_table(list(records.values()))


if __name__ == "__main__":
    main()
