"""The discrete contact operator: residual ``T^T r`` and tangent ``T^T K T`` of an iterate.

The residual and Jacobian forms of a problem are assembled over the fields ``[u, xhat_1,
lambda_1, ...]``; the chain operator ``T`` of :mod:`contact_ufl.layout` (identity on the
unknowns, the gathers ``xhat = Xhat + P u``) maps them onto the unknowns ``[u, lambda_1,
...]``: residual ``T^T r``, tangent ``T^T K T`` (the tangent's blocks between two unknowns,
the bulk's among them, are assembled straight into the solver matrix: ``T`` maps them by the
identity). :class:`ContactOperator` owns the state of an iterate: the unknowns set into the
fields, the couplings' search and gathers (:mod:`contact_ufl.coupling`), ``T``, and the
solver matrix with its sparsity plan (:mod:`contact_ufl.sparsity`). The search runs at every
new state; ``T`` and the tangent's pattern change only when the pairing does, the solver
matrix's pattern only when a pairing leaves the plan's superset and its product adds a
nonzero to the matrix.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import dolfinx
import dolfinx.fem.petsc as fem_petsc
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import assembly, keysets
from contact_ufl.coupling import Coupling, Gather
from contact_ufl.layout import StackedLayout, chain_operator, split_tangent
from contact_ufl.sparsity import SolverPattern, nonzero_keys
from contact_ufl.timings import NewtonTimings


@dataclass
class DirichletRows:
    """The prescribed rows of the unknowns: ``k (x_i - g_i) = 0``.

    Attributes
    ----------
    rows
        Local (owned) indices of the prescribed rows in a vector of the unknowns.
    scale
        The stiffness ``k`` of their equations (every row of the residual a force).
    values
        ``values()``: the prescribed values ``g`` of those rows at the current pseudo-time.
    """

    rows: np.ndarray
    scale: float
    values: Callable[[], np.ndarray]


@dataclass
class AssembledSystem:
    """What the operator assembles: the fields, the unknowns and the compiled forms.

    Attributes
    ----------
    fields, unknowns
        The assembled fields ``[u_1, ..., u_m, xhat_1, lambda_1, ...]`` and the unknowns
        ``[u_1, ..., u_m, lambda_1, ...]``.
    layout, full_layout
        Numbering of the unknowns and of the fields.
    residual_form, jacobian_form
        Compiled blocked residual (rows: ``fields``) and Jacobian (``fields`` x ``fields``),
        each block a list of parts (:mod:`contact_ufl.assembly`).
    couplings
        The contact interfaces, then the volume controls.
    dirichlet
        The prescribed rows.
    meshes
        How many of the unknowns are displacements (the first).
    """

    fields: list[dolfinx.fem.Function]
    unknowns: list[dolfinx.fem.Function]
    layout: StackedLayout
    full_layout: StackedLayout
    residual_form: list
    jacobian_form: list
    couplings: Sequence[Coupling]
    dirichlet: DirichletRows
    meshes: int


class ContactOperator:
    """The residual and tangent of a contact problem at an iterate of its unknowns.

    Parameters
    ----------
    system
        Fields, unknowns, forms, couplings and prescribed rows.
    pattern_superset
        Whether the solver matrix's pattern holds the facets beside each point's facet
        (:class:`~contact_ufl.sparsity.SolverPattern`; the problem's default: in 2D).
    timings
        Where the search and assembly times are added.

    Attributes
    ----------
    x
        The unknowns ``[u, lambda_1, ...]`` (a PETSc vector; the problem's functions hold
        the same values at the current state).
    matrix
        The solver matrix (its pattern that of :attr:`pattern`).
    pattern
        The sparsity plan of :attr:`matrix`.
    pattern_version
        A number that changes whenever :attr:`matrix` is another matrix or its pattern grew
        (the factorisation must be analysed again).
    """

    def __init__(
        self,
        system: AssembledSystem,
        pattern_superset: bool,
        timings: NewtonTimings | None = None,
    ):
        self.system = s = system
        self.comm = s.layout.comm
        self.timings = NewtonTimings() if timings is None else timings
        self._field_index = {id(f): k for k, f in enumerate(s.fields)}
        self._field_residual = fem_petsc.create_vector(
            [f.function_space for f in s.fields], kind="mpi"
        )
        # the tangent's blocks between unknowns go straight into the solver matrix (T maps
        # them by the identity; _unknown_blocks: their pattern and the local-to-global maps
        # of that assembly); only the blocks of the gathered fields go through T^T K T
        self._unknown_forms, self._gathered_forms, self._coupled = split_tangent(
            s.jacobian_form, s.fields, s.unknowns
        )
        self._unknown_blocks = None
        # the parts of those blocks fixed by the mesh (a linear-elastic bulk's stiffness):
        # assembled once a load step (on the unknown blocks' pattern), added to every tangent
        # of the step
        self._fixed_blocks = self._varying_forms = self._fixed_forms = None
        self._fixed_blocks_stale = True
        if self._unknown_forms is not None:
            self._unknown_blocks = assembly.create_matrix_with_pattern(self._unknown_forms)
            fixed, self._varying_forms = assembly.split_constant(self._unknown_forms)
            if any(parts for row in fixed for parts in row):
                self._fixed_blocks = self._unknown_blocks.duplicate()  # zero values
                self._fixed_forms = fixed
        self._gathered_tangent = self._coupled_layout = None
        if self._gathered_forms is not None:
            coupled = [s.fields[i].function_space for i in self._coupled]
            # the gathered blocks couple the point data (the master nodes at each slave
            # point) only point by point: K's pattern without the rest (fewer nonzeros to
            # assemble and multiply)
            full = assembly.create_matrix_with_pattern(self._gathered_forms)
            self._gathered_tangent = assembly.without_cross_point_couplings(full, coupled)
            full.destroy()
            self._coupled_layout = StackedLayout(coupled)
        self.x = fem_petsc.create_vector([f.function_space for f in s.unknowns], kind="mpi")
        fem_petsc.assign(s.unknowns, self.x)
        self.residual_vector = self.x.duplicate()
        self.matrix: PETSc.Mat | None = None
        self.pattern = SolverPattern(self.comm, pattern_superset)
        self.pattern_version = 0
        self._T = None  # the chain operator onto every field (the residual's)
        self._T_coupled = None  # its rows of the fields the gathered blocks couple
        self._T_pattern = None  # the superset operator of the solver matrix's pattern
        self._chained_tangent = None  # T^T K T of the gathered blocks
        self._gather_columns = None  # the columns of the last gathers (did they change?)
        self._gathers: list[list[Gather]] | None = None
        self._state = None  # the unknowns of the current state

    # -- state, search and the chain operator -----------------------------------------
    def read_unknowns(self) -> None:
        """Set :attr:`x` to the values of the problem's unknowns (the state they hold)."""
        fem_petsc.assign(self.system.unknowns, self.x)

    def set_state(self, x: PETSc.Vec) -> None:
        """Set the problem's unknowns to ``x`` and update the pairing there (nothing if
        ``x`` is the current state)."""
        if self._state is not None and x.equal(self._state):
            return
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        fem_petsc.assign(x, self.system.unknowns)
        for f in self.system.unknowns:
            f.x.scatter_forward()
        self.update_pairing(x)
        self._state = x.copy()

    def replan(self) -> None:
        """Forget the pairings met: the chain operator and the sparsity plan are made anew
        at the next :meth:`update_pairing`, the solver matrix at the next tangent (a
        restart point)."""
        self.pattern = SolverPattern(self.comm, self.pattern.superset, self.pattern.slack)
        self._T = self._T_coupled = self._T_pattern = self._chained_tangent = None
        self._gather_columns = self._gathers = self._state = None
        self._fixed_blocks_stale = True

    def forget_state(self) -> None:
        """Make the next evaluation redo the search even at an unchanged state."""
        self._state = None

    def update_pairing(self, x: PETSc.Vec) -> None:
        """Update the couplings at ``x`` (the search), and ``T`` where the pairing changed
        (collective)."""
        start = time.perf_counter()
        couplings = self.system.couplings
        gathers = [c.update(x, self.system.layout) for c in couplings]
        columns = [cols for g in gathers for _, cols in g]
        columns = np.concatenate(columns) if columns else np.zeros(0, np.int64)
        changed = self._gather_columns is None or not np.array_equal(columns, self._gather_columns)
        if self.comm.allreduce(changed, MPI.LOR):
            self._gather_columns = columns
            self._T = self._chain_operator(gathers)
            self._T_coupled = self._chain_operator(gathers, self._coupled)
            self._chained_tangent = None
            self._gathers = gathers
            self._widen()
        self.timings.search += time.perf_counter() - start
        self.timings.searches += 1

    def _gather_keys(self, gathers: list[list[Gather]]) -> np.ndarray:
        """Sorted keys ``row * N + column`` of the gathered entries of ``T`` (local rows)."""
        offsets = np.concatenate([[0], np.cumsum(self.system.full_layout.local_sizes)])
        n = self.system.layout.global_size
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
        gathers = self._gathers
        if self.pattern.current_keys is not None and self.pattern.holds(self._gather_keys(gathers)):
            return
        if self.pattern.superset:
            wide = [c.pattern_gathers() for c in self.system.couplings]
        else:
            wide = gathers
        # without the superset (3D) the pattern's operator is T itself: its product
        # T^T K T is then the tangent's, not a second PtAP
        same = all(w is g for w, g in zip(wide, gathers, strict=True))
        self._T_pattern = self._T_coupled if same else self._chain_operator(wide, self._coupled)
        self.pattern.widen(self._gather_keys(wide))

    def _chain_operator(self, gathers: list[list[Gather]], rows: list[int] | None = None):
        """``T``: identity from each unknown to its assembled field, gathers for the others;
        its rows of the fields ``rows`` (indices in the fields; default: all). ``None`` for
        no rows."""
        s = self.system
        if rows is not None and not rows:
            return None
        fields = s.fields
        rows = range(len(fields)) if rows is None else rows
        layout = s.full_layout if len(rows) == len(fields) else self._coupled_layout
        block = {id(fields[i]): k for k, i in enumerate(rows)}
        unknown_index = {id(f): k for k, f in enumerate(s.unknowns)}
        identity = [(block[k], unknown_index[k]) for k in block if k in unknown_index]
        gather_blocks, gather_cols = [], []
        for g in gathers:
            for f, cols in g:
                if id(f) in block:
                    gather_blocks.append(block[id(f)])
                    gather_cols.append(cols)
        return chain_operator(layout, s.layout, identity, gather_blocks, gather_cols)

    # -- residual -----------------------------------------------------------------------
    def assemble(self, forms, out: PETSc.Vec | None = None) -> PETSc.Vec:
        """Assemble the linear ``forms`` (rows: the fields) at the current state and map
        them to the unknowns, ``T^T r``.

        Parameters
        ----------
        forms
            A compiled blocked linear form over the fields, each block a list of parts
            (:mod:`contact_ufl.assembly`).
        out
            The result (default: a new vector of the unknowns).
        """
        out = self.residual_vector.duplicate() if out is None else out
        r = self._field_residual
        with r.localForm() as r_local:
            r_local.set(0.0)
        assembly.assemble_vector(r, forms)
        r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self._T.multTranspose(r, out)
        return out

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        """``F``: the residual ``T^T r`` at the unknowns ``x``, with the prescribed rows."""
        self.set_state(x)
        start = time.perf_counter()
        self.assemble(self.system.residual_form, F)
        dirichlet = self.system.dirichlet
        if len(dirichlet.rows):
            u = x.array_r[dirichlet.rows]
            F.array[dirichlet.rows] = dirichlet.scale * (u - dirichlet.values())
        self.timings.residual_assembly += time.perf_counter() - start
        self.timings.residuals += 1

    def evaluate_residual(self, x: PETSc.Vec) -> PETSc.Vec:
        """The residual at the unknowns ``x`` (a new vector); sets the state to ``x``."""
        F = self.residual_vector.duplicate()
        self.residual(x, F)
        return F

    # -- tangent ------------------------------------------------------------------------
    def jacobian(self, x: PETSc.Vec) -> tuple[PETSc.Mat, int]:
        """The tangent ``T^T K T`` at the unknowns ``x`` in the solver matrix, and
        :attr:`pattern_version`."""
        self.set_state(x)
        self._assemble_tangent()
        return self.matrix, self.pattern_version

    def evaluate_jacobian(self, x: PETSc.Vec) -> PETSc.Mat:
        """The tangent at the unknowns ``x`` (the solver matrix); sets the state to ``x``."""
        return self.jacobian(x)[0]

    def first_tangent(self) -> None:
        """Make the solver matrix and assemble the tangent at the current state."""
        self._assemble_tangent(first=True)

    def begin_step(self) -> None:
        """A load step begins: the fixed parts again on its first tangent, and the solver
        matrix rebuilt on the current superset where the union of the patterns met has
        grown beyond the plan's slack (collective)."""
        self._fixed_blocks_stale = True
        if self._chained_tangent is None or self._T_pattern is None or not self.pattern.overgrown():
            return
        self.pattern.forget()
        self._widen()
        J = self._grown_matrix(new=True)
        self._assemble_unknown_blocks(J)
        self._add_gathered_blocks(J)
        self.matrix = J

    def _assemble_tangent(self, first: bool = False) -> None:
        start = time.perf_counter()
        K = self._gathered_tangent
        if K is not None:
            K.zeroEntries()
            assembly.assemble_matrix(K, self._gathered_forms)
            K.assemble()
        assembled = time.perf_counter()
        if K is not None:
            if self._chained_tangent is None:
                self._chained_tangent = K.PtAP(self._T_coupled)
                self.timings.new_patterns += 1
            else:
                K.PtAP(self._T_coupled, result=self._chained_tangent)
        J = self._grown_matrix(first)
        multiplied = time.perf_counter()
        self._assemble_unknown_blocks(J)
        own = time.perf_counter()
        self._add_gathered_blocks(J)
        self.timings.jacobian_assembly += (assembled - start) + (own - multiplied)
        self.timings.ptap += (multiplied - assembled) + (time.perf_counter() - own)
        self.timings.jacobians += 1
        self.matrix = J

    def _assemble_unknown_blocks(self, J: PETSc.Mat) -> None:
        """The tangent's blocks between unknowns, straight into ``J`` (its values zeroed):
        the fixed parts (assembled on the first tangent of a load step), then the others."""
        J.zeroEntries()
        if self._unknown_blocks is None:
            return
        if self._fixed_blocks is not None:
            if self._fixed_blocks_stale:
                self._fixed_blocks.zeroEntries()
                assembly.assemble_matrix(self._fixed_blocks, self._fixed_forms, self._unknown_forms)
                self._fixed_blocks.assemble()
                self._fixed_blocks_stale = False
            J.axpy(1.0, self._fixed_blocks, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        assembly.assemble_matrix(J, self._varying_forms, self._unknown_forms)
        J.assemble()

    def _add_gathered_blocks(self, J: PETSc.Mat) -> None:
        """Add ``T^T K T`` of the gathered blocks to ``J``, then the prescribed rows."""
        if self._chained_tangent is not None:
            J.axpy(1.0, self._chained_tangent, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        layout, dirichlet = self.system.layout, self.system.dirichlet
        rows = (layout.rank_offsets[layout.rank] + dirichlet.rows).astype(PETSc.IntType)
        J.zeroRows(rows, diag=dirichlet.scale)

    def _grown_matrix(self, new: bool = False) -> PETSc.Mat:
        """The solver matrix, its pattern grown by that of the superset operator where a
        pairing left it (a ``new`` matrix: on that pattern only). Its pattern holds
        ``T^T K T``'s: ``T`` is within the superset operator."""
        plan = self.pattern
        new = new or plan.product_keys is None  # a plan without its matrix yet
        if not (plan.must_grow or new):
            return self.matrix
        product = None  # the gathered blocks' T^T K T over the superset operator
        tangent = self._T_pattern is self._T_coupled and self._chained_tangent is not None
        if self._gathered_tangent is not None:
            product = (
                self._chained_tangent if tangent else self._gathered_tangent.PtAP(self._T_pattern)
            )
        keys = nonzero_keys(product)
        rebuild = new or plan.overgrown()
        if not rebuild and plan.within_matrix(keys):
            # the superset left, but its product is not: the solver matrix and its
            # factorisation's symbolic analysis hold (no new nonzero)
            if product is not None and not tangent:
                product.destroy()
            plan.must_grow = False
            return self.matrix
        if rebuild:  # on the current superset only
            J = self._new_matrix(product)
            plan.rebuilt(keys)
        else:
            J = self.matrix
            J.zeroEntries()
            if product is not None:
                J.axpy(1.0, product, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            plan.grown(keys)
        if product is not None and not tangent:
            product.destroy()
        if self._unknown_blocks is not None:  # the maps of the unknowns' blocks' assembly into J
            J.setLGMap(*self._unknown_blocks.getLGMap())
        J.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        self.timings.analyses += 1
        self.pattern_version += 1
        return J

    def _new_matrix(self, product: PETSc.Mat | None) -> PETSc.Mat:
        """A solver matrix on the pattern of the unknowns' blocks and ``product``."""
        if self._unknown_blocks is None:
            return product.duplicate()
        J = self._unknown_blocks.duplicate()
        if product is not None:
            J.axpy(1.0, product, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        return J

    # -- the linear solver's view -------------------------------------------------------
    def has_multipliers(self) -> bool:
        """Whether the unknowns hold more than the displacements (multipliers, a control's
        load factor) on some rank (collective)."""
        s = self.system
        local = int(s.layout.local_sizes[s.meshes :].sum())
        return self.comm.allreduce(local, MPI.SUM) > 0

    def field_splits(self, gdim: int) -> list[tuple[str, PETSc.IS]] | None:
        """The splits of a ``pc_type fieldsplit``: ``u``, the displacements of the meshes
        (block size ``gdim``, for GAMG), and ``lambda``, the other unknowns (the
        multipliers; a control's load factor); ``None`` without multipliers (one field).
        Their solvers take the options ``<prefix>fieldsplit_u_...`` and
        ``<prefix>fieldsplit_lambda_...`` (collective)."""
        if not self.has_multipliers():
            return None
        layout, meshes = self.system.layout, self.system.meshes
        blocks = [layout.owned(b, np.arange(n)) for b, n in enumerate(layout.local_sizes)]
        u = np.concatenate(blocks[:meshes]).astype(PETSc.IntType)
        rest = np.concatenate([np.zeros(0, np.int64), *blocks[meshes:]]).astype(PETSc.IntType)
        displacements = PETSc.IS().createGeneral(u, comm=self.comm)
        displacements.setBlockSize(gdim)
        return [("u", displacements), ("lambda", PETSc.IS().createGeneral(rest, comm=self.comm))]

    def close(self) -> None:
        """Free the PETSc objects now (collective)."""
        objects = [
            self.matrix,
            self._unknown_blocks,
            self._fixed_blocks,
            self._gathered_tangent,
            self._chained_tangent,
            self._T,
            self._T_coupled,
        ]
        objects += [
            self._T_pattern,
            self._field_residual,
            self.x,
            self.residual_vector,
            self._state,
        ]
        for obj in objects:
            if obj is not None:
                obj.destroy()
        self.matrix = self._unknown_blocks = self._fixed_blocks = self._gathered_tangent = (
            self._chained_tangent
        ) = None
        self._T = self._T_coupled = self._T_pattern = self._state = None
