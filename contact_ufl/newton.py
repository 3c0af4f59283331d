"""Newton's method (PETSc SNES) over the unknowns of a contact problem.

The residual and Jacobian forms of :class:`~contact_ufl.problem.ContactProblem` are
assembled over the fields ``[u, xhat_1, lambda_1, ...]``; the chain operator ``T`` of
:mod:`contact_ufl.layout` (identity on the unknowns, the gathers ``xhat = Xhat + P u``)
maps them onto the unknowns ``[u, lambda_1, ...]``: residual ``T^T r``, tangent
``T^T K T`` (the tangent's blocks between two unknowns, the bulk's among them, are assembled
straight into the solver matrix: ``T`` maps them by the identity). The search runs at every
new state; ``T`` and the tangent's sparsity pattern change only when the pairing does, and
the solver matrix's pattern (that of the factorisation's symbolic analysis) only when a
pairing leaves a superset of the pairings met (:attr:`NewtonSolver.pattern_superset`) and its
product adds a nonzero to the solver matrix. The solver times its parts
(:class:`NewtonTimings`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import time
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import dolfinx
import dolfinx.fem.petsc as fem_petsc
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import assembly, free_bodies, keysets
from contact_ufl.layout import StackedLayout, chain_operator, split_tangent

if TYPE_CHECKING:
    from contact_ufl.problem import ContactProblem

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
#: split of the unknowns (:meth:`NewtonSolver._split_fields`), algebraic multigrid (GAMG) on
#: the displacements and LU on the multipliers' Schur approximation. MUMPS's work grows like n^2
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


@dataclass
class NewtonTimings:
    """Wall-clock seconds of the parts of the Newton solves of a :class:`NewtonSolver`, on
    this rank, accumulated since the solver was made or :meth:`reset` (no collectives: on
    several ranks each rank has its own).

    Attributes
    ----------
    search
        Search and contact data update (``_update_contact``): closest-point projection,
        contact data, and the chain operator ``T`` where the pairing changed.
    residual_assembly
        Assembly of the residual over the fields and its map ``T^T r`` to the unknowns, with
        the Dirichlet rows.
    jacobian_assembly
        Assembly of the tangent: its blocks between unknowns straight into the solver's
        matrix, the blocks of the gathered fields (``K``) over the fields they couple.
    ptap
        ``T^T K T`` of the gathered blocks, its sum into the solver's matrix (whose pattern
        grows, with a reset factorisation, where a new pairing leaves it) and the Dirichlet
        rows.
    newton
        Time inside ``SNES.solve``.
    callbacks
        Time of the residual and Jacobian callbacks inside ``SNES.solve`` (including their
        searches).
    searches, residuals, jacobians, iterations
        Counts: contact updates, residual and Jacobian evaluations (in or out of SNES), and
        Newton iterations.
    new_patterns
        Jacobians assembled on a new sparsity pattern of ``T^T K T`` (the pairing changed):
        a symbolic PtAP.
    analyses
        Sparsity patterns given to the factorisation (the first, and those grown because a
        pairing added a nonzero to the solver matrix's pattern, see
        :attr:`NewtonSolver.pattern_slack`): each is followed by a symbolic analysis, as
        costly as a numeric factorisation.
    """

    search: float = 0.0
    residual_assembly: float = 0.0
    jacobian_assembly: float = 0.0
    ptap: float = 0.0
    newton: float = 0.0
    callbacks: float = 0.0
    searches: int = 0
    residuals: int = 0
    jacobians: int = 0
    iterations: int = 0
    new_patterns: int = 0
    analyses: int = 0

    @property
    def linear_solve(self) -> float:
        """SNES time outside the callbacks: factorisation and solve of the linear systems,
        plus SNES's own vector work (norms, updates, line search), which is small beside
        them."""
        return max(self.newton - self.callbacks, 0.0)

    def reset(self) -> None:
        """Zero all times and counts."""
        for f in dataclasses.fields(self):
            setattr(self, f.name, f.default)

    def per_iteration(self) -> dict[str, float]:
        """Seconds per Newton iteration of each part (and ``total``, the SNES time).

        The parts include their calls outside SNES (the search at the converged state of a
        step, the evaluations of a closing iterate), so they may add up to more than
        ``total``."""
        n = max(self.iterations, 1)
        parts = ("search", "residual_assembly", "jacobian_assembly", "ptap", "linear_solve")
        out = {name: getattr(self, name) / n for name in parts}
        out["total"] = self.newton / n
        return out


#: The growth of the residual norm above which a first contact's predictor iterate is
#: undone (:meth:`NewtonSolver._predictor_iterate`): it changes the contact state at once,
#: so the norm may grow a little on an iterate that saves later ones, but a predictor that
#: pulls large overlaps shut in one linear step can throw the state far off (the beams' first
#: contact without friction), and Newton then inverts cells.
_PREDICTOR_GROWTH = 10.0


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


def _nonzero_keys(M: PETSc.Mat | None) -> np.ndarray:
    """Sorted keys ``row * columns + column`` (global indices) of the nonzeros of this
    rank's rows of ``M``, explicit zeros included (none for no matrix)."""
    if M is None:
        return np.zeros(0, np.int64)
    offsets, columns, _ = M.getValuesCSR()
    start = M.getOwnershipRange()[0]
    rows = np.repeat(np.arange(start, start + len(offsets) - 1, dtype=np.int64), np.diff(offsets))
    keys = rows * M.getSize()[1] + columns
    # an AIJ row holds its columns sorted: the keys are a set already
    return keys if keysets.is_strictly_increasing(keys) else keysets.unique(keys)


class NewtonSolver:
    """PETSc SNES Newton over the unknowns of a :class:`~contact_ufl.problem.ContactProblem`.

    Usually made on first use of :attr:`ContactProblem.solver
    <contact_ufl.problem.ContactProblem.solver>`. Making it searches the contacts at the
    current state and commits that state as the converged state of step 0
    (:meth:`ContactProblem.commit <contact_ufl.problem.ContactProblem.commit>`); it then
    becomes the problem's :attr:`~contact_ufl.problem.ContactProblem.solver` (one solver per
    problem: a second one would commit the contacts and plastic histories again).

    Parameters
    ----------
    problem
        The problem: fields, unknowns, forms, Dirichlet rows, pseudo-time.
    petsc_options
        PETSc options (SNES, KSP, PC) overriding :data:`DEFAULT_PETSC_OPTIONS`; the
        default ``snes_atol`` is ``1e-11 E_max L^(d-1)`` (a force, L the scene's diameter).
    petsc_options_prefix
        Prefix of those options in the PETSc options database.

    Attributes
    ----------
    x
        The unknowns ``[u, lambda_1, ...]`` (a PETSc vector; the problem's functions hold
        the same values at the current state).
    snes
        The PETSc SNES.
    fallback_linesearch
        Line search of the try of a failed Newton solve after the predicted one (see
        :meth:`solve_step`).
    predictor
        Where a step may start from the *predicted* state, the converged state plus the last
        converged step's increment scaled to the step (the same equations, another first
        iterate; see :meth:`solve_step`): ``"retry"`` (default) in a try after the
        full-step Newton from the converged state failed, ``"first"`` in the first try, or
        ``None`` (never).
    close_gaps
        Whether a failed step whose start has a contact pair with no point in contact is
        tried once more after a closing iterate (see :meth:`solve_step`).
    first_contact_level
        The first try of a step whose start has a contact pair with no point in contact
        takes, after its first (free) iterate, a predictor iterate in which that pair's
        points count as in contact only where they overlap the master by more than a
        level (see :meth:`solve_step`): ``"mean"`` (default) the mean overlap of its
        overlapping points, a number that fraction of its deepest overlap, ``None`` no
        predictor iterate.
    timings
        Seconds spent in the parts of the Newton solves (:class:`NewtonTimings`).
    pattern_slack
        The solver matrix's sparsity pattern is made, not from the current pairing's
        tangent ``T^T K T``, but from a superset: the couplings of every point with the
        master nodes of its facet and of the facets beside it (the contacts'
        ``pattern_gathers``), explicit zeros where there is no coupling. A pairing that
        moves points onto neighbouring facets then keeps the pattern, and the factorisation
        keeps its symbolic analysis. A pairing outside it grows the pattern (a union); a
        union that would hold more than ``1 + pattern_slack`` times the couplings of the
        current superset is rebuilt on the current one instead (at that growth, or at the
        start of a step): in 3D, where every new pairing grows the pattern, an unbounded
        union ends with several times the nonzeros and the factorisation's flops of the
        rebuilt pattern. A pairing that leaves the last superset but whose product ``T^T K
        T`` has no nonzero outside those added to the solver matrix keeps the matrix and its
        analysis, which saves analyses in 3D (see :doc:`/guide/solvers` and, for the
        numbers, :doc:`/developer`).
    pattern_superset
        Whether the pattern holds the facets beside each point's facet (default: in 2D).
        Without it (the 3D default) the pattern is the union of the pairings met: an analysis
        for every pairing that leaves it. In 3D the superset's extra fill (larger still with
        the smoothed normal's wide gathers) costs more than the analyses it saves.
    """

    def __init__(
        self,
        problem: ContactProblem,
        petsc_options: dict | None = None,
        petsc_options_prefix: str = "contact_",
    ):
        if problem._solver is not None:
            raise ValueError("this problem has a solver already (problem.solver)")
        self.problem = problem
        self.comm = problem.comm
        self.timings = NewtonTimings()
        self._in_snes = False
        spaces = [f.function_space for f in problem.fields]
        self._field_index = {id(f): k for k, f in enumerate(problem.fields)}
        self._r = fem_petsc.create_vector(spaces, kind="mpi")
        # the tangent's blocks between unknowns go straight into the solver matrix (T maps
        # them by the identity; A: their pattern and the local-to-global maps of that
        # assembly); only the blocks of the gathered fields go through T^T K T
        self._unknown_forms, self._gathered_forms, self._coupled = split_tangent(
            problem.jacobian_form, problem.fields, problem.unknowns
        )
        self._A = None
        # the parts of those blocks fixed by the mesh (a linear-elastic bulk's stiffness):
        # assembled once a load step into B (A's pattern), added to every tangent of the step
        self._B = self._varying_forms = self._fixed_forms = None
        self._B_stale = True
        if self._unknown_forms is not None:
            self._A = assembly.create_matrix_with_pattern(self._unknown_forms)
            fixed, self._varying_forms = assembly.split_constant(self._unknown_forms)
            if any(parts for row in fixed for parts in row):
                self._B = self._A.duplicate()  # zero values
                self._fixed_forms = fixed
        self._K = self._coupled_layout = None
        if self._gathered_forms is not None:
            coupled = [problem.fields[i].function_space for i in self._coupled]
            # the gathered blocks couple the point data (the master nodes at each slave
            # point) only point by point: K's pattern without the rest (fewer nonzeros to
            # assemble and multiply)
            full = assembly.create_matrix_with_pattern(self._gathered_forms)
            self._K = assembly.without_cross_point_couplings(full, coupled)
            full.destroy()
            self._coupled_layout = StackedLayout(coupled)
        self.x = fem_petsc.create_vector([f.function_space for f in problem.unknowns], kind="mpi")
        fem_petsc.assign(problem.unknowns, self.x)
        self._R = self.x.duplicate()
        self._J = None
        self._T = None  # the chain operator onto every field (the residual's)
        self._T_coupled = None  # its rows of the fields the gathered blocks couple
        self._JT = None
        self._pattern = None
        self._T_wide = None  # the superset operator of the solver matrix's pattern
        self._wide_keys = None  # sorted (row, column) keys of the couplings of the pattern
        self._wide_now = 0  # number of keys of the last superset (this rank)
        self._wide_current = None  # sorted keys of the last superset operator
        self._gathers = None  # the parts of the problem that gather, and their gathers
        self._grow = True  # the pattern must grow before the next factorisation
        self._retired = None  # a solver matrix replaced inside a SNES Jacobian call
        self._product_keys = None  # the gathered blocks' nonzeros added to the solver matrix
        self.pattern_slack = 0.5
        self.pattern_superset = problem.gdim == 2
        self._state = None
        self._update_contact(self.x)
        problem.commit(self.x)  # the initial state is the converged state of step 0
        problem.begin_step()
        self._state = None
        self._update_contact(self.x)
        self._J = self._assemble_jacobian_matrix(first=True)
        self.snes = self._create_snes(petsc_options or {}, petsc_options_prefix)
        self.fallback_linesearch: str | None = "bt"
        #: per Newton iteration of the last solve: residual norm and the contact state (a
        #: signature of the pairing and status of this rank's points), for :meth:`diagnose`
        self.iterates: list[tuple[float, int]] = []
        self._not_finite = None
        self._callback_error: Exception | None = None  # raised in a callback (see _newton)
        #: try a closing iterate where a pair has no point in contact (:meth:`solve_step`)
        self.close_gaps = True
        self._pieces = None  # (piece, its pairs) of the pieces free in some direction
        #: where a step starts from the last converged increment (:meth:`solve_step`)
        self.predictor: str | None = "retry"
        #: the overlap above which a first contact's points count as in contact in the
        #: iterate after the free one (:meth:`solve_step`): "mean" (the mean overlap of
        #: its overlapping points), a fraction of its deepest overlap, or None (no such
        #: iterate)
        self.first_contact_level: str | float | None = "mean"
        self._increment = None  # (t_from, t_to, x_to, x_to - x_from) of the last solve
        problem._solver = self  # the solver of the problem's results that need T

    def _create_snes(self, options: dict, prefix: str) -> PETSc.SNES:
        snes = PETSc.SNES().create(self.comm)
        snes.setOptionsPrefix(prefix)
        opts = PETSc.Options()
        if options.get("pc_type") == "fieldsplit" and not self._has_other_unknowns():
            options = one_field_options(options)
        for key, value in {
            **DEFAULT_PETSC_OPTIONS,
            "snes_atol": self._default_atol(),
            **options,
        }.items():
            opts[f"{prefix}{key}"] = value
        # weak callbacks: the SNES must not keep the solver (and its problem, meshes, spaces
        # and communicators) alive through a reference cycle that Python's collector cannot see
        snes.setFunction(weak_callback(self._residual), self._R)
        snes.setJacobian(weak_callback(self._jacobian), self._J)
        snes.setMonitor(weak_callback(self._monitor))
        snes.setFromOptions()
        snes.getKSP().setFromOptions()
        if snes.getKSP().getPC().getType() == PETSc.PC.Type.FIELDSPLIT:
            self._split_fields(snes.getKSP().getPC())
        return snes

    def _reset_pc(self) -> None:
        """Reset the preconditioner (a new symbolic factorisation), keeping the field
        splits of a ``fieldsplit`` (which a reset drops)."""
        pc = self.snes.getKSP().getPC()
        pc.reset()
        if pc.getType() == PETSc.PC.Type.FIELDSPLIT:
            self._split_fields(pc)

    def _has_other_unknowns(self) -> bool:
        """Whether the unknowns hold more than the displacements (multipliers, a control's
        load factor) on some rank (collective)."""
        meshes = len(self.problem.bulks)
        return self.comm.allreduce(int(self.problem.layout.local_sizes[meshes:].sum()), MPI.SUM) > 0

    def _split_fields(self, pc: PETSc.PC) -> None:
        """The splits of a ``pc_type fieldsplit``: ``u``, the displacements of the meshes
        (block size the dimension, for GAMG), and ``lambda``, the other unknowns (the
        multipliers; a control's load factor). Their solvers take the options
        ``<prefix>fieldsplit_u_...`` and ``<prefix>fieldsplit_lambda_...``."""
        if not self._has_other_unknowns():
            return  # no multipliers: one field
        layout, meshes = self.problem.layout, len(self.problem.bulks)
        blocks = [layout.owned(b, np.arange(n)) for b, n in enumerate(layout.local_sizes)]
        u = np.concatenate(blocks[:meshes]).astype(PETSc.IntType)
        rest = np.concatenate([np.zeros(0, np.int64), *blocks[meshes:]]).astype(PETSc.IntType)
        displacements = PETSc.IS().createGeneral(u, comm=self.comm)
        displacements.setBlockSize(self.problem.gdim)
        pc.setFieldSplitIS(
            ("u", displacements), ("lambda", PETSc.IS().createGeneral(rest, comm=self.comm))
        )

    def _default_atol(self) -> float:
        """A force scale: 1e-11 of ``E_max L^(d-1)`` with L the scene's diameter."""
        size, E = self.problem.scales()
        return 1e-11 * E * size ** (self.problem.gdim - 1)

    # -- state, search and the chain operator -----------------------------------------
    def _set_state(self, x: PETSc.Vec) -> None:
        if self._state is not None and x.equal(self._state):
            return
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        fem_petsc.assign(x, self.problem.unknowns)
        for f in self.problem.unknowns:
            f.x.scatter_forward()
        self._update_contact(x)
        self._state = x.copy()

    def forget_state(self) -> None:
        """Make the next evaluation redo the search even at an unchanged state."""
        self._state = None

    def _update_contact(self, x: PETSc.Vec) -> None:
        """Search, refresh the contact data and (if the pairing changed) the operator T."""
        start = time.perf_counter()
        contacts = self.problem.contacts
        parts = [*contacts, *self.problem.controls]  # (controls gather their load factor)
        gathers = [c.update(self.problem.layout) for c in parts]
        pattern = [cols for g in gathers for _, cols in g]
        pattern = np.concatenate(pattern) if pattern else np.zeros(0, np.int64)
        changed = self._pattern is None or not np.array_equal(pattern, self._pattern)
        changed = self.comm.allreduce(changed, MPI.LOR)
        if changed:
            self._pattern = pattern
            self._T = self._chain_operator(gathers)
            self._T_coupled = self._chain_operator(gathers, self._coupled)
            self._JT = None
            self._gathers = (parts, gathers)
            self._widen()
        for c in contacts:
            c.update_history(self._T, x, self._block_slice)
        self.timings.search += time.perf_counter() - start
        self.timings.searches += 1

    def _gather_keys(self, gathers: list[list]) -> np.ndarray:
        """Sorted keys ``row * N + column`` of the gathered entries of ``T`` (local rows)."""
        offsets = np.concatenate([[0], np.cumsum(self.problem.full_layout.local_sizes)])
        n = self.problem.layout.global_size
        keys = []
        for g in gathers:
            for f, cols in g:
                start = offsets[self._field_index[id(f)]]
                cols = np.asarray(cols)
                cols = cols[:, None] if cols.ndim == 1 else cols
                rows = start + np.arange(len(cols))[:, None]
                keys.append((rows * n + cols)[cols >= 0])
        return keysets.unique(np.concatenate(keys)) if keys else np.zeros(0, np.int64)

    def _widen(self) -> None:
        """Where the current pairing's ``T`` is not within the solver matrix's pattern (or
        there is none yet): the superset operator of the pattern to add (collective)."""
        parts, gathers = self._gathers
        if self._wide_current is not None:
            # within the *last* superset operator, not the union of those met: T^T K T is
            # within the pattern of one operator that holds T, while a T whose rows gather
            # from two different earlier operators couples columns that no single one of
            # them couples (a new nonzero outside the pattern)
            keys, wide = self._gather_keys(gathers), self._wide_current
            inside = len(keys) == 0 or (
                len(wide) > 0 and bool(np.all(np.isin(keys, wide, assume_unique=True)))
            )
            if self.comm.allreduce(inside, MPI.LAND):
                return
        wide = [
            p.pattern_gathers() if self.pattern_superset and hasattr(p, "pattern_gathers") else g
            for p, g in zip(parts, gathers, strict=True)
        ]
        # without the superset (3D) the pattern's operator is T itself: its product
        # T^T K T is then the tangent's, not a second PtAP
        same = all(w is g for w, g in zip(wide, gathers, strict=True))
        self._T_wide = self._T_coupled if same else self._chain_operator(wide, self._coupled)
        keys = self._gather_keys(wide)
        self._wide_current = keys
        self._wide_now = len(keys)
        old = self._wide_keys
        self._wide_keys = keys if old is None else keysets.union(old, keys)
        self._grow = True

    def _chain_operator(self, gathers: list[list], rows: list[int] | None = None) -> PETSc.Mat:
        """``T``: identity from each unknown to its assembled field, gathers for the others;
        its rows of the fields ``rows`` (indices in the problem's fields; default: all).
        ``None`` for no rows."""
        problem = self.problem
        if rows is not None and not rows:
            return None
        fields = problem.fields
        rows = range(len(fields)) if rows is None else rows
        layout = problem.full_layout if len(rows) == len(fields) else self._coupled_layout
        block = {id(fields[i]): k for k, i in enumerate(rows)}
        unknown_index = {id(f): k for k, f in enumerate(problem.unknowns)}
        identity = [(block[k], unknown_index[k]) for k in block if k in unknown_index]
        gather_blocks, gather_cols = [], []
        for g in gathers:
            for f, cols in g:
                if id(f) in block:
                    gather_blocks.append(block[id(f)])
                    gather_cols.append(cols)
        return chain_operator(layout, problem.layout, identity, gather_blocks, gather_cols)

    def _block_slice(self, f: dolfinx.fem.Function) -> slice:
        """Local (owned) range of the assembled field ``f`` in the full layout."""
        k = self._field_index[id(f)]
        sizes = self.problem.full_layout.local_sizes
        start = int(sizes[:k].sum())
        return slice(start, start + int(sizes[k]))

    # -- residual and tangent -----------------------------------------------------------
    def assemble(self, forms, out: PETSc.Vec | None = None) -> PETSc.Vec:
        """Assemble the linear ``forms`` (rows: the problem's fields) at the current state and
        map them to the unknowns, ``T^T r``.

        Parameters
        ----------
        forms
            A compiled blocked linear form over the problem's fields, each block a list of
            parts (:mod:`contact_ufl.assembly`).
        out
            The result (default: a new vector of the unknowns).
        """
        out = self._R.duplicate() if out is None else out
        r = self._r
        with r.localForm() as r_local:
            r_local.set(0.0)
        assembly.assemble_vector(r, forms)
        r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self._T.multTranspose(r, out)
        return out

    def _residual(self, snes, x, F) -> None:
        if self._in_snes and self._callback_error is not None:
            F.set(np.nan)  # stop this SNES solve: :meth:`_newton` raises the error
            return
        if self._in_snes and not self.comm.allreduce(bool(np.isfinite(x.array_r).all()), MPI.LAND):
            F.set(np.nan)  # the iterate left the numbers: a failed try, no search on it
            return
        with self._holding_errors():
            self._evaluate_residual_callback(x, F)
        if self._callback_error is not None:
            F.set(np.nan)

    @contextlib.contextmanager
    def _holding_errors(self):
        """Inside a SNES solve, keep an exception of a callback in :attr:`_callback_error`
        (raised by :meth:`_newton` once SNES has returned and unlocked its vectors)."""
        try:
            yield
        except Exception as error:
            if not self._in_snes:
                raise
            self._callback_error = error

    def _evaluate_residual_callback(self, x, F) -> None:
        start = time.perf_counter()
        self._set_state(x)
        problem = self.problem
        assembly = time.perf_counter()
        self.assemble(problem.residual_form, F)
        rows = problem.dirichlet_rows
        if len(rows):
            u = x.array_r[rows]
            F.array[rows] = problem.dirichlet_scale * (u - problem.prescribed(problem.t))
        if self._in_snes and not np.isfinite(F.norm()):  # where did the iterate go wrong?
            from contact_ufl.results import inverted_cell_centres

            self._not_finite = inverted_cell_centres(problem)
        end = time.perf_counter()
        self.timings.residual_assembly += end - assembly
        self.timings.residuals += 1
        if self._in_snes:
            self.timings.callbacks += end - start

    def _assemble_jacobian_matrix(self, first: bool = False) -> PETSc.Mat:
        start = time.perf_counter()
        K = self._K
        if K is not None:
            K.zeroEntries()
            assembly.assemble_matrix(K, self._gathered_forms)
            K.assemble()
        assembled = time.perf_counter()
        if K is not None:
            if self._JT is None:
                self._JT = K.PtAP(self._T_coupled)
                self.timings.new_patterns += 1
            else:
                K.PtAP(self._T_coupled, result=self._JT)
        J = self._grown_matrix(first)
        multiplied = time.perf_counter()
        self._assemble_unknown_blocks(J)
        own = time.perf_counter()
        self._add_gathered_blocks(J)
        self.timings.jacobian_assembly += (assembled - start) + (own - multiplied)
        self.timings.ptap += (multiplied - assembled) + (time.perf_counter() - own)
        self.timings.jacobians += 1
        return J

    def _assemble_unknown_blocks(self, J: PETSc.Mat) -> None:
        """The tangent's blocks between unknowns, straight into ``J`` (its values zeroed):
        the fixed parts' ``B`` (assembled on the first tangent of a load step), then the
        others."""
        J.zeroEntries()
        if self._A is None:
            return
        if self._B is not None:
            if self._B_stale:
                self._B.zeroEntries()
                assembly.assemble_matrix(self._B, self._fixed_forms, self._unknown_forms)
                self._B.assemble()
                self._B_stale = False
            J.axpy(1.0, self._B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        assembly.assemble_matrix(J, self._varying_forms, self._unknown_forms)
        J.assemble()

    def _add_gathered_blocks(self, J: PETSc.Mat) -> None:
        """Add ``T^T K T`` of the gathered blocks to ``J``, then the Dirichlet rows."""
        if self._JT is not None:
            J.axpy(1.0, self._JT, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        self._zero_dirichlet_rows(J)

    def _grown_matrix(self, new: bool = False) -> PETSc.Mat:
        """The solver matrix, its pattern grown by that of the superset operator where a
        pairing left it (a ``new`` matrix: on that pattern only). Its pattern holds
        ``T^T K T``'s: ``T`` is within the superset operator."""
        if not (self._grow or new):
            return self._J
        pattern = None  # the gathered blocks' T^T K T over the superset operator
        tangent = self._T_wide is self._T_coupled and self._JT is not None
        if self._K is not None:
            pattern = self._JT if tangent else self._K.PtAP(self._T_wide)
        union, now = self.comm.allreduce(np.array([len(self._wide_keys), self._wide_now]))
        keys = _nonzero_keys(pattern)
        rebuild = new or union > (1.0 + self.pattern_slack) * now
        if not rebuild and self._within_solver_pattern(keys):
            # the superset left, but its product is not: the solver matrix and its
            # factorisation's symbolic analysis hold (no new nonzero)
            if pattern is not None and not tangent:
                pattern.destroy()
            self._grow = False
            return self._J
        if rebuild:  # on the current superset only
            J = self._new_matrix(pattern)
            self._wide_keys = self._wide_current
            self._product_keys = keys
            if not new:  # the SNES's matrix from now on (the old one kept for its caller)
                self._retired, self._J = self._J, J
                self.snes.setJacobian(weak_callback(self._jacobian), J)
        else:
            J = self._J
            J.zeroEntries()
            if pattern is not None:
                J.axpy(1.0, pattern, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            self._product_keys = keysets.union(self._product_keys, keys)
        if pattern is not None and not tangent:
            pattern.destroy()
        if self._A is not None:  # the maps of the unknowns' blocks' assembly into J
            J.setLGMap(*self._A.getLGMap())
        if not new:
            self._reset_pc()  # MUMPS fails on a changed pattern otherwise
        J.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        self._grow = False
        self.timings.analyses += 1
        return J

    def _within_solver_pattern(self, keys: np.ndarray) -> bool:
        """Whether the nonzeros ``keys`` (:func:`_nonzero_keys`) of a product over the
        superset are all among those added to the solver matrix since it was made, on every
        rank (collective)."""
        inside = bool(np.isin(keys, self._product_keys, assume_unique=True).all())
        return bool(self.comm.allreduce(inside, MPI.LAND))

    def _new_matrix(self, pattern: PETSc.Mat | None) -> PETSc.Mat:
        """A solver matrix on the pattern of the unknowns' blocks and ``pattern``."""
        if self._A is None:
            return pattern.duplicate()
        J = self._A.duplicate()
        if pattern is not None:
            J.axpy(1.0, pattern, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        return J

    def _shrink_pattern(self) -> None:
        """Rebuild the solver matrix on the current superset pattern where the union of the
        patterns met has grown beyond :attr:`pattern_slack` (collective; between solves)."""
        if self._JT is None or self._T_wide is None:
            return
        union, now = self.comm.allreduce(np.array([len(self._wide_keys), self._wide_now]))
        if union <= (1.0 + self.pattern_slack) * now:
            return
        self._wide_keys = self._wide_current = None
        self._widen()
        J = self._grown_matrix(new=True)
        self._assemble_unknown_blocks(J)
        self._add_gathered_blocks(J)
        self._J = J
        self.snes.setJacobian(weak_callback(self._jacobian), J)
        self._reset_pc()

    def _zero_dirichlet_rows(self, J: PETSc.Mat) -> None:
        problem = self.problem
        layout = problem.layout
        rows = (layout.rank_offsets[layout.rank] + problem.dirichlet_rows).astype(PETSc.IntType)
        J.zeroRows(rows, diag=problem.dirichlet_scale)

    def _jacobian(self, snes, x, J, P) -> None:
        if self._in_snes and self._callback_error is not None:
            return  # the next residual stops the solve
        start = time.perf_counter()
        with self._holding_errors():
            self._set_state(x)
            self._assemble_jacobian_matrix()
        if self._in_snes:
            self.timings.callbacks += time.perf_counter() - start

    def evaluate_residual(self, x: PETSc.Vec) -> PETSc.Vec:
        """The residual at the unknowns ``x`` (a new vector); sets the state to ``x``."""
        F = self._R.duplicate()
        self._residual(self.snes, x, F)
        return F

    def evaluate_jacobian(self, x: PETSc.Vec) -> PETSc.Mat:
        """The Jacobian at the unknowns ``x`` (the solver's matrix); sets the state to ``x``."""
        self._jacobian(self.snes, x, self._J, self._J)
        return self._J

    # -- Newton -------------------------------------------------------------------------
    def solve_step(self, t: float) -> tuple[bool, int, str]:
        """Solve for pseudo-time ``t`` from the current state (a step begun by
        :meth:`ContactProblem.begin_step <contact_ufl.problem.ContactProblem.begin_step>`).

        Newton takes full steps first. Where that fails, the step is solved again, before
        the caller cuts it back:

        1. with full steps from the *predicted* state (:attr:`predictor` ``"retry"``, where
           the step begins at the end of the last converged step): the start plus that
           step's increment of the unknowns (displacements and multipliers) times the
           ratio of the step sizes. In a steady process (sliding) a step repeats the last
           one, and the predicted state holds the contact and stick/slip status of the
           solution much better than the start: in a frictional ironing, where the
           full-step Newton from the start swings many contact statuses per iterate on the
           punch's front until an iterate inverts elements, it converges from the
           predicted state and saves the cut-backs, with the same forces (see
           :doc:`/guide/robustness`);
        2. from the start, with the backtracking line search :attr:`fallback_linesearch`
           (``None``: not tried): a semismooth Newton can cycle between contact or
           stick/slip states, or overshoot into inverted elements;
        3. where a contact pair has no point in contact at the start (:attr:`close_gaps`):
           after one *closing* iterate, in which the open points of such a pair within
           twice the nearest open gap, or within a tenth of the slave mesh size, count as in
           contact (a patch of points around the nearest one, not a single point about
           which the body could turn). A body held only by contact and
           pushed by a force is free until it touches: its tangent is singular at the
           start, and no Newton step can find the contact. The closing iterate ties the
           nearest points to the master surface, so the load has a path; the iterates after
           it use the contact law again (points in tension are released), so the solution
           is that of the same equations.

        Where the start shows such a body (:meth:`_loose_pairs`: a piece of a mesh with a
        rigid mode no support holds, a translation or a rotation, no point in contact on
        any of its pairs, and a net load along its free modes above the absolute
        tolerance, so that the Newton equation has no solution), the step begins with the
        closing iterate on its pairs instead of reaching it after failed tries; the
        line-search try follows if that fails (no predicted try).

        A pair with no point in contact at the start of the step (a *first contact*, not
        a loose body) gets a predictor iterate after the first one: that free iterate
        overlaps the master over the whole approach (3D Hertz: twice the contact area, 2D:
        1.7 times the width), and the semismooth Newton releases the excess from the
        zone's edge inwards, a third to a half of it an iterate, about one more iterate
        each time the excess points double under refinement. In the predictor iterate the
        pair's points count as in contact only where the free iterate overlaps by more
        than its mean overlap over the overlapping points (:attr:`first_contact_level`):
        the overlap of a rigid approach is parabolic near the first touch, and its mean is
        half its largest over an elliptic region (a point contact: the zone of Hertz's
        contact of paraboloids, ``a^2 = R delta``) and two thirds over a strip (a line
        contact: 2D, or 3D extruded; in plane strain the zone's edge depends on the bodies'
        sizes through a logarithm, and lies at two thirds in the 2D Hertz scene). Then
        Newton goes on with the contact law (the same equations, a better start, fewer
        iterations: see :doc:`/guide/robustness`). An iterate that leaves the residual over
        ten times that of the free iterate (a large overlap pulled shut in one linear step:
        the beams' first contact without friction) is undone.

        With :attr:`predictor` ``"first"`` the first try starts from the predicted state
        (fewer Newton iterations in a long steady sliding, the same forces); it changes the
        iterations of every step, ``"retry"`` only those of steps whose first try failed.

        Returns
        -------
        converged, Newton iterations (of all tries), SNES converged reason (name)
        """
        if self.snes is None:
            raise RuntimeError("this solver is closed (close()): make a new problem to solve")
        if self.predictor not in (None, "first", "retry"):
            raise ValueError(f"predictor must be 'retry', 'first' or None, got {self.predictor!r}")
        level = self.first_contact_level
        if not (level in (None, "mean") or (isinstance(level, (int, float)) and 0 < level < 1)):
            raise ValueError(
                f"first_contact_level must be 'mean', a fraction in (0, 1) or None, got {level!r}"
            )
        t0 = self.problem.t
        self._B_stale = True  # the fixed parts again on this step's first tangent
        self.problem.set_time(t)
        fem_petsc.assign(self.problem.unknowns, self.x)
        self._shrink_pattern()
        start = self.x.copy()
        if self.predictor == "first":
            self._predict(t0, t)
        loose = self._loose_pairs() if self.close_gaps else []
        opening = []
        if self.first_contact_level and not loose and self.snes.getTolerances()[3] > 2:
            opening = self._open_pairs()
        if loose:  # no Newton step without contact: close first
            reason, its = self._closed_newton(loose)
        elif opening:
            reason, its = self._first_contact_newton(opening)
        else:
            reason, its = self._newton()
        if reason <= 0 and self.predictor == "retry" and not loose:
            start.copy(self.x)
            if self._predict(t0, t):
                reason, more = self._newton()
                its += more
        linesearch = self.snes.getLineSearch()
        primary = linesearch.getType()
        if reason <= 0 and self.fallback_linesearch not in (None, primary):
            start.copy(self.x)
            linesearch.setType(self.fallback_linesearch)
            try:
                reason, more = self._newton()
            finally:
                linesearch.setType(primary)
            its += more
        if reason <= 0 and self.close_gaps and not loose:
            start.copy(self.x)
            open_pairs = self._open_pairs()
            if open_pairs:
                reason, more = self._closed_newton(open_pairs)
                its += more
        self._state = None
        self._set_state(self.x)
        if reason > 0:
            increment = self.x.copy()
            increment.axpy(-1.0, start)
            self._increment = (t0, t, self.x.copy(), increment)
        # PETSc objects of more than one rank dropped by Python (the operators and matrices
        # of the pairings met) wait on their communicator until a collective clean-up:
        # without it they stay in memory (the mesh's communicator, not PETSc's world one)
        PETSc.garbage_cleanup(self.comm)
        names = {v: k for k, v in vars(PETSc.SNES.ConvergedReason).items() if k.isupper()}
        return reason > 0, its, names.get(reason, str(reason))

    def close(self) -> None:
        """Free this solver's PETSc objects now (collective: call it on every rank).

        On more than one rank PETSc frees an object that Python drops only at a collective
        clean-up on its communicator, which for a dropped problem never comes: its SNES,
        factorisation and matrices stay in memory (megabytes for a small problem, far more
        with the factors of a large one: see :doc:`/guide/solvers`). A script that
        makes many problems closes each one when done with it
        (:meth:`ContactProblem.close <contact_ufl.problem.ContactProblem.close>`). The
        solver cannot solve afterwards."""
        if self.snes is None:
            return
        objects = [self.snes, self._J, self._retired, self._A, self._B, self._K, self._JT]
        objects += [self._T, self._T_coupled, self._T_wide, self._r, self.x, self._R, self._state]
        if self._increment is not None:
            objects += list(self._increment[2:])
        for obj in objects:
            if obj is not None:
                obj.destroy()
        self.snes = self._J = self._retired = self._A = self._B = self._K = self._JT = None
        self._T = self._T_coupled = self._T_wide = self._increment = self._state = None
        PETSc.garbage_cleanup(self.comm)

    def _predict(self, t0: float, t: float) -> bool:
        """Move :attr:`x`, the start of the step from ``t0`` to ``t``, to the predicted
        state ``x + (t - t0) / (t_to - t_from) dx``, where the last converged step (from
        ``t_from`` to ``t_to``, increment ``dx``) ended at this start (collective).
        Returns whether it did."""
        if self._increment is None:
            return False
        t_from, t_to, x_to, dx = self._increment
        if t_to == t_from or abs(t_to - t0) > 1e-12 * max(abs(t0), 1.0):
            return False  # a solve at its start's time predicts nothing
        diff = self.x.copy()
        diff.axpy(-1.0, x_to)
        if diff.norm() > 0.0:
            return False
        self.x.axpy((t - t0) / (t_to - t_from), dx)
        return True

    def _open_pairs(self) -> list:
        """The contact pairs with no point in contact at :attr:`x` (collective)."""
        self._state = None
        self._set_state(self.x)
        contacts = self.problem.contacts
        counts = self.comm.allreduce(np.array([c.active().sum() for c in contacts]), MPI.SUM)
        return [c for c, n in zip(contacts, counts, strict=True) if n == 0]

    def _first_contact_newton(self, pairs: list) -> tuple[int, int]:
        """Newton where ``pairs`` have no point in contact at the start: after the first
        (free) iterate, one iterate in which the points of each such pair count as in
        contact only where they overlap the master by more than
        :meth:`_first_contact_overlap` (:meth:`_predictor_iterate`); then Newton. Converged
        reason and iterations (all counted; at most the SNES's ``max_it`` in all, which is
        over 2)."""
        rtol, atol, _, max_it = self.snes.getTolerances()
        self.snes.setTolerances(max_it=1)
        try:
            reason, its = self._newton(partial=True)
            if reason > 0:
                return reason, its
            # the relative tolerance of the later solves refers to the step's start
            self.snes.setTolerances(atol=max(atol, rtol * self.iterates[0][0]))
            self._set_state(self.x)  # the free iterate's search (its last residual's)
            shifted = []
            for c in pairs:
                level = self._first_contact_overlap(c)
                if level > 0.0:
                    c.normal.closing.value = -level
                    shifted.append(c)
            if shifted:
                self._predictor_iterate(shifted)
                its += 1
            self.snes.setTolerances(max_it=max_it - its)  # the try's budget: max_it in all
            reason, more = self._newton()
            its += more
        finally:
            self.snes.setTolerances(atol=atol, max_it=max_it)
            for c in pairs:
                c.normal.closing.value = c.normal.touching
            self._state = None
        return reason, its

    def _first_contact_overlap(self, pair) -> float:
        """The overlap above which the points of ``pair`` count as in contact in the
        predictor iterate (:attr:`first_contact_level`; 0 if none overlaps; collective).

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
        deepest = self.comm.allreduce(normal.deepest_overlap(proj), MPI.MAX)
        if self.first_contact_level != "mean":
            return float(self.first_contact_level) * deepest
        moments = normal.overlap_moments(proj, pair.slave.point_weights)
        total, measure = self.comm.allreduce(moments, MPI.SUM)
        if measure == 0.0 or deepest == 0.0:
            return 0.0
        m = total / measure / deepest
        return deepest * max(min(m, 7.0 * (0.8 - m)), 0.0)

    def _predictor_iterate(self, shifted: list) -> None:
        """One iterate from :attr:`x` with the shifted contact law of ``shifted`` (their
        ``closing`` set), kept unless it leaves the residual of the contact law above
        :data:`_PREDICTOR_GROWTH` times that at :attr:`x` (or not a number), else undone
        (collective)."""
        before = self.iterates[-1][0]  # the residual at x (the free iterate's last)
        free = self.x.copy()
        try:
            self._newton(partial=True)
            for c in shifted:
                c.normal.closing.value = c.normal.touching
            self._state = None
            F = self.evaluate_residual(self.x)
            after = F.norm()
            F.destroy()
            if not after < _PREDICTOR_GROWTH * before:  # or not a number: back
                free.copy(self.x)
        finally:
            free.destroy()

    def _closed_newton(self, pairs: list) -> tuple[int, int]:
        """A closing iterate on ``pairs``, then Newton: converged reason and iterations
        (the closing iterate counted)."""
        self._closing_iterate(pairs)
        reason, its = self._newton()
        return reason, 1 + its

    def _loose_pairs(self) -> list:
        """The contact pairs to close before the first try (collective): the pairs with no
        point in contact at :attr:`x` on a piece held by no point in contact, with free
        rigid modes (translations, rotations) along which the residual at :attr:`x` has a
        net load (force, moment over the piece's size) above the absolute tolerance
        (:mod:`contact_ufl.free_bodies`): there the tangent is singular and the Newton
        equation has no solution."""
        problem = self.problem
        if not self._free_pieces():
            return []
        self._state = None  # the search at the step's time (a rigid obstacle moves)
        residual = self.evaluate_residual(self.x).array_r
        counts = self.comm.allreduce(
            np.array([c.active().sum() for c in problem.contacts]), MPI.SUM
        )
        atol = self.snes.getTolerances()[0]
        loose = set()
        for piece, on in self._pieces:
            if np.any(counts[on] > 0):
                continue  # a point in contact holds the piece
            if free_bodies.net_free_load(problem, residual, piece) > atol:
                loose.update(on)
        return [c for k, c in enumerate(problem.contacts) if k in loose]

    def _closing_iterate(self, pairs: list) -> None:
        """One Newton iterate from :attr:`x` in which the open points of ``pairs`` near the
        master surface count as in contact (see :meth:`solve_step`)."""
        self._set_state(self.x)  # the search of :meth:`_open_pairs` at x, if still current
        for c in pairs:
            nearest = self.comm.allreduce(c.normal.nearest_open_gap(c.projection), MPI.MIN)
            if np.isfinite(nearest):
                c.normal.closing.value = max(2.0 * nearest, 0.1 * c.slave.facet_size)
        max_it = self.snes.getTolerances()[3]
        self.snes.setTolerances(max_it=1)
        try:
            self._newton()
        finally:
            self.snes.setTolerances(max_it=max_it)
            for c in pairs:
                c.normal.closing.value = c.normal.touching
            self._state = None

    def _monitor(self, snes, its: int, norm: float) -> None:
        """Record the residual norm and the contact state of each Newton iterate (the
        pairing, the contact status and, with friction, the stick/slip status)."""
        state = [
            np.concatenate(
                [c.projection.facet, c.active().astype(np.int64)]
                + ([c.stick().astype(np.int64)] if c.friction else [])
            )
            for c in self.problem.contacts
            if c.projection is not None
        ]
        signature = hash(np.concatenate(state).tobytes()) if state else 0
        self.iterates.append((float(norm), signature))

    def diagnose(self) -> str:
        """Why the last Newton solve failed, at its last iterate (collective): inverted
        elements (and where), contact pairing or status that cycles between iterates, or a
        residual that stalls with neither (a limit point, or a singular tangent); otherwise
        how far the residual fell and in how many iterates the contact state changed. Where
        a piece of a mesh with contact pairs is free to turn (no support holds a rotation,
        :mod:`contact_ufl.free_bodies`), the diagnosis says so and where it turns."""
        return self._diagnosis() + self._turning_hint()

    def _free_pieces(self) -> list:
        """(piece, its pairs) of the pieces with a free rigid mode and contact pairs."""
        if self._pieces is None:  # those the problem found when it was made
            self._pieces = [(piece, on) for piece, on in self.problem.free_pieces if on]
        return self._pieces

    def _turning_hint(self) -> str:
        """The hint for a piece free to turn (the same on every rank)."""
        hints = []
        for piece, on in self._free_pieces():
            if not piece.rotates:
                continue
            point = piece.turning_point()
            about = "" if point is None else " about (" + ", ".join(f"{v:.3g}" for v in point) + ")"
            pairs = ", ".join(self.problem.contacts[k].pair.surface("slave") for k in on)
            hints.append(
                f"; the body with the contact pair(s) of slave surface {pairs} is free to turn"
                f"{about}: no support holds that rotation, only the contact, which a "
                "frictionless contact of a curved surface may not (the tangent is then near "
                "singular): hold it by a support"
            )
        return "".join(hints)

    def _diagnosis(self) -> str:
        from contact_ufl.results import inverted_cell_centres

        centres = inverted_cell_centres(self.problem)
        if not len(centres) and self._not_finite is not None:
            centres = self._not_finite  # the trial iterate the line search rejected
        if len(centres):
            where = ", ".join("(" + ", ".join(f"{v:.3g}" for v in c) + ")" for c in centres[:3])
            return f"inverted elements in {len(centres)} cells, e.g. at {where}"
        signatures = [s for _, s in self.iterates]
        revisits = any(
            signatures[k] in signatures[: k - 1] and signatures[k] != signatures[k - 1]
            for k in range(2, len(signatures))
        )
        if self.comm.allreduce(revisits, MPI.LOR):
            return (
                "the contact pairing or status cycles: an iterate returns to the contact state "
                "of an earlier one (active-set cycling)" + self._normal_hint()
            )
        changed = np.array([a != b for a, b in zip(signatures, signatures[1:], strict=False)])
        changes = int(np.count_nonzero(self.comm.allreduce(changed.astype(np.int64), MPI.SUM)))
        if changes == 0 and len(signatures) > 2:
            return (
                "the residual stalls with no inverted element and no change of contact state: "
                "a limit point or a singular tangent (a load beyond a maximum, a body free "
                "to move)"
            )
        norms = [r for r, _ in self.iterates]
        state = (
            f"the contact pairing or status changing in {changes} of them"
            if changes
            else "no change of contact state"
        )
        fell = (
            f": it fell from {norms[0]:.3g} to {norms[-1]:.3g} in {len(norms) - 1} iterates, "
            + state
            if len(norms) > 1
            else ""
        )
        return f"the residual does not converge (no inverted element, no contact cycling){fell}"

    def _normal_hint(self) -> str:
        """The hint for active-set cycling where a pair could have the smoothed master
        normal and has the facet one (a solid master of a degree-1 displacement; the same on
        every rank: the pairs are)."""
        faceted = [
            c.pair.surface("master")
            for c in self.problem.contacts
            if not c.pair.on_obstacle
            and c.pair.master_normal == "facet"
            and not (c.master.two_sided or c.pair.self_contact)
            and c.V.ufl_element().embedded_superdegree == 1
        ]
        if not faceted:
            return ""
        return (
            f"; the master surface {', '.join(faceted)} has the facet normal, which jumps "
            'at every facet edge: master_normal="smoothed" in its ContactPair removes those '
            "jumps (continuous normal from facet to facet)"
        )

    def _newton(self, partial: bool = False) -> tuple[int, int]:
        """One SNES solve from :attr:`x`: converged reason and iterations. ``partial``: a
        solve cut short on purpose (``max_it`` set low, the first-contact iterates), whose
        factorisation and contact state at :attr:`x` the next solve may keep (a failed
        solve's factorisation is reset, and a solve's first residual searches anew)."""
        if not partial:
            self._state = None
        self.iterates = []
        self._not_finite = None  # inverted cells of an iterate whose residual is NaN/inf
        self._callback_error = None
        start = time.perf_counter()
        self._in_snes = True
        try:
            self.snes.solve(None, self.x)
            reason = self.snes.getConvergedReason()
        except PETSc.Error as error:  # e.g. a failed factorisation: a failed step, not a crash
            if self.problem.verbose and self.comm.rank == 0:
                print(f"  PETSc error in the Newton solve: {error}", flush=True)
            reason = PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
        finally:
            self._in_snes = False
            self.timings.newton += time.perf_counter() - start
        if self._callback_error is not None:
            # an exception in a callback is not a failed try: PETSc would have kept the
            # iterate's vector locked (every later try failing), and it names the problem
            error, self._callback_error = self._callback_error, None
            raise error
        self.timings.iterations += self.snes.getIterationNumber()
        if reason <= 0:
            if not partial:
                self._reset_pc()  # no stale factorisation in the next try
        return reason, self.snes.getIterationNumber()

    @property
    def residual_norm(self) -> float:
        """Norm of the residual at the end of the last Newton solve."""
        return self.snes.getFunctionNorm()
