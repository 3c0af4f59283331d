"""Newton's method: a thin wrapper of PETSc SNES over a residual and a Jacobian callback.

:class:`NewtonDriver` knows nothing of contact, in the manner of DOLFINx's
``NonlinearProblem``: callbacks and an unknowns vector in, a converged reason and the
iterations out. The contact problem's callbacks are those of its discrete operator
(:class:`~contact_ufl.operator.ContactOperator`); how a load step is tried, and retried, is
:mod:`contact_ufl.strategies`.
"""

from __future__ import annotations

import contextlib
import time
import weakref
from collections.abc import Callable, Iterator

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl.timings import NewtonTimings

DEFAULT_PETSC_OPTIONS = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    "snes_rtol": 1e-9,
    "snes_stol": 0.0,
    "snes_max_it": 25,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}

#: Options of an iterative linear solve for large 3D problems (``petsc_options`` of
#: :class:`~contact_ufl.problem.ContactProblem`): flexible GMRES on an upper triangular Schur
#: split of the unknowns (:meth:`ContactOperator.field_splits
#: <contact_ufl.operator.ContactOperator.field_splits>`), algebraic multigrid (GAMG) on the
#: displacements and LU on the multipliers' Schur approximation. MUMPS's work grows like n^2
#: with the unknowns in 3D, this one's about like n: it pays from some 25,000 unknowns in 3D
#: with linear elements (not with quadratic ones at the sizes tried) and gains more on two
#: ranks (see :doc:`/guide/solvers`). Its linear solves end at a relative residual of
#: 1e-8; Newton's iterations and answers are MUMPS's. A problem without multipliers (no
#: contact pair) takes the multigrid on the whole.
FIELD_SPLIT_PETSC_OPTIONS = {
    "ksp_type": "fgmres",
    "ksp_rtol": 1e-8,
    "ksp_gmres_restart": 100,
    "ksp_max_it": 500,
    "pc_type": "fieldsplit",
    "pc_fieldsplit_type": "schur",
    "pc_fieldsplit_schur_fact_type": "upper",  # one multigrid cycle an iteration, not two
    "pc_fieldsplit_schur_precondition": "selfp",
    "fieldsplit_u_ksp_type": "preonly",
    "fieldsplit_u_pc_type": "gamg",
    "fieldsplit_u_pc_gamg_threshold": 0.01,
    "fieldsplit_lambda_ksp_type": "preonly",
    "fieldsplit_lambda_pc_type": "lu",
}


def one_field_options(options: dict) -> dict:
    """The ``fieldsplit`` ``options`` of a problem with the displacements only (no
    multipliers: one field, nothing to split): the ``u`` split's preconditioner (``pc_*``
    of ``fieldsplit_u_pc_*``) on the whole; the other options kept."""
    kept = {k: v for k, v in options.items() if not k.startswith(("pc_", "fieldsplit_"))}
    prefix = "fieldsplit_u_pc_"
    return kept | {k[len("fieldsplit_u_") :]: v for k, v in options.items() if k.startswith(prefix)}


def weak_callback(method: Callable) -> Callable:
    """A callback calling the bound ``method`` through a weak reference to its object (a
    PETSc object holding it does not keep that object alive; once it is gone, the callback
    does nothing)."""
    ref = weakref.WeakMethod(method)

    def call(*args):
        if (bound := ref()) is not None:
            return bound(*args)
        return None

    return call


#: A residual callback ``residual(x, F)``: ``F`` set to the residual at the unknowns ``x``.
Residual = Callable[[PETSc.Vec, PETSc.Vec], None]
#: A Jacobian callback ``jacobian(x) -> (J, pattern)``: the Jacobian at ``x`` and a number
#: that changes whenever ``J`` is another matrix or its nonzero pattern changed (then the
#: factorisation's symbolic analysis is redone).
Jacobian = Callable[[PETSc.Vec], tuple[PETSc.Mat, int]]


class NewtonDriver:
    """PETSc SNES over a residual and a Jacobian callback.

    Parameters
    ----------
    comm
        The communicator of the unknowns.
    residual, jacobian
        The callbacks (:data:`Residual`, :data:`Jacobian`).
    F, J
        The residual vector SNES evaluates into, and the first Jacobian matrix.
    options
        PETSc options (SNES, KSP, PC) overriding :data:`DEFAULT_PETSC_OPTIONS`.
    prefix
        Prefix of those options in the PETSc options database.
    field_splits
        The index sets of a ``pc_type fieldsplit`` (``[(name, IS), ...]``; ``None``: one
        field, whose options are then :func:`one_field_options`).
    timings
        Where the SNES time, its callbacks' time and the iterations are added.
    verbose
        Print a PETSc error of a solve (rank 0).

    Attributes
    ----------
    snes
        The PETSc SNES.
    norms
        The residual norm of each iterate of the last solve.
    on_iterate
        Called as ``on_iterate(norm)`` at each iterate (SNES's monitor), or ``None``.
    on_not_finite
        Called, inside a solve, when a residual is not a number (where did the iterate go
        wrong?), or ``None``.
    """

    def __init__(
        self,
        comm: MPI.Comm,
        residual: Residual,
        jacobian: Jacobian,
        F: PETSc.Vec,
        J: PETSc.Mat,
        options: dict,
        prefix: str = "contact_",
        field_splits: list[tuple[str, PETSc.IS]] | None = None,
        timings: NewtonTimings | None = None,
        verbose: bool = False,
    ):
        self.comm = comm
        self._residual_callback, self._jacobian_callback = residual, jacobian
        self.J = J
        self._pattern: int | None = None  # the pattern the factorisation was analysed on
        self._retired = None  # a matrix replaced inside a Jacobian call, kept for its caller
        self.field_splits = field_splits
        self.timings = NewtonTimings() if timings is None else timings
        self.verbose = verbose
        self.norms: list[float] = []
        self.on_iterate: Callable[[float], None] | None = None
        self.on_not_finite: Callable[[], None] | None = None
        self._in_solve = False
        self._callback_error: BaseException | None = None
        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        if options.get("pc_type") == "fieldsplit" and field_splits is None:
            options = one_field_options(options)
        database = PETSc.Options()
        for key, value in (DEFAULT_PETSC_OPTIONS | options).items():
            database[f"{prefix}{key}"] = value
        # weak callbacks: the SNES must not keep the driver (and through it the operator,
        # meshes, spaces and communicators) alive through a reference cycle that Python's
        # collector cannot see
        self.snes.setFunction(weak_callback(self._residual), F)
        self.snes.setJacobian(weak_callback(self._jacobian), J)
        self.snes.setMonitor(weak_callback(self._monitor))
        self.snes.setFromOptions()
        self.snes.getKSP().setFromOptions()
        self._split_fields()

    # -- the solve ----------------------------------------------------------------------
    def solve(self, x: PETSc.Vec, keep_factorisation: bool = False) -> tuple[int, int]:
        """Newton from ``x`` (updated in place): SNES's converged reason and iterations.

        A PETSc error inside the solve (a failed factorisation) is a failed solve
        (``DIVERGED_LINEAR_SOLVE``), not a crash; an exception of a callback is raised once
        SNES has returned. After a failed solve the factorisation is reset (no stale one in
        the next try) unless ``keep_factorisation`` (a solve cut short on purpose)."""
        self.norms = []
        self._callback_error = None
        start = time.perf_counter()
        self._in_solve = True
        try:
            self.snes.solve(None, x)
            reason = self.snes.getConvergedReason()
        except PETSc.Error as error:
            if self.verbose and self.comm.rank == 0:
                print(f"  PETSc error in the Newton solve: {error}", flush=True)
            reason = PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
        finally:
            self._in_solve = False
            self.timings.newton += time.perf_counter() - start
        if self._callback_error is not None:
            # an exception in a callback is not a failed try: PETSc would have kept the
            # iterate's vector locked (every later try failing), and it names the problem
            error, self._callback_error = self._callback_error, None
            raise error
        iterations = self.snes.getIterationNumber()
        self.timings.iterations += iterations
        if reason <= 0 and not keep_factorisation:
            self.reset_factorisation()
        return reason, iterations

    @property
    def residual_norm(self) -> float:
        """Norm of the residual at the end of the last solve."""
        return self.snes.getFunctionNorm()

    @property
    def tolerances(self) -> tuple[float, float, float, int]:
        """SNES's ``(rtol, atol, stol, max_it)``."""
        return self.snes.getTolerances()

    @contextlib.contextmanager
    def limited(self, max_it: int | None = None, atol: float | None = None) -> Iterator[None]:
        """Solves with another iteration budget or absolute tolerance, restored on leaving."""
        rtol, old_atol, stol, old_max_it = self.snes.getTolerances()
        self.snes.setTolerances(
            atol=old_atol if atol is None else atol,
            max_it=old_max_it if max_it is None else max_it,
        )
        try:
            yield
        finally:
            self.snes.setTolerances(atol=old_atol, max_it=old_max_it)

    @property
    def line_search(self) -> str:
        """The type of SNES's line search."""
        return self.snes.getLineSearch().getType()

    @contextlib.contextmanager
    def using_line_search(self, kind: str) -> Iterator[None]:
        """Solves with the line search ``kind``, the former one restored on leaving."""
        line_search = self.snes.getLineSearch()
        former = line_search.getType()
        line_search.setType(kind)
        try:
            yield
        finally:
            line_search.setType(former)

    def reset_factorisation(self) -> None:
        """Reset the preconditioner (a new symbolic factorisation), keeping the field
        splits of a ``fieldsplit`` (which a reset drops)."""
        self.snes.getKSP().getPC().reset()
        self._split_fields()

    def close(self) -> None:
        """Destroy the SNES and the matrix kept for a caller (collective)."""
        for obj in (self.snes, self._retired):
            if obj is not None:
                obj.destroy()
        self.snes = self._retired = self.J = None

    # -- callbacks ----------------------------------------------------------------------
    def _residual(self, snes, x, F) -> None:
        if self._in_solve and self._callback_error is not None:
            F.set(np.nan)  # stop this solve: :meth:`solve` raises the error
            return
        if self._in_solve and not self.comm.allreduce(bool(np.isfinite(x.array_r).all()), MPI.LAND):
            F.set(np.nan)  # the iterate left the numbers: a failed try, no evaluation of it
            return
        start = time.perf_counter()
        with self._holding_errors():
            self._residual_callback(x, F)
            if self._in_solve and self.on_not_finite and not np.isfinite(F.norm()):
                self.on_not_finite()
        if self._callback_error is not None:
            F.set(np.nan)
        if self._in_solve:
            self.timings.callbacks += time.perf_counter() - start

    def _jacobian(self, snes, x, J, P) -> None:
        if self._in_solve and self._callback_error is not None:
            return  # the next residual stops the solve
        start = time.perf_counter()
        with self._holding_errors():
            matrix, pattern = self._jacobian_callback(x)
            self._use(matrix, pattern)
        if self._in_solve:
            self.timings.callbacks += time.perf_counter() - start

    def _use(self, matrix: PETSc.Mat, pattern: int) -> None:
        """Give SNES ``matrix`` (another one, or a new pattern: a new analysis). Inside a
        Jacobian call SNES hands the new matrix to its linear solver; the replaced one is
        kept until the next replacement, for the call that holds it."""
        if matrix is not self.J:
            self._retired, self.J = self.J, matrix
            self.snes.setJacobian(weak_callback(self._jacobian), matrix)
        if self._pattern is not None and pattern != self._pattern:
            self.reset_factorisation()  # MUMPS fails on a changed pattern otherwise
        self._pattern = pattern

    def _monitor(self, snes, its: int, norm: float) -> None:
        self.norms.append(float(norm))
        if self.on_iterate is not None:
            with self._holding_errors():  # the next residual stops the solve
                self.on_iterate(float(norm))

    @contextlib.contextmanager
    def _holding_errors(self) -> Iterator[None]:
        """Inside a solve, keep an exception of a callback (raised by :meth:`solve` once
        SNES has returned and unlocked its vectors), Ctrl-C's ``KeyboardInterrupt``
        included: through PETSc it would come back as a failed linear solve, and the step
        would be cut back instead of stopped."""
        try:
            yield
        except BaseException as error:
            if not self._in_solve:
                raise
            self._callback_error = error

    def _split_fields(self) -> None:
        pc = self.snes.getKSP().getPC()
        if self.field_splits and pc.getType() == PETSc.PC.Type.FIELDSPLIT:
            pc.setFieldSplitIS(*self.field_splits)
