"""The contact problem: forms of a scene, PETSc SNES Newton, load stepping with cut-back.

Data flow: scene -> forms (bulk in UFL, contact terms of :mod:`contact_ufl.contact`) ->
assembled system over ``[u, xhat_1, lambda_1, ...]`` -> chain rule ``T^T r``, ``T^T K T``
onto the unknowns ``[u, lambda_1, ...]`` -> SNES.
"""

from __future__ import annotations

import time
import weakref
from collections.abc import Callable
from dataclasses import dataclass, field

import dolfinx
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl.contact import ContactInterface, ContactPair
from contact_ufl.errors import ConvergenceError
from contact_ufl.layout import StackedLayout, chain_operator
from contact_ufl.loads import BodyForce, deformation_gradient, evaluate, load_constant
from contact_ufl.mpi import global_bounds
from contact_ufl.plasticity import J2Plasticity, PlasticHistory
from contact_ufl.scene import Scene

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


@dataclass
class StepRecord:
    """What happened in one accepted load step."""

    step: int
    t: float
    newton_iterations: int
    residual: float
    active_points: int
    contact_force: np.ndarray
    wall_s: float


@dataclass
class History:
    """Accepted steps and cut-backs of a run."""

    steps: list[StepRecord] = field(default_factory=list)
    cutbacks: list[tuple[float, str]] = field(default_factory=list)


def _weakly(method: Callable) -> Callable:
    """A callback calling the bound ``method`` through a weak reference to its object."""
    ref = weakref.WeakMethod(method)

    def call(*args):
        return ref()(*args)

    return call


def softer_modulus(scene: Scene, pair: ContactPair) -> float:
    """The smallest Young's modulus of the bodies whose cells hold the facets of ``pair``."""
    mesh = scene.mesh
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    facets = np.concatenate([scene.facet_tags.find(pair.slave), scene.facet_tags.find(pair.master)])
    cells = f2c.array[f2c.offsets[facets]]
    num_cells = mesh.topology.index_map(tdim).size_local + mesh.topology.index_map(tdim).num_ghosts
    cell_tag = np.full(num_cells, -1, dtype=np.int64)
    cell_tag[scene.cell_tags.indices] = scene.cell_tags.values
    found = mesh.comm.allreduce(set(cell_tag[cells].tolist()), MPI.BOR)
    moduli = [b.material.E for b in scene.bodies if b.tag in found]
    return min(moduli) if moduli else float("nan")


def _nonempty(form: ufl.Form) -> ufl.Form | None:
    form = ufl.algorithms.expand_derivatives(form)
    return None if form.empty() else form


class ContactProblem:
    """Quasi-static large-deformation contact of the bodies of a scene.

    Parameters
    ----------
    scene
        Mesh, bodies, supports, loads and contact pairs.
    degree
        Polynomial degree of the displacement.
    quadrature_degree
        Quadrature degree of the bulk integrals (default: exact for P1 simplices, ``2 p``
        otherwise).
    petsc_options
        PETSc options (SNES, KSP, PC) overriding :data:`DEFAULT_PETSC_OPTIONS`.
    petsc_options_prefix
        Prefix of those options in the PETSc options database.
    verbose
        Print one line per load step (rank 0).
    """

    def __init__(
        self,
        scene: Scene,
        degree: int = 1,
        quadrature_degree: int | None = None,
        petsc_options: dict | None = None,
        petsc_options_prefix: str = "contact_",
        verbose: bool = True,
    ):
        scene.validate()
        self.scene = scene
        mesh = scene.mesh
        self.comm = mesh.comm
        self.verbose = verbose
        gdim = mesh.geometry.dim
        self.V = dolfinx.fem.functionspace(mesh, ("Lagrange", degree, (gdim,)))
        self.u = dolfinx.fem.Function(self.V, name="displacement")
        simplex = mesh.topology.cell_type in (
            dolfinx.mesh.CellType.triangle,
            dolfinx.mesh.CellType.tetrahedron,
        )
        qdeg = quadrature_degree or (2 * degree - 1 if simplex else 2 * degree)
        self.dx = ufl.Measure(
            "dx", domain=mesh, subdomain_data=scene.cell_tags, metadata={"quadrature_degree": qdeg}
        )
        self.ds = ufl.Measure("ds", domain=mesh, subdomain_data=scene.facet_tags)
        self.t = 0.0
        self._energy_form = None
        #: history of the elastoplastic bodies, by cell tag (moved on each converged step)
        self.histories = {
            b.tag: PlasticHistory(b.material, self.u, qdeg, scene.cell_tags.find(b.tag))
            for b in scene.bodies
            if isinstance(b.material, J2Plasticity)
        }
        self.contacts = [
            ContactInterface(self.u, scene.facet_tags, p, softer_modulus(scene, p))
            for p in scene.contacts
        ]
        self._build_forms()
        self._build_dirichlet()
        self._build_solver(petsc_options or {}, petsc_options_prefix)
        self.history = History()
        #: line search of the second try of a failed Newton solve (see :meth:`solve_step`)
        self.fallback_linesearch: str | None = "bt"

    # -- forms ------------------------------------------------------------------------
    def first_piola(self, body) -> ufl.core.expr.Expr:
        """First Piola-Kirchhoff stress of ``body`` at the current displacement (and, for an
        elastoplastic body, the history of the last converged step)."""
        if body.tag in self.histories:
            return self.histories[body.tag].first_piola()
        return body.material.first_piola(deformation_gradient(self.u))

    def _build_forms(self) -> None:
        u, v = self.u, ufl.TestFunction(self.V)
        F_u = sum(
            ufl.inner(self.first_piola(b), ufl.grad(v)) * self.dx(b.tag) for b in self.scene.bodies
        )
        self._load_constants = []
        for load in self.scene.loads:
            c = load_constant(self.V.mesh, load)
            self._load_constants.append((load, c))
            measure = self.dx if isinstance(load, BodyForce) else self.ds
            F_u -= load.virtual_work(u, v, measure, c)
        residuals = [F_u]
        contact_residuals = [0]
        fields, unknowns = [u], [u]
        for c in self.contacts:
            Fu_c, F_fields = c.residuals(v)
            residuals[0] = residuals[0] + Fu_c
            contact_residuals[0] = contact_residuals[0] + Fu_c
            residuals += F_fields
            contact_residuals += F_fields
            fields += c.fields
            unknowns += c.unknowns
        self.fields, self.unknowns = fields, unknowns
        self._field_index = {id(f): k for k, f in enumerate(fields)}
        jacobian = [
            [_nonempty(ufl.derivative(Fi, f, ufl.TrialFunction(f.function_space))) for f in fields]
            for Fi in residuals
        ]
        entity_maps = [c.slave.entity_map for c in self.contacts]
        self.residual_form = dolfinx.fem.form(residuals, entity_maps=entity_maps)
        self._contact_residual_ufl = contact_residuals
        self._contact_residual_form = None
        self._load_resultant_forms = None
        self.jacobian_form = dolfinx.fem.form(jacobian, entity_maps=entity_maps)
        spaces = [f.function_space for f in fields]
        self.full_layout = StackedLayout(spaces)
        self.layout = StackedLayout([f.function_space for f in unknowns])
        self._r = fem_petsc.create_vector(spaces, kind="mpi")
        self._K = fem_petsc.create_matrix(self.jacobian_form, kind="mpi")

    def _build_dirichlet(self) -> None:
        mesh, fdim = self.V.mesh, self.V.mesh.topology.dim - 1
        gdim = mesh.geometry.dim
        self._bc_dofs, self._bc_values = [], []
        owned = self.V.dofmap.index_map.size_local * gdim
        for bc in self.scene.dirichlet:
            facets = self.scene.facet_tags.find(bc.tag)
            comps = range(gdim) if bc.component is None else [bc.component]
            for i in comps:
                blocks = dolfinx.fem.locate_dofs_topological(self.V.sub(i), fdim, facets)
                dofs = blocks[blocks < owned]
                self._bc_dofs.append(dofs)
                self._bc_values.append((bc, i))
        # prescribed-displacement equations k (u - g) = 0 are scaled by a stiffness k = E L^(d-2)
        # so that every row of the residual is a force (one absolute tolerance for all)
        size, E = self._scales()
        self._bc_scale = E * size ** (gdim - 2)
        self._bc_rows = (
            np.concatenate(self._bc_dofs).astype(np.int64)
            if self._bc_dofs
            else np.zeros(0, np.int64)
        )

    def _prescribed(self, t: float) -> np.ndarray:
        values = []
        for dofs, (bc, i) in zip(self._bc_dofs, self._bc_values, strict=True):
            value = evaluate(bc.value, t)
            value = value if bc.component is not None or value.ndim == 0 else value[i]
            values.append(np.full(len(dofs), float(value)))
        return np.concatenate(values) if values else np.zeros(0)

    # -- solver -----------------------------------------------------------------------
    def _build_solver(self, options: dict, prefix: str) -> None:
        self.x = fem_petsc.create_vector([f.function_space for f in self.unknowns], kind="mpi")
        fem_petsc.assign(self.unknowns, self.x)
        self._R = self.x.duplicate()
        self._J = None
        self._T = None
        self._JT = None
        self._pattern = None
        self._state = None
        self._update_contact(self.x)
        for c in self.contacts:  # the initial state is the converged state of step 0
            c.commit(self.x)
            c.begin_step()
        self._state = None
        self._update_contact(self.x)
        self._J = self._assemble_jacobian_matrix(first=True)
        self.snes = PETSc.SNES().create(self.comm)
        self.snes.setOptionsPrefix(prefix)
        opts = PETSc.Options()
        for key, value in {
            **DEFAULT_PETSC_OPTIONS,
            "snes_atol": self._default_atol(),
            **options,
        }.items():
            opts[f"{prefix}{key}"] = value
        # weak callbacks: the solver must not keep the problem (and its meshes, spaces and
        # communicators) alive through a reference cycle that Python's collector cannot see
        self.snes.setFunction(_weakly(self._residual), self._R)
        self.snes.setJacobian(_weakly(self._jacobian), self._J)
        self.snes.setFromOptions()
        self.snes.getKSP().setFromOptions()

    def _scales(self) -> tuple[float, float]:
        """The scene's diameter L and largest Young's modulus E."""
        lo, hi = global_bounds(self.comm, self.V.mesh.geometry.x)
        return float(np.linalg.norm(hi - lo)), max(b.material.E for b in self.scene.bodies)

    def _default_atol(self) -> float:
        """A force scale: 1e-11 of ``E_max L^(d-1)`` with L the scene's diameter."""
        size, E = self._scales()
        return 1e-11 * E * size ** (self.V.mesh.geometry.dim - 1)

    def _set_state(self, x: PETSc.Vec) -> None:
        if self._state is not None and x.equal(self._state):
            return
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        fem_petsc.assign(x, self.unknowns)
        for f in self.unknowns:
            f.x.scatter_forward()
        self._update_contact(x)
        self._state = x.copy()

    def _update_contact(self, x: PETSc.Vec) -> None:
        """Search, refresh the contact data and (if the pairing changed) the operator T."""
        gathers = [c.update(self.layout) for c in self.contacts]
        pattern = [cols for g in gathers for _, cols in g]
        pattern = np.concatenate(pattern) if pattern else np.zeros(0, np.int64)
        changed = self._pattern is None or not np.array_equal(pattern, self._pattern)
        changed = self.comm.allreduce(changed, MPI.LOR)
        if changed:
            self._pattern = pattern
            self._T = self._chain_operator(gathers)
            self._JT = None
        for c in self.contacts:
            c.update_history(self._T, x, self._block_slice)

    def _chain_operator(self, gathers: list[list]) -> PETSc.Mat:
        """``T``: identity from each unknown to its assembled field, gathers for the others."""
        unknown_index = {id(f): k for k, f in enumerate(self.unknowns)}
        identity, gather_blocks, gather_cols = [], [], []
        for row, f in enumerate(self.fields):
            if id(f) in unknown_index:
                identity.append((row, unknown_index[id(f)]))
        for g in gathers:
            for f, cols in g:
                gather_blocks.append(self._field_index[id(f)])
                gather_cols.append(cols)
        return chain_operator(self.full_layout, self.layout, identity, gather_blocks, gather_cols)

    def _block_slice(self, f: dolfinx.fem.Function) -> slice:
        """Local (owned) range of the assembled field ``f`` in the full layout."""
        k = self._field_index[id(f)]
        start = int(self.full_layout.local_sizes[:k].sum())
        return slice(start, start + int(self.full_layout.local_sizes[k]))

    def _residual(self, snes, x, F) -> None:
        self._set_state(x)
        self._assemble(self.residual_form, F)
        if len(self._bc_rows):
            u = self.u.x.array[self._bc_rows]
            F.array[self._bc_rows] = self._bc_scale * (u - self._prescribed(self.t))

    def _assemble(self, forms, out: PETSc.Vec) -> PETSc.Vec:
        """Assemble ``forms`` over the assembled fields and map them to the unknowns."""
        r = self._r
        with r.localForm() as r_local:
            r_local.set(0.0)
        fem_petsc.assemble_vector(r, forms)
        r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self._T.multTranspose(r, out)
        return out

    def reaction(self, tag: int | str) -> np.ndarray:
        """Resultant of the support reaction on the facets ``tag`` (an integer or the name of
        a physical group) at the current state.

        It is the residual of the displacement equations (internal minus external forces,
        contact included) summed over the dofs of those facets, without the equations that
        prescribe them.
        """
        R = self._assemble(self.residual_form, self._R.duplicate())
        gdim = self.V.mesh.geometry.dim
        owned = self.V.dofmap.index_map.size_local
        facets = self.scene.facet_tags.find(self.scene.facet_tag(tag))
        blocks = dolfinx.fem.locate_dofs_topological(self.V, gdim - 1, facets)
        blocks = blocks[blocks < owned]
        local = R.array[: owned * gdim].reshape(-1, gdim)[blocks].sum(axis=0)
        return self.comm.allreduce(local, MPI.SUM)

    def load_resultant(self) -> np.ndarray:
        """Resultant of all applied loads (dead and follower) at the current state."""
        if self._load_resultant_forms is None:
            mesh = self.V.mesh
            gdim = mesh.geometry.dim
            self._load_resultant_forms = []
            for i in range(gdim):
                e_i = dolfinx.fem.Constant(mesh, np.eye(gdim)[i])
                work = sum(
                    load.virtual_work(
                        self.u, e_i, self.dx if isinstance(load, BodyForce) else self.ds, c
                    )
                    for load, c in self._load_constants
                )
                self._load_resultant_forms.append(dolfinx.fem.form(work) if work else None)
        local = [
            dolfinx.fem.assemble_scalar(f) if f is not None else 0.0
            for f in self._load_resultant_forms
        ]
        return self.comm.allreduce(np.asarray(local, dtype=float), MPI.SUM)

    def contact_residual(self) -> PETSc.Vec:
        """The contact terms alone of the residual at the current state, as a vector of the
        unknowns (master parts gathered through the chain-rule operator)."""
        if self._contact_residual_form is None:
            self._contact_residual_form = dolfinx.fem.form(
                self._contact_residual_ufl, entity_maps=[c.slave.entity_map for c in self.contacts]
            )
        return self._assemble(self._contact_residual_form, self._R.duplicate())

    def _assemble_jacobian_matrix(self, first: bool = False) -> PETSc.Mat:
        K = self._K
        K.zeroEntries()
        fem_petsc.assemble_matrix(K, self.jacobian_form)
        K.assemble()
        if self._JT is None:
            self._JT = K.PtAP(self._T)
            new_pattern = True
        else:
            K.PtAP(self._T, result=self._JT)
            new_pattern = False
        if first:
            J = self._JT.duplicate(copy=True)
            J.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
            self._zero_bc_rows(J)
            return J
        J = self._J
        J.zeroEntries()
        structure = (
            PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
            if new_pattern
            else PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN
        )
        J.axpy(1.0, self._JT, structure=structure)
        if new_pattern:
            J.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
            self.snes.getKSP().getPC().reset()
        self._zero_bc_rows(J)
        return J

    def _zero_bc_rows(self, J: PETSc.Mat) -> None:
        rows = self.layout.owned(0, self._bc_rows).astype(PETSc.IntType)
        J.zeroRows(rows, diag=self._bc_scale)

    def _jacobian(self, snes, x, J, P) -> None:
        self._set_state(x)
        self._assemble_jacobian_matrix()

    def forget_state(self) -> None:
        """Make the next evaluation redo the search even at an unchanged state."""
        self._state = None

    def evaluate_residual(self, x: PETSc.Vec) -> PETSc.Vec:
        """The residual at the unknowns ``x`` (a new vector); sets the state to ``x``."""
        F = self._R.duplicate()
        self._residual(self.snes, x, F)
        return F

    def evaluate_jacobian(self, x: PETSc.Vec) -> PETSc.Mat:
        """The Jacobian at the unknowns ``x`` (the solver's matrix); sets the state to ``x``."""
        self._jacobian(self.snes, x, self._J, self._J)
        return self._J

    # -- load stepping --------------------------------------------------------------
    def set_time(self, t: float) -> None:
        """Set the pseudo-time (load factor) of loads and prescribed displacements."""
        self.t = t
        for load, c in self._load_constants:
            c.value = evaluate(load.value, t)

    def solve_step(self, t: float) -> tuple[bool, int, str]:
        """Solve for pseudo-time ``t`` from the current state.

        Newton takes full steps first. Where that fails (a semismooth Newton can cycle
        between contact or stick/slip states, or overshoot into inverted elements), the step
        is solved once more from the same start with the backtracking line search
        :attr:`fallback_linesearch` (``None``: no second try), before the caller cuts it back.

        Returns
        -------
        converged, Newton iterations (of both tries), SNES converged reason (name)
        """
        self.set_time(t)
        for c in self.contacts:
            c.begin_step()
        fem_petsc.assign(self.unknowns, self.x)
        start = self.x.copy()
        reason, its = self._newton()
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
        self._state = None
        self._set_state(self.x)
        names = {v: k for k, v in vars(PETSc.SNES.ConvergedReason).items() if k.isupper()}
        return reason > 0, its, names.get(reason, str(reason))

    def _newton(self) -> tuple[int, int]:
        """One SNES solve from ``self.x``: converged reason and iterations."""
        self._state = None
        try:
            self.snes.solve(None, self.x)
            reason = self.snes.getConvergedReason()
        except PETSc.Error as error:  # e.g. a failed factorisation: a failed step, not a crash
            self._print(f"  PETSc error in the Newton solve: {error}")
            reason = PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
        if reason <= 0:
            self.snes.getKSP().getPC().reset()  # no stale factorisation in the next try
        return reason, self.snes.getIterationNumber()

    def solve(
        self,
        num_steps: int = 10,
        t_end: float = 1.0,
        max_cutbacks: int = 8,
        callback: Callable[[ContactProblem, StepRecord], None] | None = None,
    ) -> History:
        """Load stepping from the current pseudo-time to ``t_end`` in ``num_steps`` steps.

        A step whose Newton solve fails is restored and halved; after two converged steps in
        a row the step grows back (at most to its initial size). A step smaller than the
        initial one halved ``max_cutbacks`` times raises :class:`ConvergenceError`, which
        names the step. Accepted steps are in :attr:`history` (and were passed to
        ``callback``, e.g. a :class:`~contact_ufl.output.ResultWriter`) whatever happens later.
        """
        dt0 = (t_end - self.t) / num_steps
        dt, streak = dt0, 0
        while self.t < t_end - 1e-12 * abs(t_end):
            t_prev, t_new = self.t, min(self.t + dt, t_end)
            saved = [f.x.array.copy() for f in self.unknowns]
            start = time.perf_counter()
            ok, its, reason = self.solve_step(t_new)
            if not ok:
                self._restore(saved, t_prev)
                self.history.cutbacks.append((t_new, reason))
                self._print(f"  step to t = {t_new:.5g} failed ({reason}): cutting back")
                dt, streak = 0.5 * dt, 0
                if dt < dt0 * 0.5**max_cutbacks * (1.0 - 1e-9):
                    raise ConvergenceError(
                        f"load step from t = {t_prev:.6g} to t = {t_new:.6g} did not converge "
                        f"({reason}) after {max_cutbacks} cut-backs; the state of "
                        f"t = {t_prev:.6g} is kept"
                    )
                continue
            record = StepRecord(
                len(self.history.steps) + 1,
                t_new,
                its,
                self.snes.getFunctionNorm(),
                self.active_points(),
                self.contact_force(),
                time.perf_counter() - start,
            )
            self.history.steps.append(record)
            for c in self.contacts:
                c.commit(self.x)
            for h in self.histories.values():
                h.commit()
            self._state = None
            self._print(self._format(record))
            if callback is not None:
                callback(self, record)
            streak += 1
            if streak >= 2 and dt < dt0:
                dt, streak = min(2.0 * dt, dt0), 0
        return self.history

    def _restore(self, saved: list[np.ndarray], t: float) -> None:
        for f, a in zip(self.unknowns, saved, strict=True):
            f.x.array[:] = a
        self.set_time(t)
        self._state = None

    # -- results --------------------------------------------------------------------
    def contact_force(self, k: int | None = None) -> np.ndarray:
        """Resultant contact force on the slave body, ``int (t_N nu - P(q)) dS_o`` (all pairs;
        the frictional part only with friction)."""
        pairs = self.contacts if k is None else [self.contacts[k]]
        return sum((c.integrate("traction") for c in pairs), np.zeros(self.V.mesh.geometry.dim))

    def stored_energy(self) -> float:
        """Elastic energy ``sum_b int psi_b(F) dV`` of all bodies (reference volume), for
        hyperelastic bodies (an elastoplastic one raises)."""
        if self.histories:
            raise ValueError(
                "stored_energy covers hyperelastic bodies only; this scene has "
                f"elastoplastic bodies (cell tags {sorted(self.histories)})"
            )
        if self._energy_form is None:
            F = deformation_gradient(self.u)
            energy = sum(b.material.strain_energy(F) * self.dx(b.tag) for b in self.scene.bodies)
            self._energy_form = dolfinx.fem.form(energy)
        return self.comm.allreduce(dolfinx.fem.assemble_scalar(self._energy_form))

    def active_points(self) -> int:
        """Number of slave quadrature points in contact (all pairs)."""
        return int(self.comm.allreduce(sum(c.active().sum() for c in self.contacts), MPI.SUM))

    @property
    def search_time(self) -> float:
        """Seconds spent in the closest-point projection so far."""
        return sum(c.search_time for c in self.contacts)

    def _format(self, r: StepRecord) -> str:
        force = " ".join(f"{f: .4e}" for f in r.contact_force)
        return (
            f"step {r.step:3d}  t = {r.t:.4f}  newton {r.newton_iterations:2d}  "
            f"|R| = {r.residual:.2e}  active {r.active_points:5d}  contact force [{force}]"
        )

    def _print(self, text: str) -> None:
        if self.verbose and self.comm.rank == 0:
            print(text, flush=True)
