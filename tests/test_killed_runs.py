"""Runs killed (SIGKILL) in a Newton iterate or in the write of a checkpoint, or interrupted
(SIGINT) in a solve, then restarted from their last complete checkpoint, end where the same
run never killed ends (consistency checks).

The runs are those of ``tests/killed_run.py`` (frictional 2D ironing, press in 10 steps and
slide in 4, a checkpoint at every step), each in its own process: on one rank ``python``,
on two the ``mpiexec`` beside it. The tests launch their processes themselves, so they run
from a one-rank pytest (``serial``).
"""

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from killed_run import SOLVES, build, gathered, records

import contact_ufl as cu

pytestmark = pytest.mark.serial

SCRIPT = Path(__file__).with_name("killed_run.py")
MPIEXEC = Path(sys.executable).parent / "mpiexec"
#: seconds a run may take before it is taken for hung (about 3 s on one rank, 12 s on two)
TIMEOUT = 600
CASE = "Ironing 2D, mu = 0.3, h_punch = 0.05, h_block = 0.2, a checkpoint at every step"
SOURCE = "the same run never killed"
#: On two ranks MUMPS does not repeat itself bit for bit (relative differences of ~1e-16 in
#: a solve), and 14 nonlinear steps carry them on: between runs never killed, as between a
#: killed and restarted run and one never killed, the unknowns (and lambda_N of the last
#: contact surface) differed by up to 1.1e-13 of their largest entry and the forces
#: (reaction, contact force, step residuals) by up to 4.6e-15 of the largest contact force
#: (21 pairs of runs).
TOL_X_2, TOL_F_2 = 3e-13, 1e-14
#: the step records that two runs share exactly (the step residual and contact force are
#: compared as forces)
EXACT_RECORDS = ("step_number", "step_t", "step_newton_iterations", "step_active_points")


def run(folder: Path, ranks: int, *options: str) -> subprocess.CompletedProcess:
    """Run ``killed_run.py`` on ``ranks`` ranks with its files in ``folder``."""
    command = [
        sys.executable,
        str(SCRIPT),
        str(folder / "checkpoints"),
        str(folder / "output"),
        str(folder / "result.npz"),
        *options,
    ]
    if ranks > 1:
        command = [str(MPIEXEC), "-n", str(ranks), *command]
    return subprocess.run(
        command, env=dict(os.environ), capture_output=True, text=True, timeout=TIMEOUT
    )


def finished(folder: Path, ranks: int, *options: str) -> dict[str, np.ndarray]:
    """Run ``killed_run.py`` to its end; its results."""
    done = run(folder, ranks, *options)
    assert done.returncode == 0, done.stderr[-3000:]
    with np.load(folder / "result.npz") as data:
        return dict(data)


def killed(folder: Path, ranks: int, *options: str) -> None:
    """Run ``killed_run.py`` with a kill option: it must die of its SIGKILL."""
    done = run(folder, ranks, *options)
    if ranks == 1:
        assert done.returncode == -signal.SIGKILL, done.stderr[-3000:]
    else:  # mpiexec ends the job when a rank dies, with a nonzero status of its own
        assert done.returncode != 0
    assert not (folder / "result.npz").exists()


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """``reference(ranks)``: the results and output folder of the run never killed, on
    ``ranks`` ranks (run once per module)."""
    done = {}

    def result(ranks: int) -> tuple[dict[str, np.ndarray], Path]:
        if ranks not in done:
            folder = tmp_path_factory.mktemp(f"never_killed_{ranks}")
            done[ranks] = finished(folder, ranks), folder
        return done[ranks]

    return result


def partial_folders(folder: Path) -> list[Path]:
    return sorted(folder.glob("step_*.partial"))


def series(folder: Path) -> list[tuple[float, str]]:
    """The (pseudo-time, file) entries of the contact surface's ``.pvd`` series."""
    text = (folder / "output" / "contact_surface_0.pvd").read_text()
    return [(float(t), f) for t, f in re.findall(r'timestep="([^"]*)"[^>]*file="([^"]*)"', text)]


def last_surface(folder: Path) -> np.ndarray:
    """``lambda_N`` of the last surface of the ``.pvd`` series, read by pyvista."""
    import pyvista

    reader = pyvista.get_reader(str(folder / "output" / "contact_surface_0.pvd"))
    reader.set_active_time_value(reader.time_values[-1])
    return np.asarray(reader.read()[0].point_data["lambda_N"])


def relative(ours: np.ndarray, theirs: np.ndarray, scale: float | None = None) -> float:
    """The largest difference, relative to ``scale`` (default: the largest entry of
    ``theirs``)."""
    scale = np.abs(theirs).max() if scale is None else scale
    return float(np.abs(np.asarray(ours) - np.asarray(theirs)).max() / scale)


def compare_final(verification, ours, theirs, ranks: int, when: str) -> None:
    """Record and assert that the final state and forces of ``ours`` are those of the run
    never killed ``theirs``: bit for bit on one rank, to run-to-run noise on two."""
    assert ours["t"] == theirs["t"] and ours["cutbacks"] == theirs["cutbacks"] == 0
    force = np.abs(theirs["step_contact_force"]).max()
    compared = [
        ("unknowns", ours["x"], theirs["x"], None, TOL_X_2),
        ("punch-top reaction", ours["reaction"], theirs["reaction"], force, TOL_F_2),
        ("contact force", ours["contact_force"], theirs["contact_force"], force, TOL_F_2),
    ]
    for name, a, b, scale, tol in compared:
        error = relative(a, b, scale)
        tol = 0.0 if ranks == 1 else tol
        unit = "of the largest entry" if scale is None else "of the largest contact force"
        quantity = f"{name} after {when}, restarted, {ranks} rank(s): largest difference {unit}"
        verification(CASE, quantity, error, 0.0, tol, SOURCE, kind="consistency")
        assert error <= tol, (name, error)
    if ranks == 1:
        assert ours["x"].tobytes() == theirs["x"].tobytes()  # the same SHA-256


def compare_records(verification, ours, theirs, steps: slice, ranks: int, what: str) -> None:
    """Record and assert that the step records ``steps`` of ``ours`` are those of ``theirs``:
    the counts and times exactly, residuals and contact forces bit for bit on one rank and
    to the run-to-run noise on two."""
    for key in EXACT_RECORDS + ("step_reason",):
        assert np.array_equal(ours[key][steps], theirs[key][steps]), key
    force = np.abs(theirs["step_contact_force"]).max()
    tol = 0.0 if ranks == 1 else TOL_F_2
    for key in ("step_residual", "step_contact_force"):
        error = relative(ours[key][steps], theirs[key][steps], force)
        quantity = (
            f"{key.removeprefix('step_').replace('_', ' ')} of {what}, {ranks} rank(s): "
            "largest difference of the largest contact force"
        )
        verification(CASE, quantity, error, 0.0, tol, SOURCE, kind="consistency")
        assert error <= tol, (key, error)


# on two ranks (mpiexec ends the job when one rank dies): the slow tier, 20 s
@pytest.mark.parametrize("ranks", [1, pytest.param(2, marks=pytest.mark.slow)])
def test_killed_in_a_newton_iterate_restarts_to_the_same_end(
    ranks, reference, tmp_path, verification
):
    """SIGKILL at Newton iterate 2 of step 6 leaves the checkpoints of steps 1 to 5, all
    complete; the run restarted from step 5 records steps 1 to 5 as the run never killed did,
    takes the same Newton iterations from step 6 on, ends in the same state, and its
    contact-surface series lists the 14 steps of the run never killed."""
    ref, ref_folder = reference(ranks)
    killed(tmp_path, ranks, "--kill-newton", "6", "2")
    checkpoints = cu.Checkpoints(tmp_path / "checkpoints")
    assert checkpoints.steps() == [1, 2, 3, 4, 5]
    assert not partial_folders(checkpoints.folder)
    assert len(series(tmp_path)) == 5  # the steps accepted before the kill

    ours = finished(tmp_path, ranks, "--restart")
    assert np.array_equal(ours["step_newton_iterations"], ref["step_newton_iterations"])
    compare_records(verification, ours, ref, slice(0, 5), ranks, "steps 1 to 5")
    compare_final(verification, ours, ref, ranks, "a kill in step 6")
    assert checkpoints.steps() == list(range(1, 15)) and not partial_folders(checkpoints.folder)

    entries = series(tmp_path)
    assert entries == series(ref_folder)  # the 14 steps, in order, each its own file
    assert [t for t, _ in entries] == list(ref["step_t"])
    assert [f for _, f in entries] == [f"contact_surface_0/step_{k:05d}.vtu" for k in range(14)]
    lambda_N, ref_lambda_N = last_surface(tmp_path), last_surface(ref_folder)
    error = relative(lambda_N, ref_lambda_N)
    tol = 0.0 if ranks == 1 else TOL_X_2
    quantity = (
        f"lambda_N of the last surface of the .pvd series after a kill in step 6, {ranks} "
        "rank(s): largest difference of its largest value"
    )
    verification(CASE, quantity, error, 0.0, tol, SOURCE, kind="consistency")
    assert error <= tol


def test_killed_in_a_checkpoint_write_restarts_from_the_one_before(
    reference, tmp_path, verification
):
    """SIGKILL in the write of the checkpoint of step 7, its files written and the partial
    folder not yet renamed, leaves ``step_000007.partial`` and the complete checkpoints of
    steps 1 to 6; the restart goes on from step 6 and ends in the state of the run never
    killed, bit for bit."""
    ref, ref_folder = reference(1)
    killed(tmp_path, 1, "--kill-write", "7")
    checkpoints = cu.Checkpoints(tmp_path / "checkpoints")
    partial = checkpoints.folder / "step_000007.partial"
    assert partial_folders(checkpoints.folder) == [partial]
    assert (partial / "meta.json").is_file() and (partial / "state.npz").is_file()
    assert checkpoints.steps() == [1, 2, 3, 4, 5, 6]

    ours = finished(tmp_path, 1, "--restart")
    compare_records(verification, ours, ref, slice(0, 14), 1, "steps 1 to 14")
    compare_final(verification, ours, ref, 1, "a kill in the write of step 7")
    assert checkpoints.steps() == list(range(1, 15)) and not partial_folders(checkpoints.folder)
    assert series(tmp_path) == series(ref_folder)


def test_ctrl_c_in_a_checkpointed_solve_restarts_to_the_same_end(
    reference, tmp_path, monkeypatch, verification
):
    """SIGINT (Ctrl-C) in the Newton solve of step 6 raises ``KeyboardInterrupt`` from the
    solve; the last checkpoint is that of step 5, the last accepted, complete; a problem made
    anew and restarted from it ends in the state of the run never interrupted, bit for bit."""
    ref, _ = reference(1)
    folder = tmp_path / "checkpoints"
    checkpoints = cu.Checkpoints(folder, every=1, keep=None)
    _, problem = build()
    operator, calls = problem.operator, []
    update = operator.update_pairing

    def interrupted(x):
        last = problem.history.steps[-1].t if problem.history.steps else 0.0
        if len(problem.history.steps) == 5 and problem.t > last:  # step 6 under way
            calls.append(1)
            if len(calls) == 3:
                os.kill(os.getpid(), signal.SIGINT)
        update(x)

    monkeypatch.setattr(operator, "update_pairing", interrupted)
    with pytest.raises(KeyboardInterrupt):
        for num_steps, t_end in SOLVES:
            problem.solve(num_steps=num_steps, t_end=t_end, checkpoint=checkpoints)
    assert len(calls) == 3
    assert len(problem.history.steps) == 5 and problem.t == ref["step_t"][4]
    assert checkpoints.steps() == [1, 2, 3, 4, 5] and not partial_folders(folder)
    last = checkpoints.path(5)
    assert (last / "meta.json").is_file() and (last / "state.npz").is_file()
    problem.close()

    scene, restarted = build()
    assert restarted.restart(folder) == ref["step_t"][4]
    for num_steps, t_end in SOLVES:
        restarted.solve(num_steps=num_steps, t_end=t_end, checkpoint=checkpoints)
    ours = {
        "x": gathered(restarted),
        "reaction": restarted.reaction(scene.tags["punch_top"]),
        "contact_force": restarted.contact_force(),
        "t": restarted.t,
        **records(restarted.history),
    }
    compare_records(verification, ours, ref, slice(0, 14), 1, "steps 1 to 14 after a Ctrl-C")
    compare_final(verification, ours, ref, 1, "a Ctrl-C in step 6")
