"""The contact problem: the fields, unknowns and UFL forms of a scene, its Dirichlet data,
pseudo-time and the step protocol of everything with history.

Data flow: scene -> forms (bulk in UFL, contact terms of :mod:`contact_ufl.contact`) over
the assembled fields ``[u, xhat_1, lambda_1, ...]`` -> the Newton solver of
:mod:`contact_ufl.newton` (chain rule onto the unknowns ``[u, lambda_1, ...]``) -> load
stepping of :mod:`contact_ufl.stepping` -> results. This module imports neither:
:attr:`ContactProblem.solver` and :meth:`ContactProblem.solve` make them on first use (a
convenience), and the results that need the chain rule (:meth:`ContactProblem.reaction`,
:meth:`ContactProblem.contact_residual`) ask the solver, which owns it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl.contact import ContactInterface, ContactPair
from contact_ufl.contact.obstacles import RigidObstacle
from contact_ufl.layout import StackedLayout
from contact_ufl.loads import BodyForce, deformation_gradient, evaluate, load_constant
from contact_ufl.mpi import global_bounds
from contact_ufl.plasticity import J2Plasticity, PlasticHistory
from contact_ufl.scene import Scene

if TYPE_CHECKING:
    from contact_ufl.newton import NewtonSolver
    from contact_ufl.stepping import History, LoadStepper, StepRecord


def softer_modulus(scene: Scene, pair: ContactPair) -> float:
    """The smallest Young's modulus of the bodies whose cells hold the facets of ``pair``
    (the slave body alone when the master is a rigid obstacle)."""
    mesh = scene.mesh
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    sides = [pair.slave] if pair.on_obstacle else [pair.slave, pair.master]
    facets = np.concatenate([scene.facet_tags.find(tag) for tag in sides])
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

    The problem holds the displacement, the contact interfaces and plastic histories, the
    residual and Jacobian forms over the assembled fields, the Dirichlet rows and the load
    constants of the pseudo-time. It is solved by a
    :class:`~contact_ufl.newton.NewtonSolver` (:attr:`solver`) stepped by a
    :class:`~contact_ufl.stepping.LoadStepper` (:attr:`stepper`), both made on first use::

        problem = ContactProblem(scene)
        problem.solve(num_steps=4)

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
        PETSc options (Newton, KSP, PC) of :attr:`solver`, overriding
        :data:`contact_ufl.newton.DEFAULT_PETSC_OPTIONS`.
    petsc_options_prefix
        Prefix of those options in the PETSc options database.
    verbose
        Print one line per load step (rank 0).

    Attributes
    ----------
    u
        The displacement.
    t
        The pseudo-time (load factor) of loads and prescribed displacements.
    contacts
        The contact interfaces, one per contact pair of the scene.
    histories
        The :class:`~contact_ufl.plasticity.PlasticHistory` of each elastoplastic body, by
        cell tag.
    fields, unknowns
        The assembled fields ``[u, xhat_1, lambda_1, ...]`` and the unknowns
        ``[u, lambda_1, ...]``.
    layout, full_layout
        Numbering of the unknowns and of the assembled fields.
    residual_form, jacobian_form
        The compiled blocked residual (rows: ``fields``) and Jacobian (``fields`` x
        ``fields``).
    dirichlet_rows
        Local (owned) indices of the prescribed displacement dofs (unrolled).
    dirichlet_scale
        The stiffness ``k = E L^(d-2)`` of the prescribed-displacement equations
        ``k (u - g) = 0`` (every row of the residual is then a force).
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
        self.petsc_options = dict(petsc_options or {})
        self.petsc_options_prefix = petsc_options_prefix
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
        self._solver: NewtonSolver | None = None
        self._stepper: LoadStepper | None = None

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
        self.full_layout = StackedLayout([f.function_space for f in fields])
        self.layout = StackedLayout([f.function_space for f in unknowns])

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
        size, E = self.scales()
        self.dirichlet_scale = E * size ** (gdim - 2)
        self.dirichlet_rows = (
            np.concatenate(self._bc_dofs).astype(np.int64)
            if self._bc_dofs
            else np.zeros(0, np.int64)
        )

    def prescribed(self, t: float) -> np.ndarray:
        """The prescribed displacements ``g(t)`` of the rows :attr:`dirichlet_rows`."""
        values = []
        for dofs, (bc, i) in zip(self._bc_dofs, self._bc_values, strict=True):
            value = evaluate(bc.value, t)
            value = value if bc.component is not None or value.ndim == 0 else value[i]
            values.append(np.full(len(dofs), float(value)))
        return np.concatenate(values) if values else np.zeros(0)

    def scales(self) -> tuple[float, float]:
        """The scene's diameter L and largest Young's modulus E (collective)."""
        lo, hi = global_bounds(self.comm, self.V.mesh.geometry.x)
        return float(np.linalg.norm(hi - lo)), max(b.material.E for b in self.scene.bodies)

    # -- pseudo-time and the step protocol ----------------------------------------------
    def set_time(self, t: float) -> None:
        """Set the pseudo-time (load factor) of loads, prescribed displacements and the
        motion of rigid obstacles."""
        self.t = t
        for load, c in self._load_constants:
            c.value = evaluate(load.value, t)
        for c in self.contacts:
            c.set_time(t)

    def _parts_with_history(self) -> list:
        return [*self.contacts, *self.histories.values()]

    def begin_step(self) -> None:
        """Begin a load step from the last committed state, in every part with history
        (contacts, plastic histories). Idempotent: a step cut back and tried again begins
        from the same state."""
        for part in self._parts_with_history():
            part.begin_step()

    def commit(self, x: PETSc.Vec) -> None:
        """Accept the current state, of unknowns ``x``, as the converged state of a load
        step, in every part with history (contacts, then plastic histories)."""
        for part in self._parts_with_history():
            part.commit(x)

    # -- solver and load stepping (made on first use) -----------------------------------
    @property
    def solver(self) -> NewtonSolver:
        """The :class:`~contact_ufl.newton.NewtonSolver` of this problem, made on first use
        with :attr:`petsc_options` (the state it starts from is the converged state of step
        0), or the one made directly for it. One solver per problem: it owns the search
        state of the contacts and the chain operator T."""
        if self._solver is None:
            from contact_ufl.newton import NewtonSolver

            self._solver = NewtonSolver(self, self.petsc_options, self.petsc_options_prefix)
        return self._solver

    @property
    def stepper(self) -> LoadStepper:
        """The :class:`~contact_ufl.stepping.LoadStepper` of :attr:`solver`, made on first
        use."""
        if self._stepper is None:
            from contact_ufl.stepping import LoadStepper

            self._stepper = LoadStepper(self, self.solver)
        return self._stepper

    @property
    def history(self) -> History:
        """Accepted steps and cut-backs of :meth:`solve` so far."""
        return self.stepper.history

    def solve(
        self,
        num_steps: int = 10,
        t_end: float = 1.0,
        max_cutbacks: int = 8,
        callback: Callable[[ContactProblem, StepRecord], None] | None = None,
    ) -> History:
        """Load stepping from the current pseudo-time to ``t_end`` in ``num_steps`` steps.

        A convenience: :meth:`LoadStepper.solve <contact_ufl.stepping.LoadStepper.solve>`
        of :attr:`stepper` (cut-back of failed steps, :class:`ConvergenceError
        <contact_ufl.errors.ConvergenceError>` when cut-backs run out).

        Returns
        -------
        The :attr:`history` of all solves of this problem.
        """
        return self.stepper.solve(num_steps, t_end, max_cutbacks, callback)

    # -- results --------------------------------------------------------------------
    def reaction(self, tag: int | str) -> np.ndarray:
        """Resultant of the support reaction on the facets ``tag`` (an integer or the name of
        a physical group) at the current state.

        It is the residual of the displacement equations (internal minus external forces,
        contact included) summed over the dofs of those facets, without the equations that
        prescribe them (assembled by :attr:`solver`, which owns the chain rule).
        """
        R = self.solver.assemble(self.residual_form)
        gdim = self.V.mesh.geometry.dim
        owned = self.V.dofmap.index_map.size_local
        facets = self.scene.facet_tags.find(self.scene.facet_tag(tag))
        blocks = dolfinx.fem.locate_dofs_topological(self.V, gdim - 1, facets)
        blocks = blocks[blocks < owned]
        local = R.array[: owned * gdim].reshape(-1, gdim)[blocks].sum(axis=0)
        return self.comm.allreduce(local, MPI.SUM)

    def obstacle_reaction(self, obstacle: RigidObstacle) -> np.ndarray:
        """Resultant force of a rigid obstacle on the bodies at the current state: its
        reaction, reported like a support's (:meth:`reaction` is the force of a support on
        the body). The force of the bodies on the obstacle is its negative.

        It is the contact resultant ``int (t_N nu - P(q)) dS_o`` on the slave surfaces of
        all pairs whose master is ``obstacle`` (compared with ``==``), summed over all
        ranks. With the obstacle a scene's forces balance as with supports only:
        ``sum of support reactions + obstacle reactions + loads = 0``, to solver tolerance
        (the contact traction is a term of the displacement residual, whose sum over a
        body's dofs is exactly the resultant of its external and contact forces).
        """
        pairs = [c for c in self.contacts if c.pair.on_obstacle and c.pair.master == obstacle]
        if not pairs:
            raise ValueError(f"no contact pair of this problem has the master {obstacle}")
        return sum((c.integrate("traction") for c in pairs), np.zeros(self.V.mesh.geometry.dim))

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
        unknowns (master parts gathered through the chain rule of :attr:`solver`)."""
        if self._contact_residual_form is None:
            self._contact_residual_form = dolfinx.fem.form(
                self._contact_residual_ufl, entity_maps=[c.slave.entity_map for c in self.contacts]
            )
        return self.solver.assemble(self._contact_residual_form)

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
