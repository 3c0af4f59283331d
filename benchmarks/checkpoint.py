"""The cost of checkpoints: a load-stepped solve with a checkpoint at every step against the
same solve without.

A checkpoint (:class:`contact_ufl.Checkpoints`, ``every=1, keep=2``) is written at every
accepted step, and the step after it starts afresh
(:meth:`ContactProblem.fresh_start <contact_ufl.problem.ContactProblem.fresh_start>`: the
pairing, sparsity plan, matrix and factorisation made anew, as a restart makes them), so
the cost is the writing, the fresh start and what the next Newton iteration pays for it (a
new symbolic analysis). Scenes, mu = 0.3 (with friction, so the slip history is part of the state):

* ``ironing_2d``: the 2D shallow ironing of ``benchmarks/ironing.py`` (its default mesh,
  h = 0.025 / 0.1, pressed in 20 steps and slid 10 in 200: 220 steps); ``--quick``: its
  quick mesh (0.05 / 0.2), pressed in 20 steps and slid 2 in 20 (the step of its quick
  run);
* ``ironing_3d``: the 3D ironing of ``benchmarks/ironing_3d.py`` on its quick mesh (h = 0.6
  / 0.75, pressed in 10 steps and slid 4 in 20: 30 steps, about 100 s a solve on one core;
  its default mesh is finer and has not been run); ``--quick``: pressed in 10 steps and
  slid 0.8 in 4.

Each case is solved without checkpoints (A) and with (B) in turn, A B A B, ``--pairs``
times (default 3, 2 without ``--quick``), each solve on a problem made anew, after an
untimed solve of two steps that loads the compiled forms. Recorded per case:

* per solve: its wall time (the largest of the ranks; making the problem is not counted)
  and CPU time (of the process, the largest of the ranks: less disturbed by other work on
  the machine, but blind to waiting for the disk), its steps, cut-backs and Newton
  iterations, the load average at its start and the contact force at its end;
* the ratio with / without of each pair's wall times, their median, smallest and largest,
  and the median of the CPU times' ratios;
* the time per call spent in :meth:`Checkpoints.write
  <contact_ufl.checkpoint.Checkpoints.write>` and in ``fresh_start`` (wrapped, the largest
  of the ranks; the first write also writes the meshes, once: its time is recorded apart);
* the size of the last checkpoint (``state.npz`` and ``meta.json``; the step records in
  ``meta.json`` grow with the steps) per unknown of the solver
  (``problem.solver.x.getSize()``), and that of the meshes' files;
* the largest difference of the solves' contact forces relative to their size (whether the
  checkpoints change the result).

Target: a checkpoint at every step costs less than 5% of the wall time (ratio < 1.05).

The checkpoints go to a temporary folder in ``--folder`` (default: the system's temporary
folder; its file system is recorded), removed after each solve.

    python benchmarks/checkpoint.py --json benchmarks/results/checkpoint.json
    python benchmarks/checkpoint.py --quick --json benchmarks/results/checkpoint_quick.json
"""

import argparse
import os
import shutil
import statistics
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import resultfile
from ironing_3d import QUICK as IRONING_3D_MESH
from mpi4py import MPI

from contact_ufl.checkpoint import META, STATE, Checkpoints
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Scene
from contact_ufl.verification import scenes

#: the friction coefficient of both scenes
MU = 0.3
#: the target: checkpoints at every step cost less than this share of the wall time
TARGET = 0.05


@dataclass(frozen=True)
class Case:
    """A scene and its load stages (``(num_steps, t_end)`` each, solved in turn)."""

    label: str
    mesh: str
    scene: Callable[[], Scene]
    stages: tuple[tuple[int, float], ...]


CASES = {
    "ironing_2d": Case(
        "2D ironing, mu = 0.3",
        "0.025 / 0.1",
        lambda: scenes.ironing(mu=MU, h_punch=0.025, h_block=0.1),
        ((20, 1.0), (200, 2.0)),
    ),
    "ironing_3d": Case(
        "3D ironing, mu = 0.3",
        f"{IRONING_3D_MESH['h_die']:g} / {IRONING_3D_MESH['h_slab']:g}",
        lambda: scenes.ironing_3d(
            mu=MU, h_die=IRONING_3D_MESH["h_die"], h_slab=IRONING_3D_MESH["h_slab"]
        ),
        ((IRONING_3D_MESH["press_steps"], 1.0), (IRONING_3D_MESH["slide_steps"], 2.0)),
    ),
}
QUICK_CASES = {
    "ironing_2d": Case(
        "2D ironing, mu = 0.3",
        "0.05 / 0.2",
        lambda: scenes.ironing(mu=MU, h_punch=0.05, h_block=0.2),
        ((20, 1.0), (20, 1.2)),
    ),
    "ironing_3d": Case(
        "3D ironing, mu = 0.3",
        CASES["ironing_3d"].mesh,
        CASES["ironing_3d"].scene,
        ((IRONING_3D_MESH["press_steps"], 1.0), (4, 1.2)),
    ),
}


class TimedCheckpoints(Checkpoints):
    """:class:`Checkpoints` at every step, keeping two, that record the time of each write
    (this rank's)."""

    def __init__(self, folder: Path):
        super().__init__(folder, every=1, keep=2)
        self.seconds: list[float] = []

    def write(self, problem, history, schedule) -> Path:
        start = time.perf_counter()
        path = super().write(problem, history, schedule)
        self.seconds.append(time.perf_counter() - start)
        return path


def time_fresh_start(problem: ContactProblem) -> list:
    """Wrap ``problem.fresh_start`` (the stepper calls it after each checkpoint) so that it
    adds up its time; returns the ``[seconds, calls]`` it adds to."""
    spent = [0.0, 0]
    fresh_start = problem.fresh_start

    def timed() -> None:
        start = time.perf_counter()
        fresh_start()
        spent[0] += time.perf_counter() - start
        spent[1] += 1

    problem.fresh_start = timed
    return spent


def file_system(path: Path) -> str:
    """The type of the file system that holds ``path`` (from ``/proc/mounts``)."""
    path = path.resolve()
    best, kind = "", "unrecorded"
    try:
        with open("/proc/mounts") as f:
            for line in f:
                fields = line.split()
                if (
                    len(fields) >= 3
                    and path.is_relative_to(fields[1])
                    and len(fields[1]) > len(best)
                ):
                    best, kind = fields[1], fields[2]
    except OSError:
        pass
    return kind


def solve(case: Case, folder: Path | None, comm: MPI.Comm, steps: int | None = None) -> dict:
    """Solve ``case`` on a problem made anew, with checkpoints in ``folder`` or without
    (``None``); ``steps``: only that many steps of the first stage's size (the warm-up).
    Returns the record of the solve."""
    problem = ContactProblem(case.scene(), verbose=False, petsc_options={"snes_max_it": 40})
    checkpoints = None if folder is None else TimedCheckpoints(folder)
    fresh = time_fresh_start(problem)
    stages = case.stages
    if steps is not None:
        n, t_end = stages[0]
        stages = ((steps, t_end * steps / n),)
    load = os.getloadavg()[0]
    comm.Barrier()
    start, cpu = time.perf_counter(), time.process_time()
    for n, t_end in stages:
        problem.solve(num_steps=n, t_end=t_end, checkpoint=checkpoints)
    wall = comm.allreduce(time.perf_counter() - start, MPI.MAX)
    cpu = comm.allreduce(time.process_time() - cpu, MPI.MAX)
    history = problem.history
    record = {
        "checkpoints": folder is not None,
        "wall_s": wall,
        "cpu_s": cpu,
        "load": load,
        "steps": len(history.steps),
        "cutbacks": len(history.cutbacks),
        "newton_iterations": sum(s.newton_iterations for s in history.steps),
        "unknowns": problem.solver.x.getSize(),
        "contact_force": [float(f) for f in problem.contact_force()],
    }
    if checkpoints is not None:
        writes = np.array(checkpoints.seconds)
        comm.Allreduce(MPI.IN_PLACE, writes, MPI.MAX)
        record["writes"] = len(writes)
        record["write_s"] = float(writes.sum())
        record["first_write_s"] = float(writes[0])  # with the meshes
        record["fresh_starts"] = fresh[1]
        record["fresh_start_s"] = comm.allreduce(fresh[0], MPI.MAX)
        if comm.rank == 0:
            last = checkpoints.path(checkpoints.steps()[-1])
            record["state_bytes"] = (last / STATE).stat().st_size
            record["meta_bytes"] = (last / META).stat().st_size
            meshes = [p for p in (folder / "meshes").rglob("*") if p.is_file()]
            record["meshes_bytes"] = sum(p.stat().st_size for p in meshes)
            shutil.rmtree(folder)
        comm.Barrier()
    problem.close()
    return record


def run_case(name: str, case: Case, pairs: int, root: Path, comm: MPI.Comm) -> dict:
    """The A B A B solves of ``case`` (``pairs`` of each) and the record of the case."""
    solve(case, root / f"{name}_warm_up", comm, steps=2)
    without, with_ = [], []
    for k in range(pairs):
        without.append(solve(case, None, comm))
        with_.append(solve(case, root / f"{name}_{k}", comm))
        if comm.rank == 0:
            print(
                f"{name} pair {k + 1}: without {without[-1]['wall_s']:.2f} s, with "
                f"{with_[-1]['wall_s']:.2f} s (load {without[-1]['load']:.1f}, "
                f"{with_[-1]['load']:.1f})",
                flush=True,
            )
    ratios = [b["wall_s"] / a["wall_s"] for a, b in zip(without, with_, strict=True)]
    cpu_ratios = [b["cpu_s"] / a["cpu_s"] for a, b in zip(without, with_, strict=True)]
    unknowns = without[0]["unknowns"]
    forces = [np.asarray(r["contact_force"]) for r in without + with_]
    scale = max(float(np.linalg.norm(f)) for f in forces)
    record = {
        "case": name,
        "label": case.label,
        "mesh": case.mesh,
        "mu": MU,
        "stages": [list(s) for s in case.stages],
        "unknowns": unknowns,
        "steps": without[0]["steps"],
        "pairs": pairs,
        "without": without,
        "with": with_,
        "ratios": ratios,
        "ratio_median": statistics.median(ratios),
        "ratio_min": min(ratios),
        "ratio_max": max(ratios),
        "cpu_ratios": cpu_ratios,
        "cpu_ratio_median": statistics.median(cpu_ratios),
        "wall_without_s": statistics.median(r["wall_s"] for r in without),
        "wall_with_s": statistics.median(r["wall_s"] for r in with_),
        "write_ms_per_step": statistics.median(1e3 * r["write_s"] / r["writes"] for r in with_),
        "fresh_start_ms_per_step": statistics.median(
            1e3 * r["fresh_start_s"] / r["fresh_starts"] for r in with_
        ),
        "force_difference": max(float(np.linalg.norm(f - forces[0])) for f in forces) / scale,
        "target": TARGET,
    }
    for part in ("write", "fresh_start"):  # the part's seconds over the wall time without
        seconds = statistics.median(r[f"{part}_s"] for r in with_)
        record[f"{part}_share"] = seconds / record["wall_without_s"]
    if comm.rank == 0:
        last = with_[-1]
        record["state_bytes"] = last["state_bytes"]
        record["meta_bytes"] = last["meta_bytes"]
        record["meshes_bytes"] = last["meshes_bytes"]
        record["bytes_per_unknown"] = (last["state_bytes"] + last["meta_bytes"]) / unknowns
        record["target_met"] = record["ratio_median"] < 1.0 + TARGET
    return record


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="coarse meshes, fewer steps")
    parser.add_argument("--cases", nargs="+", choices=sorted(CASES), default=list(CASES))
    parser.add_argument("--pairs", type=int, help="A B pairs (default 3; 2 without --quick)")
    parser.add_argument("--folder", type=Path, help="where the checkpoints are written")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    cases = QUICK_CASES if args.quick else CASES
    pairs = args.pairs or (3 if args.quick else 2)
    root = tempfile.mkdtemp(prefix="checkpoints_", dir=args.folder) if comm.rank == 0 else None
    root = Path(comm.bcast(root, root=0))
    kind = file_system(root)
    records = []
    try:
        for name in args.cases:
            record = run_case(name, cases[name], pairs, root, comm)
            records.append(record)
            if comm.rank == 0:
                print(
                    f"{record['label']}, {record['mesh']}: {record['unknowns']} unknowns, "
                    f"{record['steps']} steps; wall without {record['wall_without_s']:.2f} s, "
                    f"with {record['wall_with_s']:.2f} s, ratio {record['ratio_median']:.3f} "
                    f"({record['ratio_min']:.3f}-{record['ratio_max']:.3f}, CPU "
                    f"{record['cpu_ratio_median']:.3f}); "
                    f"{record['bytes_per_unknown']:.0f} bytes per unknown; write "
                    f"{record['write_ms_per_step']:.1f} ms, fresh start "
                    f"{record['fresh_start_ms_per_step']:.1f} ms per step; force difference "
                    f"{record['force_difference']:.1e}; target (< {TARGET:.0%}) "
                    f"{'met' if record['target_met'] else 'not met'}",
                    flush=True,
                )
    finally:
        if comm.rank == 0:
            shutil.rmtree(root, ignore_errors=True)
    if comm.rank == 0:
        results = {"quick": args.quick, "file_system": kind, "records": records}
        resultfile.write(args.json, results)


if __name__ == "__main__":
    main()
