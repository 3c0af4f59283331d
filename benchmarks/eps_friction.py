"""The default tangential augmentation parameter under refinement (issue 12, item 3, friction).

``eps_T`` defaults to ``eps_N``, whose default is ``E / L`` (a length of the scene, not of
the mesh; see ``eps_default.py`` for the normal part). This benchmark shows on four meshes
of the Cattaneo-Mindlin scene (:func:`contact_ufl.verification.runs.cattaneo_mindlin_run`:
the plane-strain Hertz half disc pressed on a block in four steps, then its top moved
sideways in four steps, mu = 0.3, up to Q / (mu P) = 0.68), with the default ``eps_N``
and ``eps_T``,

* the Newton iterations per load step under refinement (pressing, and sliding with a stick
  zone that shrinks), and
* how the result depends on ``eps_T``: the same scene with ``10 eps_T`` and ``eps_T / 10``
  (``eps_N`` the default) against the default, the tangential force and the stick zone;

and, for comparison, the scene's own ``eps_N = eps_T = E / h``. Each record also has the
errors against Johnson's Cattaneo-Mindlin solution (7.1): the stick zone's half-width
``c`` and the shear traction's RMS in ``|x| < 0.8 a`` relative to ``mu p0``.

    python benchmarks/eps_friction.py --json benchmarks/results/eps_friction.json [--quick]

Records, one per mesh and case: ``h_contact``, ``dofs``, ``case`` (:data:`CASES`),
``eps_N``, ``eps_T``, ``newton_press`` and ``newton_slide`` (iterations per step of the
pressing and the sliding steps), ``cutbacks``, ``Q`` and ``P`` (the tangential and normal
contact force at the last level), ``Q_over_muP``, ``c``, ``c_error`` (against ``c =
a sqrt(1 - Q / (mu P))``), ``shear_error``, ``Q_change``, ``c_change`` (relative to the
default's on the same mesh), ``wall_s``, ``ranks``.
"""

import argparse
import time

import resultfile
from eps_default import compared_to_default
from mpi4py import MPI

from contact_ufl.verification.runs import cattaneo_mindlin_run

MESHES = [0.02, 0.01, 0.005, 0.0025]
QUICK = MESHES[:3]
CASES = ("default", "10 eps_T", "eps_T / 10", "E / h")
"""The runs on each mesh: the default ``eps_N`` and ``eps_T``; ``eps_T`` ten times and a tenth
of the default (``eps_N`` the default); the scene's own ``eps_N = eps_T = E / h``."""
PRESSING_STEPS = 4


def run(h: float, case: str, eps_default: float | None) -> dict:
    """Solve one mesh with the eps of ``case`` (``eps_default``: the default ``eps_N`` on
    this mesh, unknown for ``"default"`` itself)."""
    factor = {"default": None, "10 eps_T": 10.0, "eps_T / 10": 0.1, "E / h": None}[case]
    pair = {} if case == "E / h" else {"eps_N": None}
    if factor is not None:
        pair["eps_T"] = factor * eps_default
    start = time.perf_counter()
    levels, problem = cattaneo_mindlin_run(h, pair=pair)
    wall = time.perf_counter() - start
    steps = problem.history.steps
    friction = problem.contacts[0].friction
    last = levels[-1]
    Q, P = (float(abs(f)) for f in steps[-1].contact_force[:2])
    return {
        "h_contact": h,
        "dofs": problem.layout.global_size,
        "case": case,
        "eps_N": float(problem.contacts[0].normal.eps_N.value),
        "eps_T": float(friction.eps_T.value),
        "newton_press": [s.newton_iterations for s in steps[:PRESSING_STEPS]],
        "newton_slide": [s.newton_iterations for s in steps[PRESSING_STEPS:]],
        "cutbacks": len(problem.history.cutbacks),
        "Q": Q,
        "P": P,
        "Q_over_muP": last["Q_over_muP"],
        "c": last["c"],
        "c_error": last["stick_zone_error"],
        "shear_error": last["shear_error"],
        "wall_s": wall,
        "ranks": problem.comm.size,
    }


def mesh_records(h: float) -> list[dict]:
    """The runs of :data:`CASES` on one mesh, with the changes against the default."""

    def solve(case: str, eps_default: float | None) -> dict:
        return run(h, case, eps_default)

    return compared_to_default(solve, CASES, ("Q", "c"))


HEADER = (
    f"{'h':>7} {'dofs':>7} {'case':>10} {'eps_T':>8} {'press its':>12} {'slide its':>12} "
    f"{'Q/muP':>6} {'c err':>7} {'shear':>6} {'dQ':>9} {'dc':>9} {'wall':>6}"
)


def row(r: dict) -> str:
    press = ",".join(str(n) for n in r["newton_press"])
    slide = ",".join(str(n) for n in r["newton_slide"])
    return (
        f"{r['h_contact']:7g} {r['dofs']:7d} {r['case']:>10} {r['eps_T']:8.3g} {press:>12} "
        f"{slide:>12} {r['Q_over_muP']:6.3f} {r['c_error']:+7.3f} {r['shear_error']:6.3f} "
        f"{r['Q_change']:9.1e} {r['c_change']:9.1e} {r['wall_s']:6.1f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="three meshes")
    parser.add_argument("--h", type=float, nargs="+", default=None, help="h_contact list")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    records = []
    if comm.rank == 0:
        print(HEADER, flush=True)
    for h in args.h or (QUICK if args.quick else MESHES):
        for r in mesh_records(h):
            records.append(r)
            if comm.rank == 0:
                print(row(r), flush=True)
        if comm.rank == 0:
            resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
