"""Load stepping with cut-back: the pseudo-time from the current state to its end.

Every step follows the step protocol of the problem: :meth:`begin_step
<contact_ufl.problem.ContactProblem.begin_step>`, the step's strategies
(:meth:`StepSolver.solve_step <contact_ufl.strategies.StepSolver.solve_step>`), then, once
converged, :meth:`commit <contact_ufl.problem.ContactProblem.commit>`. A step that all
strategies fail is restored and halved: the cut-back, the last resort.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple, Protocol

import numpy as np
from mpi4py import MPI

from contact_ufl.errors import ContactInputError, ConvergenceError
from contact_ufl.strategies import StepSolver


class SteppedProblem(Protocol):
    """What the load stepper asks of the problem it steps: pseudo-time, the step protocol
    of everything with history, and a step's results."""

    t: float
    unknowns: list
    verbose: bool
    comm: MPI.Comm

    def set_time(self, t: float) -> None: ...

    def begin_step(self) -> None: ...

    def commit(self, x) -> None: ...

    def active_points(self) -> int: ...

    def contact_force(self) -> np.ndarray: ...

    def fresh_start(self) -> None: ...


@dataclass
class StepRecord:
    """What happened in one accepted load step.

    Attributes
    ----------
    step
        Number of the accepted step (from 1, over all solves of the problem).
    t
        Pseudo-time reached.
    newton_iterations
        Newton iterations of the step (of all tries, see
        :meth:`~contact_ufl.strategies.StepSolver.solve_step`).
    residual
        Norm of the residual at convergence.
    active_points
        Slave quadrature points in contact (all pairs).
    contact_force
        Resultant contact force (all pairs).
    wall_s
        Wall time of the accepted try of the step (seconds).
    reason
        SNES's converged reason of the solve the step was accepted with (a
        ``CONVERGED_*`` name).
    """

    step: int
    t: float
    newton_iterations: int
    residual: float
    active_points: int
    contact_force: np.ndarray
    wall_s: float
    reason: str = ""


class Cutback(NamedTuple):
    """A failed load step, cut back.

    Attributes
    ----------
    t
        The pseudo-time the step tried to reach.
    reason
        SNES's converged reason of its last try (a ``DIVERGED_*`` name).
    why
        What went wrong at its last iterate (:meth:`StepSolver.diagnose
        <contact_ufl.strategies.StepSolver.diagnose>`): inverted elements and where, contact
        cycling, or a stalled residual (a limit point).
    """

    t: float
    reason: str
    why: str = ""


@dataclass
class Schedule:
    """The load steps of a solve: from ``t_start`` to ``t_end`` in ``num_steps`` steps of
    ``(t_end - t_start) / num_steps``; the size ``dt`` of the next step (smaller after a
    cut-back) and how many steps in a row converged since (``streak``: at 2 the step grows
    back)."""

    t_start: float
    t_end: float
    num_steps: int
    dt: float
    streak: int = 0

    @property
    def dt0(self) -> float:
        """The step of the plan, the largest."""
        return (self.t_end - self.t_start) / self.num_steps


@dataclass
class History:
    """Accepted steps and cut-backs of a run.

    Attributes
    ----------
    steps
        The accepted steps.
    cutbacks
        Every failed step (:class:`Cutback`: pseudo-time, SNES converged reason, why).
    """

    steps: list[StepRecord] = field(default_factory=list)
    cutbacks: list[Cutback] = field(default_factory=list)


class CheckpointWriter(Protocol):
    """What the load stepper asks of its checkpoints
    (:class:`~contact_ufl.checkpoint.Checkpoints`): whether a step is written, and the
    writing."""

    def due(self, step: int, last: bool) -> bool: ...

    def write(self, problem, history: History, schedule: Schedule) -> object: ...


class LoadStepper:
    """Load stepping with cut-back of a problem and its step solver.

    Usually made by :attr:`ContactProblem.stepper
    <contact_ufl.problem.ContactProblem.stepper>`.

    Parameters
    ----------
    problem
        The problem (pseudo-time, step protocol, results of a step).
    solver
        Its step solver.
    verbose
        Print one line per load step on rank 0 (``None``: as the problem's ``verbose``
        says at the time).

    Attributes
    ----------
    history
        Accepted steps and cut-backs of all solves so far.
    """

    def __init__(self, problem: SteppedProblem, solver: StepSolver, verbose: bool | None = None):
        self.problem = problem
        self.solver = solver
        self.verbose = verbose
        self.history = History()
        self.schedule: Schedule | None = None  # that of the solve under way (or the last)
        self._resumed: tuple[Schedule, float] | None = None
        self._fresh_start_due = False  # a checkpoint was written: a restart point

    def resume(self, schedule: Schedule, t: float) -> None:
        """Continue the solve that ``schedule`` belongs to, from pseudo-time ``t`` (a
        restart): the next :meth:`solve` to the same ``t_end`` in the same ``num_steps``
        takes its steps where that one would have; a solve that ended at or before ``t``
        is skipped (a script run again from the top passes it)."""
        self._resumed = (schedule, t)

    def _schedule(self, num_steps: int, t_end: float) -> Schedule | None:
        """The schedule of a solve: the resumed one where it is that solve's, ``None`` where
        a restart is past the solve's end."""
        t = self.problem.t
        if self._resumed is not None:
            resumed, t_restart = self._resumed
            if t_end <= t_restart + 1e-12 * max(1.0, abs(t_restart)):
                self._print(f"  solve to t = {t_end:.5g}: done before the restart (t = {t:.5g})")
                return None
            self._resumed = None
            if resumed.num_steps == num_steps and abs(resumed.t_end - t_end) <= 1e-12 * max(
                1.0, abs(t_end)
            ):
                return resumed
        return Schedule(t, t_end, num_steps, (t_end - t) / num_steps)

    def solve(
        self,
        num_steps: int = 10,
        t_end: float = 1.0,
        max_cutbacks: int = 8,
        callback: Callable[[SteppedProblem, StepRecord], None] | None = None,
        checkpoints: CheckpointWriter | None = None,
    ) -> History:
        """Load stepping from the current pseudo-time to ``t_end`` in ``num_steps`` steps.

        A step whose Newton solve fails is restored and halved; after two converged steps in
        a row the step grows back (at most to its initial size). A step smaller than the
        initial one halved ``max_cutbacks`` times raises :class:`ConvergenceError
        <contact_ufl.errors.ConvergenceError>`, which names the step. Accepted steps are in
        :attr:`history` (and were passed to ``callback(problem, record)``, e.g. a
        :class:`~contact_ufl.output.ResultWriter`) whatever happens later. With
        ``checkpoints`` (:class:`~contact_ufl.checkpoint.Checkpoints`) the state is written at
        the steps it says, and the next step starts afresh from it (as a restart would:
        :meth:`~contact_ufl.problem.ContactProblem.fresh_start`).

        Returns
        -------
        :attr:`history`
        """
        problem, solver = self.problem, self.solver
        if not (isinstance(num_steps, int | np.integer) and num_steps >= 1):
            raise ContactInputError(f"num_steps must be a whole number >= 1, got {num_steps!r}")
        plan = self._schedule(num_steps, t_end)
        if plan is None:
            return self.history
        if not t_end > problem.t + 1e-12 * max(1.0, abs(problem.t)):
            raise ContactInputError(
                f"t_end = {t_end!r} does not advance the pseudo-time beyond t = {problem.t:.6g}: "
                "a solve goes forward in t; to unload, give the loads and prescribed values as "
                "functions of t that go back (e.g. lambda t: d * min(t, 2 - t)) and solve to a "
                "later t_end (see the user guide, Supports, loads and pseudo-time)"
            )
        self.schedule = plan
        dt0 = plan.dt0
        while problem.t < t_end - 1e-12 * abs(t_end):
            dt = plan.dt
            t_prev, t_new = problem.t, min(problem.t + dt, t_end)
            saved = [f.x.array.copy() for f in problem.unknowns]
            start = time.perf_counter()
            try:
                problem.begin_step()
                if self._fresh_start_due:  # the first step after a checkpoint
                    problem.fresh_start()
                    self._fresh_start_due = False
                ok, its, reason = solver.solve_step(t_new)
            except BaseException:  # an error or Ctrl-C inside the step: back to t_prev
                self._restore(saved, t_prev)
                raise
            if not ok:
                why = solver.diagnose()
                self._restore(saved, t_prev)
                self.history.cutbacks.append(Cutback(t_new, reason, why))
                self._print(f"  step to t = {t_new:.5g} failed ({reason}; {why}): cutting back")
                plan.dt, plan.streak = 0.5 * dt, 0
                if plan.dt < dt0 * 0.5**max_cutbacks * (1.0 - 1e-9):
                    raise ConvergenceError(
                        f"load step {len(self.history.steps) + 1}, from t = {t_prev:.6g} to "
                        f"t = {t_new:.6g}, did not converge ({reason}: {why}) after "
                        f"{max_cutbacks} cut-backs; the state of t = {t_prev:.6g} is kept"
                    )
                continue
            record = self._accept(t_new, its, reason, start)
            plan.streak += 1
            if plan.streak >= 2 and plan.dt < dt0:
                plan.dt, plan.streak = min(2.0 * plan.dt, dt0), 0
            if callback is not None:
                callback(problem, record)
            finished = problem.t >= t_end - 1e-12 * abs(t_end)
            if checkpoints is not None and checkpoints.due(record.step, finished):
                checkpoints.write(problem, self.history, plan)
                self._fresh_start_due = True
        return self.history

    def equilibrate(self) -> StepRecord:
        """Newton at the current pseudo-time from the current state, a step of no load
        increment: equilibrium at the same load of a state made elsewhere (a solution moved
        onto refined meshes, :mod:`contact_ufl.adapt`). Recorded as a step at the same ``t``.

        Raises
        ------
        ConvergenceError
            Newton did not converge (the state before it is kept; at a fixed load there is
            no step to cut back).
        """
        problem, solver = self.problem, self.solver
        t = problem.t
        saved = [f.x.array.copy() for f in problem.unknowns]
        start = time.perf_counter()
        try:
            problem.begin_step()
            ok, its, reason = solver.solve_step(t)
        except BaseException:
            self._restore(saved, t)
            raise
        if not ok:
            why = solver.diagnose()
            self._restore(saved, t)
            self.history.cutbacks.append(Cutback(t, reason, why))
            raise ConvergenceError(
                f"the equilibrium at t = {t:.6g} from the given state did not converge "
                f"({reason}: {why}); the state is kept"
            )
        return self._accept(t, its, reason, start)

    def _accept(self, t: float, its: int, reason: int, start: float) -> StepRecord:
        """Record a converged step to ``t`` and commit it."""
        problem, solver = self.problem, self.solver
        record = StepRecord(
            len(self.history.steps) + 1,
            t,
            its,
            solver.residual_norm,
            problem.active_points(),
            problem.contact_force(),
            time.perf_counter() - start,
            reason,
        )
        self.history.steps.append(record)
        problem.commit(solver.x)
        solver.operator.forget_state()
        self._print(_format(record))
        return record

    def _restore(self, saved: list[np.ndarray], t: float) -> None:
        for f, a in zip(self.problem.unknowns, saved, strict=True):
            f.x.array[:] = a
        self.problem.set_time(t)
        self.solver.operator.forget_state()

    def _print(self, text: str) -> None:
        verbose = self.problem.verbose if self.verbose is None else self.verbose
        if verbose and self.problem.comm.rank == 0:
            print(text, flush=True)


def _format(r: StepRecord) -> str:
    force = " ".join(f"{f: .4e}" for f in r.contact_force)
    return (
        f"step {r.step:3d}  t = {r.t:.4f}  newton {r.newton_iterations:2d}  "
        f"|R| = {r.residual:.2e}  active {r.active_points:5d}  contact force [{force}]"
    )
