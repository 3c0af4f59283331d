"""How a load step is tried: strategies in order, as a contact code composes its criteria.

A :class:`StepSolver` solves one load step by trying its :attr:`~StepSolver.strategies` in
order until one converges: the first is the *first try* (:class:`FirstTry`), the others are
retries from the step's start (:class:`PredictedStateRetry`, :class:`LineSearchRetry`,
:class:`ClosingRetry`); the load stepper (:mod:`contact_ufl.stepping`) cuts back a step that
all of them fail. A strategy moves a contact law only through that law's own methods
(:meth:`NormalLaw.count_in_contact_within
<contact_ufl.contact.normal.NormalLaw.count_in_contact_within>`). Each returns SNES's
converged reason, or ``None`` where it does not apply; a new strategy is a class here with
an ``attempt(step, solver)`` method. Why each exists, and what it saves, is in
:doc:`/guide/robustness`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl.diagnosis import StepDiagnosis
from contact_ufl.newton import NewtonDriver
from contact_ufl.operator import ContactOperator
from contact_ufl.timings import NewtonTimings

#: The growth of the residual norm above which a first contact's predictor iterate is
#: undone (:class:`FirstTry`): it changes the contact state at once, so the norm may grow a
#: little on an iterate that saves later ones, but a predictor that pulls large overlaps
#: shut in one linear step can throw the state far off (the beams' first contact without
#: friction), and Newton then inverts cells.
PREDICTOR_GROWTH = 10.0


class SolvedProblem(Protocol):
    """What a step solver asks of the problem it solves a step of."""

    t: float
    contacts: list
    free_pieces: list

    def set_time(self, t: float) -> None: ...

    def net_free_load(self, residual: np.ndarray, piece) -> float: ...


@dataclass
class Step:
    """A load step being tried.

    Attributes
    ----------
    t_from, t_to
        The pseudo-time at its start and the one it tries to reach.
    start
        The unknowns at its start (the last converged state).
    loose
        The contact pairs to close before any Newton step (:meth:`StepSolver.loose_pairs`;
        found by the first try).
    iterations
        Newton iterations of all tries so far.
    """

    t_from: float
    t_to: float
    start: PETSc.Vec
    loose: list
    iterations: int = 0


class Predictor:
    """The *predicted* state of a step: its start plus the last converged step's increment
    scaled to the step (a steady process repeats its last step)."""

    def __init__(self):
        self._last = None  # (t_from, t_to, x_to, x_to - x_from) of the last converged step

    def record(self, t_from: float, t_to: float, start: PETSc.Vec, x: PETSc.Vec) -> None:
        """A step from ``t_from`` (unknowns ``start``) converged at ``t_to`` (``x``)."""
        increment = x.copy()
        increment.axpy(-1.0, start)
        self._last = (t_from, t_to, x.copy(), increment)

    @property
    def last(self) -> tuple[float, float, PETSc.Vec] | None:
        """The last converged step: its start and end time and its increment (``None``
        before any)."""
        return None if self._last is None else (self._last[0], self._last[1], self._last[3])

    def resume(self, t_from: float, t_to: float, x: PETSc.Vec, increment: PETSc.Vec) -> None:
        """Take the last converged step from a checkpoint: from ``t_from`` to ``t_to``, ending
        at ``x``, by ``increment`` (copied)."""
        self.close()
        self._last = (t_from, t_to, x.copy(), increment.copy())

    def predict(self, x: PETSc.Vec, t0: float, t: float) -> bool:
        """Move ``x``, the start of the step from ``t0`` to ``t``, to ``x + (t - t0) /
        (t_to - t_from) dx``, where the last converged step ended at this start
        (collective). Whether it did."""
        if self._last is None:
            return False
        t_from, t_to, x_to, dx = self._last
        if t_to == t_from or abs(t_to - t0) > 1e-12 * max(abs(t0), 1.0):
            return False  # a solve at its start's time predicts nothing
        diff = x.copy()
        diff.axpy(-1.0, x_to)
        if diff.norm() > 0.0:
            return False
        x.axpy((t - t0) / (t_to - t_from), dx)
        return True

    def close(self) -> None:
        if self._last is not None:
            for v in self._last[2:]:
                v.destroy()
        self._last = None


class FirstTry:
    """Full-step Newton from the step's start, where the start allows it.

    Where the start shows a *loose* body (:meth:`StepSolver.loose_pairs`: no point in
    contact on a piece with a free rigid mode along which it is loaded, so that the Newton
    equation has no solution) and ``close_loose``, the try begins with a closing iterate
    on its pairs (:meth:`StepSolver.closing_iterate`). Where a pair has no point in contact
    at the start (a *first contact*), after the first (free) iterate, one *predictor* iterate
    in which its points count as in contact only where they overlap the master by more than
    a level (``first_contact_level``: ``"mean"``, see :meth:`first_contact_overlap`; a
    fraction of the deepest overlap; ``None``: no such iterate), undone if it leaves the
    residual over :data:`PREDICTOR_GROWTH` times the free iterate's; then Newton.

    Parameters
    ----------
    predict
        Start from the predicted state (:class:`Predictor`; fewer iterations in a long
        steady sliding, the same forces).
    first_contact_level
        See above.
    close_loose
        Close the pairs of a loose body first.
    """

    def __init__(
        self,
        predict: bool = False,
        first_contact_level: str | float | None = "mean",
        close_loose: bool = True,
    ):
        level = first_contact_level
        if not (level in (None, "mean") or (isinstance(level, (int, float)) and 0 < level < 1)):
            raise ValueError(
                f"first_contact_level must be 'mean', a fraction in (0, 1) or None, got {level!r}"
            )
        self.predict, self.first_contact_level, self.close_loose = predict, level, close_loose

    def attempt(self, step: Step, solver: StepSolver) -> int:
        if self.predict:
            solver.predictor.predict(solver.x, step.t_from, step.t_to)
        step.loose = solver.loose_pairs() if self.close_loose else []
        opening = []
        if self.first_contact_level and not step.loose and solver.newton.tolerances[3] > 2:
            opening = solver.open_pairs()
        if step.loose:  # no Newton step without contact: close first
            solver.closing_iterate(step.loose)
            reason, its = solver.newton_solve()
            its += 1
        elif opening:
            reason, its = self._first_contact(opening, solver)
        else:
            reason, its = solver.newton_solve()
        step.iterations += its
        return reason

    def _first_contact(self, pairs: list, solver: StepSolver) -> tuple[int, int]:
        """Newton with the predictor iterate after the free one: converged reason and
        iterations (all counted; at most the SNES's ``max_it`` in all, which is over 2)."""
        newton = solver.newton
        rtol, atol, _, max_it = newton.tolerances
        try:
            with newton.limited(max_it=1):
                reason, its = solver.newton_solve(partial=True)
                if reason > 0:
                    return reason, its
                # the relative tolerance of the later solves refers to the step's start
                later_atol = max(atol, rtol * newton.norms[0])
                with newton.limited(atol=later_atol):
                    solver.operator.set_state(solver.x)  # the free iterate's search
                    shifted = []
                    for c in pairs:
                        level = self.first_contact_overlap(c, solver.comm)
                        if level > 0.0:
                            c.normal.count_in_contact_within(-level)
                            shifted.append(c)
                    if shifted:
                        self._predictor_iterate(shifted, solver)
                        its += 1
            # the try's budget: max_it in all
            with newton.limited(atol=later_atol, max_it=max_it - its):
                reason, more = solver.newton_solve()
            its += more
        finally:
            for c in pairs:
                c.normal.restore_contact_threshold()
            solver.operator.forget_state()
        return reason, its

    def first_contact_overlap(self, pair, comm: MPI.Comm) -> float:
        """The overlap above which the points of ``pair`` count as in contact in the
        predictor iterate (0 if none overlaps; collective).

        ``"mean"``: ``deepest * min(m, 7 (0.8 - m))`` (0 if negative), ``m`` the mean
        overlap of the overlapping points over the deepest. A curved (non-conforming)
        contact overlaps like a paraboloid near its first touch, ``m`` = 1/2 over a point
        contact's elliptic region and 2/3 over a line contact's strip, and its zone lies
        where the overlap exceeds the mean (on the meshes of the 2D Hertz scene ``m`` is
        0.66 to 0.68). A flatter overlap (``m`` over 0.7: faces pressed together, a
        punch) is a conforming contact, whose zone covers it or more: the level falls
        linearly to every overlapping point at ``m`` = 0.8 (a strip's quartic profile; the
        self-contact slot of the tests, ``m`` = 0.73, ends with more points in contact than
        overlap).
        """
        normal, proj = pair.normal, pair.projection
        deepest = comm.allreduce(normal.deepest_overlap(proj), MPI.MAX)
        if self.first_contact_level != "mean":
            return float(self.first_contact_level) * deepest
        moments = normal.overlap_moments(proj, pair.slave.point_weights)
        total, measure = comm.allreduce(moments, MPI.SUM)
        if measure == 0.0 or deepest == 0.0:
            return 0.0
        m = total / measure / deepest
        return deepest * max(min(m, 7.0 * (0.8 - m)), 0.0)

    @staticmethod
    def _predictor_iterate(shifted: list, solver: StepSolver) -> None:
        """One iterate with the shifted contact law of ``shifted``, kept unless it leaves
        the residual of the contact law above :data:`PREDICTOR_GROWTH` times that before it
        (or not a number), else undone (collective)."""
        before = solver.newton.norms[-1]  # the residual at x (the free iterate's last)
        free = solver.x.copy()
        try:
            solver.newton_solve(partial=True)
            for c in shifted:
                c.normal.restore_contact_threshold()
            solver.operator.forget_state()
            F = solver.operator.evaluate_residual(solver.x)
            after = F.norm()
            F.destroy()
            if not after < PREDICTOR_GROWTH * before:  # or not a number: back
                free.copy(solver.x)
        finally:
            free.destroy()


class PredictedStateRetry:
    """Newton from the predicted state (:class:`Predictor`), where the step begins at the
    end of the last converged step and no body is loose. In a frictional ironing, where the
    full-step Newton from the start swings many contact statuses per iterate on the punch's
    front until an iterate inverts elements, it converges from the predicted state and saves
    the cut-backs, with the same forces."""

    def attempt(self, step: Step, solver: StepSolver) -> int | None:
        if step.loose:
            return None
        step.start.copy(solver.x)
        if not solver.predictor.predict(solver.x, step.t_from, step.t_to):
            return None
        reason, its = solver.newton_solve()
        step.iterations += its
        return reason


class LineSearchRetry:
    """Newton from the start with another line search (``None``: no such try): a
    semismooth Newton can cycle between contact or stick/slip states, or overshoot into
    inverted elements, where a backtracking one does not."""

    def __init__(self, line_search: str | None = "bt"):
        self.line_search = line_search

    def attempt(self, step: Step, solver: StepSolver) -> int | None:
        if self.line_search in (None, solver.newton.line_search):
            return None
        step.start.copy(solver.x)
        with solver.newton.using_line_search(self.line_search):
            reason, its = solver.newton_solve()
        step.iterations += its
        return reason


class ClosingRetry:
    """Where a contact pair has no point in contact at the start (and no body is loose):
    Newton after one closing iterate (:meth:`StepSolver.closing_iterate`). A body held
    only by contact and pushed by a force is free until it touches: its tangent is singular
    at the start; the closing iterate ties the nearest points to the master so the load has
    a path, and the iterates after it use the contact law again."""

    def attempt(self, step: Step, solver: StepSolver) -> int | None:
        if step.loose:
            return None
        step.start.copy(solver.x)
        pairs = solver.open_pairs()
        if not pairs:
            return None
        solver.closing_iterate(pairs)
        reason, its = solver.newton_solve()
        step.iterations += 1 + its
        return reason


def default_strategies(
    predictor: str | None = "retry",
    first_contact_level: str | float | None = "mean",
    fallback_line_search: str | None = "bt",
    close_gaps: bool = True,
) -> list:
    """The strategies of a step, in order.

    Parameters
    ----------
    predictor
        ``"retry"``: a retry from the predicted state after the first try failed;
        ``"first"``: the first try from it (it changes the iterations of every step,
        ``"retry"`` only those of steps whose first try failed); ``None``: never.
    first_contact_level
        The first try's predictor iterate on a first contact (:class:`FirstTry`).
    fallback_line_search
        The line search of :class:`LineSearchRetry` (``None``: no such retry).
    close_gaps
        Close a loose body's pairs first, and retry with a closing iterate.
    """
    if predictor not in (None, "first", "retry"):
        raise ValueError(f"predictor must be 'retry', 'first' or None, got {predictor!r}")
    strategies = [FirstTry(predictor == "first", first_contact_level, close_gaps)]
    if predictor == "retry":
        strategies.append(PredictedStateRetry())
    strategies.append(LineSearchRetry(fallback_line_search))
    if close_gaps:
        strategies.append(ClosingRetry())
    return strategies


class StepSolver:
    """A load step of a contact problem, tried by its strategies in order.

    Usually made on first use of :attr:`ContactProblem.solver
    <contact_ufl.problem.ContactProblem.solver>`.

    Parameters
    ----------
    problem
        The problem (pseudo-time, contact pairs, free pieces).
    operator
        Its discrete operator (the state, residual and tangent).
    newton
        The Newton driver over the operator's callbacks.
    diagnosis
        What a failed try's iterates showed.
    strategies
        The strategies of a step (default: :func:`default_strategies`).

    Attributes
    ----------
    strategies
        The strategies, in order; replace them to change how a step is tried.
    predictor
        The last converged increment (:class:`Predictor`).
    """

    def __init__(
        self,
        problem: SolvedProblem,
        operator: ContactOperator,
        newton: NewtonDriver,
        diagnosis: StepDiagnosis,
        strategies: list | None = None,
    ):
        self.problem, self.operator, self.newton = problem, operator, newton
        self.diagnosis = diagnosis
        self.comm = operator.comm
        self.strategies = default_strategies() if strategies is None else strategies
        self.predictor = Predictor()
        newton.on_iterate = diagnosis.record_iterate
        newton.on_not_finite = diagnosis.record_not_finite

    @property
    def x(self) -> PETSc.Vec:
        """The unknowns (the operator's)."""
        return self.operator.x

    @property
    def snes(self) -> PETSc.SNES:
        """The Newton driver's SNES."""
        return self.newton.snes

    @property
    def timings(self) -> NewtonTimings:
        """Seconds and counts of the parts of the solves."""
        return self.operator.timings

    @property
    def residual_norm(self) -> float:
        """Norm of the residual at the end of the last Newton solve."""
        return self.newton.residual_norm

    def solve_step(self, t: float) -> tuple[bool, int, str]:
        """Solve for pseudo-time ``t`` from the current state (a step begun by
        :meth:`ContactProblem.begin_step <contact_ufl.problem.ContactProblem.begin_step>`),
        trying :attr:`strategies` in order until one converges.

        Returns
        -------
        converged, Newton iterations (of all tries), SNES converged reason (name)
        """
        if self.newton.snes is None:
            raise RuntimeError("this solver is closed (close()): make a new problem to solve")
        t0 = self.problem.t
        self.problem.set_time(t)
        self.operator.read_unknowns()
        self.operator.begin_step()
        step = Step(t0, t, self.x.copy(), loose=[])
        reason = PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
        for strategy in self.strategies:
            outcome = strategy.attempt(step, self)
            if outcome is not None:
                reason = outcome
                if reason > 0:
                    break
        self.operator.forget_state()
        self.operator.set_state(self.x)
        if reason > 0:
            self.predictor.record(t0, t, step.start, self.x)
        step.start.destroy()
        # PETSc objects of more than one rank dropped by Python (the operators and matrices
        # of the pairings met) wait on their communicator until a collective clean-up:
        # without it they stay in memory (the mesh's communicator, not PETSc's world one)
        PETSc.garbage_cleanup(self.comm)
        names = {v: k for k, v in vars(PETSc.SNES.ConvergedReason).items() if k.isupper()}
        return reason > 0, step.iterations, names.get(reason, str(reason))

    def diagnose(self) -> str:
        """Why the last Newton solve failed, at its last iterate (collective; see
        :class:`~contact_ufl.diagnosis.StepDiagnosis`)."""
        return self.diagnosis.diagnose(self.newton.norms)

    # -- what the strategies use --------------------------------------------------------
    def newton_solve(self, partial: bool = False) -> tuple[int, int]:
        """One Newton solve from :attr:`x`: converged reason and iterations. ``partial``: a
        solve cut short on purpose (``max_it`` set low), whose factorisation and contact
        state at :attr:`x` the next solve may keep (a failed solve's factorisation is reset,
        and a solve's first residual searches anew)."""
        if not partial:
            self.operator.forget_state()
        self.diagnosis.start_solve()
        return self.newton.solve(self.x, keep_factorisation=partial)

    def open_pairs(self) -> list:
        """The contact pairs with no point in contact at :attr:`x` (collective)."""
        self.operator.forget_state()
        self.operator.set_state(self.x)
        contacts = self.problem.contacts
        counts = self._points_in_contact()
        return [c for c, n in zip(contacts, counts, strict=True) if n == 0]

    def loose_pairs(self) -> list:
        """The contact pairs to close before the first try (collective): the pairs with no
        point in contact at :attr:`x` on a piece held by no point in contact, with free
        rigid modes (translations, rotations) along which the residual at :attr:`x` has a
        net load (force, moment over the piece's size) above the absolute tolerance
        (:mod:`contact_ufl.free_bodies`): there the tangent is singular and the Newton
        equation has no solution."""
        pieces = self.diagnosis.free_pieces
        if not pieces:
            return []
        self.operator.forget_state()  # the search at the step's time (a rigid obstacle moves)
        residual = self.operator.evaluate_residual(self.x).array_r
        contacts = self.problem.contacts
        counts = self._points_in_contact()
        atol = self.newton.tolerances[1]
        loose = set()
        for piece, on in pieces:
            if np.any(counts[on] > 0):
                continue  # a point in contact holds the piece
            if self.problem.net_free_load(residual, piece) > atol:
                loose.update(on)
        return [c for k, c in enumerate(contacts) if k in loose]

    def _points_in_contact(self) -> np.ndarray:
        """How many slave points of each contact pair are in contact, over all ranks."""
        contacts = self.problem.contacts
        return self.comm.allreduce(np.array([c.active().sum() for c in contacts]), MPI.SUM)

    def closing_iterate(self, pairs: list) -> None:
        """One Newton iterate from :attr:`x` in which the open points of ``pairs`` within
        twice the nearest open gap, or within a tenth of the slave mesh size, count as in
        contact (a patch of points around the nearest one, not a single point about which
        the body could turn)."""
        self.operator.set_state(self.x)  # the search of open_pairs at x, if still current
        for c in pairs:
            nearest = self.comm.allreduce(c.normal.nearest_open_gap(c.projection), MPI.MIN)
            if np.isfinite(nearest):
                c.normal.count_in_contact_within(max(2.0 * nearest, 0.1 * c.slave.facet_size))
        try:
            with self.newton.limited(max_it=1):
                self.newton_solve()
        finally:
            for c in pairs:
                c.normal.restore_contact_threshold()
            self.operator.forget_state()

    def close(self) -> None:
        """Free the PETSc objects of the driver, the operator and the predictor now
        (collective: call it on every rank)."""
        if self.newton.snes is None:
            return
        self.newton.close()
        self.operator.close()
        self.predictor.close()
        PETSc.garbage_cleanup(self.comm)
