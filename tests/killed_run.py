"""A checkpointed run of the frictional 2D ironing scene that can kill itself (SIGKILL) at a
chosen point, and restart from its last complete checkpoint: the subprocess of
``tests/test_killed_runs.py``.

    python killed_run.py CHECKPOINTS OUTPUT RESULT.npz
        [--kill-newton STEP ITERATE | --kill-write STEP] [--restart]

It presses the punch in 10 steps and slides it in 4 (a checkpoint at every step, results
written by a :class:`~contact_ufl.output.ResultWriter` into OUTPUT), then rank 0 writes
RESULT.npz: the unknowns gathered in rank order, the punch-top reaction, the contact force
and the step records. ``--kill-newton S I`` kills the run at Newton iterate ``I`` (0: the
initial residual) of step ``S``; ``--kill-write S`` kills it while it writes the checkpoint
of step ``S``, once the files of the partial folder are on disk and before the rename.
"""

from __future__ import annotations

import argparse
import os
import signal
from pathlib import Path

import numpy as np
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.verification import scenes

#: the solves of the run: (num_steps, t_end), the press then the slide
SOLVES = ((10, 1.0), (4, 1.08))


def build(comm: MPI.Comm = MPI.COMM_WORLD):
    """The scene and its problem (a quick mesh of the frictional ironing)."""
    scene = scenes.ironing(mu=0.3, h_punch=0.05, h_block=0.2, comm=comm)
    problem = cu.ContactProblem(scene, verbose=False, petsc_options={"snes_max_it": 40})
    return scene, problem


def gathered(problem) -> np.ndarray | None:
    """The unknowns of every rank, concatenated in rank order on rank 0 (``None`` elsewhere)."""
    parts = problem.comm.gather(problem.solver.x.array.copy(), root=0)
    return None if parts is None else np.concatenate(parts)


def records(history) -> dict[str, np.ndarray]:
    """The step records as arrays (all but the wall time, which no two runs share)."""
    steps = history.steps
    return {
        "step_number": np.array([r.step for r in steps]),
        "step_t": np.array([r.t for r in steps]),
        "step_newton_iterations": np.array([r.newton_iterations for r in steps]),
        "step_residual": np.array([r.residual for r in steps]),
        "step_active_points": np.array([r.active_points for r in steps]),
        "step_contact_force": np.array([np.asarray(r.contact_force) for r in steps]),
        "step_reason": np.array([r.reason for r in steps]),
        "cutbacks": np.array(len(history.cutbacks)),
    }


def kill() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def kill_in_newton(problem, step: int, iterate: int) -> None:
    """SIGKILL (rank 0) at Newton iterate ``iterate`` of accepted step ``step``: wraps the
    monitor the step solver gave its Newton driver, which is still called."""
    newton = problem.solver.newton
    original, seen = newton.on_iterate, []

    def on_iterate(norm: float) -> None:
        if len(problem.history.steps) + 1 == step:
            seen.append(norm)
            if len(seen) == iterate + 1 and problem.comm.rank == 0:
                kill()
        if original is not None:
            original(norm)

    newton.on_iterate = on_iterate


def kill_in_write(step: int) -> None:
    """SIGKILL while the checkpoint of ``step`` is written: the original
    ``Checkpoints._write_files`` runs, and the rename of its partial folder kills instead."""
    original = cu.Checkpoints._write_files

    def write_files(self, final: Path, arrays: dict, meta: dict) -> None:
        if final.name != f"step_{step:06d}":
            return original(self, final, arrays, meta)
        partial = final.with_name(final.name + ".partial")
        rename = Path.rename

        def killing_rename(path: Path, target):
            if path == partial:
                kill()
            return rename(path, target)

        Path.rename = killing_rename
        try:
            return original(self, final, arrays, meta)
        finally:
            Path.rename = rename

    cu.Checkpoints._write_files = write_files


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("checkpoints", type=Path)
    parser.add_argument("output", type=Path)
    parser.add_argument("result", type=Path)
    kills = parser.add_mutually_exclusive_group()
    kills.add_argument("--kill-newton", nargs=2, type=int, metavar=("STEP", "ITERATE"))
    kills.add_argument("--kill-write", type=int, metavar="STEP")
    parser.add_argument("--restart", action="store_true")
    args = parser.parse_args(argv)

    scene, problem = build()
    if args.restart:
        problem.restart(args.checkpoints)
    if args.kill_newton is not None:
        kill_in_newton(problem, *args.kill_newton)
    if args.kill_write is not None:
        kill_in_write(args.kill_write)
    writer = cu.ResultWriter(problem, args.output)
    checkpoints = cu.Checkpoints(args.checkpoints, every=1, keep=None)
    for num_steps, t_end in SOLVES:
        problem.solve(num_steps=num_steps, t_end=t_end, checkpoint=checkpoints, callback=writer)
    writer.close()
    x = gathered(problem)
    reaction = problem.reaction(scene.tags["punch_top"])
    force = problem.contact_force()
    if problem.comm.rank == 0:
        np.savez(
            args.result,
            x=x,
            reaction=reaction,
            contact_force=force,
            t=problem.t,
            **records(problem.history),
        )


if __name__ == "__main__":
    main()
