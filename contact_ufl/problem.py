"""The contact problem: the fields, unknowns and UFL forms of a scene, its Dirichlet data,
pseudo-time and the step protocol of everything with history, and the results of a solve.

Data flow: scene -> forms (bulk in UFL, contact terms of :mod:`contact_ufl.contact`) over
the assembled fields ``[u, xhat_1, lambda_1, ...]`` -> the discrete operator of
:mod:`contact_ufl.operator` (chain rule onto the unknowns ``[u, lambda_1, ...]``) -> the
Newton driver of :mod:`contact_ufl.newton`, tried by the step strategies of
:mod:`contact_ufl.strategies` -> load stepping of :mod:`contact_ufl.stepping` -> results.
The problem composes them (:attr:`ContactProblem.solver`, made on first use); the results
that need the chain rule (:meth:`ContactProblem.reaction`,
:meth:`ContactProblem.contact_residual`) ask the operator, which owns it.
"""

from __future__ import annotations

import functools
import operator
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NamedTuple

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import free_bodies, jit, keysets
from contact_ufl.bulk import Bulk
from contact_ufl.checkpoint import Checkpoints, restart
from contact_ufl.contact import ContactInterface, ContactPair
from contact_ufl.contact.obstacles import RigidObstacle
from contact_ufl.control import VolumeConstraint, VolumeControl
from contact_ufl.diagnosis import StepDiagnosis
from contact_ufl.errors import NonUniqueSolutionWarning
from contact_ufl.estimate import ErrorEstimate, error_estimate
from contact_ufl.goal import GoalEstimate, normal_force_error
from contact_ufl.layout import StackedLayout
from contact_ufl.mpi import collective, global_bounds, global_diameter
from contact_ufl.newton import NewtonDriver
from contact_ufl.operator import AssembledSystem, ContactOperator, DirichletRows
from contact_ufl.results import inverted_cell_centres
from contact_ufl.scene import Domain, Scene
from contact_ufl.stepping import History, LoadStepper, StepRecord
from contact_ufl.strategies import StepSolver


def _support_hint(piece, modes: np.ndarray) -> str:
    """What would hold the rigid ``modes`` of ``piece``: a support per free direction."""
    gdim = len(piece.free)
    axes = [i for i in range(gdim) if np.abs(modes[:, i]).max() > 1e-6]
    turns = np.abs(modes[:, gdim:]).max(initial=0.0) > 1e-6
    parts = [f"Dirichlet(<a facet group of it>, 0.0, component={i})" for i in axes]
    advice = "Hold it with " + " and ".join(parts) if parts else "Hold it with a support"
    if turns:
        advice += " on a line or two points (a single point lets it turn)"
    return advice + ", or give the contact friction."


def softer_modulus(parts: list[Domain], pair: ContactPair) -> float:
    """The smallest Young's modulus of the bodies whose cells hold the facets of ``pair``
    (the slave body alone when the master is a rigid obstacle; a membrane's is ``E t0 / L``
    with ``L`` its mesh's diameter); ``parts`` are the scene's domains, indexed by the
    pair's ``slave_domain`` and ``master_domain``."""
    sides = [(pair.slave_domain, pair.slave)]
    if not pair.on_obstacle:
        sides.append((pair.master_domain, pair.master))
    moduli = []
    for k, tag in sides:
        domain = parts[k or 0]
        mesh = domain.mesh
        tdim = mesh.topology.dim
        cells = domain.surface_tags.find(tag)
        if not domain.membrane:  # the cells of the facets
            mesh.topology.create_connectivity(tdim - 1, tdim)
            f2c = mesh.topology.connectivity(tdim - 1, tdim)
            cells = f2c.array[f2c.offsets[cells]]
        imap = mesh.topology.index_map(tdim)
        cell_tag = np.full(imap.size_local + imap.num_ghosts, -1, dtype=np.int64)
        cell_tag[domain.cell_tags.indices] = domain.cell_tags.values
        found = mesh.comm.allreduce(set(cell_tag[cells].tolist()), MPI.BOR)
        size = global_diameter(mesh.comm, mesh.geometry.x)
        moduli += [b.modulus(size) for b in domain.bodies if b.tag in found]
    return min(moduli) if moduli else float("nan")


def _derivative(form: ufl.Form, field: dolfinx.fem.Function) -> ufl.Form | None:
    """The Gateaux derivative of ``form`` in the direction of a trial function of ``field``'s
    space, ``None`` where it is empty."""
    form = ufl.algorithms.expand_derivatives(
        ufl.derivative(form, field, ufl.TrialFunction(field.function_space))
    )
    return None if form.empty() else form


class _ContactTerms(NamedTuple):
    """The contact terms of a problem's pairs (UFL forms)."""

    on_slave: list[list[ufl.Form]]  #: on the displacement rows of each mesh
    on_slave_tangent: list[list[ufl.Form]]  #: the same with the terms only the tangent sees
    own: list[ufl.Form]  #: the residuals of the pairs' fields, in their order
    own_tangent: list[ufl.Form]  #: the same with the terms only the tangent sees


def _summed(forms: list[ufl.Form]) -> list[ufl.Form]:
    """The sum of ``forms`` as the one part of a block, or no part."""
    return [functools.reduce(operator.add, forms)] if forms else []


class ContactProblem:
    """Quasi-static large-deformation contact of the bodies of a scene.

    The problem holds one :class:`~contact_ufl.bulk.Bulk` per mesh (its displacement,
    bodies, loads, plastic histories and supports), the contact interfaces between them, the
    residual and Jacobian forms over the assembled fields, the Dirichlet rows and the
    pseudo-time. It is solved by a :class:`~contact_ufl.strategies.StepSolver`
    (:attr:`solver`: the discrete operator, the Newton driver and the step strategies)
    stepped by a :class:`~contact_ufl.stepping.LoadStepper` (:attr:`stepper`), both made on
    first use::

        problem = ContactProblem(scene)
        problem.solve(num_steps=4)

    Parameters
    ----------
    scene
        Meshes, bodies, supports, loads and contact pairs.
    degree
        Polynomial degree of the displacement.
    quadrature_degree
        Quadrature degree of the bulk integrals (default: exact for P1 simplices, ``2 p``
        otherwise).
    petsc_options
        PETSc options (Newton, KSP, PC) of :attr:`solver`, overriding
        :data:`contact_ufl.newton.DEFAULT_PETSC_OPTIONS` (MUMPS's LU);
        :data:`contact_ufl.newton.FIELD_SPLIT_PETSC_OPTIONS` for an iterative solve of a
        large 3D problem.
    petsc_options_prefix
        Prefix of those options in the PETSc options database.
    verbose
        Print one line per load step (rank 0).

    Attributes
    ----------
    bulks
        The bulk of each mesh, in the order of :attr:`Scene.parts
        <contact_ufl.scene.Scene.parts>`.
    u, V, dx, ds, histories
        Those of the one mesh of a one-mesh problem (``bulks[k].u`` etc. for mesh ``k``).
    t
        The pseudo-time (load factor) of loads and prescribed displacements.
    contacts
        The contact interfaces, one per contact pair of the scene.
    fields, unknowns
        The assembled fields ``[u_1, ..., u_m, xhat_1, lambda_1, ...]`` and the unknowns
        ``[u_1, ..., u_m, lambda_1, ...]`` (one displacement per mesh).
    layout, full_layout
        Numbering of the unknowns and of the assembled fields.
    residual_form, jacobian_form
        The compiled blocked residual (rows: ``fields``) and Jacobian (``fields`` x
        ``fields``), each block a list of parts (:mod:`contact_ufl.assembly`): the bulk's,
        then the contact terms.
    dirichlet_rows
        Local (owned) indices of the prescribed displacement dofs (unrolled) in a vector of
        the unknowns, then of the multipliers held at zero because the slave's displacement
        is prescribed there (:meth:`ContactInterface.held_multipliers
        <contact_ufl.contact.interface.ContactInterface.held_multipliers>`).
    held_multipliers
        How many of this rank's multiplier dofs are held at zero (the last rows of
        :attr:`dirichlet_rows`).
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
        parts = scene.parts
        self.comm = parts[0].mesh.comm
        self.gdim = parts[0].mesh.geometry.dim
        self.verbose = verbose
        self.petsc_options = dict(petsc_options or {})
        self.petsc_options_prefix = petsc_options_prefix
        self.t = 0.0
        #: the bulk of each mesh (its displacement, bodies and loads), in the order of
        #: :attr:`Scene.parts <contact_ufl.scene.Scene.parts>`
        self.bulks = [Bulk(d, degree, quadrature_degree) for d in parts]
        self.contacts = [self._interface(p, parts) for p in scene.contacts]
        size, E = self.scales()
        #: the path-following controls (:mod:`contact_ufl.control`): unknown load factors
        #: with their equations, e.g. a membrane's pressure set by its enclosed volume
        self.controls = [
            VolumeConstraint(load, b, E / size)
            for b in self.bulks
            for load in b.domain.loads
            if isinstance(load, VolumeControl)
        ]
        self._build_forms()
        self._build_dirichlet()
        self._check_rigid_modes()
        self._report_overlaps()
        self._solver: StepSolver | None = None
        self._stepper: LoadStepper | None = None
        self._closed = False
        #: the checkpoint this problem restarted from: (folder, step, t), or None
        self.restored_from: tuple[Path, int, float] | None = None

    def _interface(self, pair: ContactPair, parts: list) -> ContactInterface:
        """The contact interface of ``pair`` between the bulks that hold its surfaces."""
        slave = self.bulks[pair.slave_domain]
        master = self.bulks[pair.master_domain] if not pair.on_obstacle else slave
        return ContactInterface(
            slave.u,
            slave.domain.surface_tags,
            pair,
            softer_modulus(parts, pair),
            master_u=master.u,
            master_facet_tags=master.domain.surface_tags,
            master_block=self.bulks.index(master),
            master_orientation=master.orientation,
        )

    # -- one mesh: the attributes of a one-mesh problem ----------------------------------
    def _single(self) -> Bulk:
        if len(self.bulks) != 1:
            raise AttributeError(
                f"this problem has {len(self.bulks)} meshes: use problem.bulks[k] for mesh k"
            )
        return self.bulks[0]

    @property
    def u(self) -> dolfinx.fem.Function:
        """The displacement (a one-mesh problem; :attr:`bulks` ``[k].u`` for mesh k)."""
        return self._single().u

    @property
    def V(self) -> dolfinx.fem.FunctionSpace:
        """The displacement space (a one-mesh problem)."""
        return self._single().V

    @property
    def dx(self) -> ufl.Measure:
        """The cell measure (a one-mesh problem)."""
        return self._single().dx

    @property
    def ds(self) -> ufl.Measure:
        """The exterior-facet measure (a one-mesh problem)."""
        return self._single().ds

    @property
    def histories(self) -> dict:
        """The plastic histories by cell tag (a one-mesh problem)."""
        return self._single().histories

    def first_piola(self, body) -> ufl.core.expr.Expr:
        """First Piola-Kirchhoff stress of ``body`` (a one-mesh problem; see
        :meth:`Bulk.first_piola <contact_ufl.bulk.Bulk.first_piola>`)."""
        return self._single().first_piola(body)

    def locate(self, tag: int | str, kind: str = "facet") -> tuple[Bulk, int]:
        """The bulk whose mesh holds the facets (or cells) ``tag``, and the integer tag."""
        k, tag = self.scene.locate(tag, kind)
        return self.bulks[k], tag

    def bulk_of(self, contact: ContactInterface, side: str = "slave") -> Bulk:
        """The bulk that holds the ``side`` surface of ``contact``."""
        return self.bulks[getattr(contact.pair, f"{side}_domain")]

    # -- forms ------------------------------------------------------------------------
    def _build_forms(self) -> None:
        # each block a list of parts compiled apart (contact_ufl.assembly): the bulk's, then
        # the contact terms on the slave surfaces of its mesh
        tests = [ufl.TestFunction(b.V) for b in self.bulks]
        bulk = [b.residual(v) for b, v in zip(self.bulks, tests, strict=True)]
        for control in self.controls:
            k = self.bulks.index(control.bulk)
            bulk[k] = bulk[k] - control.bulk_residual(tests[k])
        terms = self._contact_terms(tests)
        controls = [F for control in self.controls for F in control.residuals()]
        displacements = [b.u for b in self.bulks]
        fields = displacements + [f for c in self.contacts for f in c.fields]
        unknowns = displacements + [f for c in self.contacts for f in c.unknowns]
        for control in self.controls:
            fields += control.fields
            unknowns += control.unknowns
            control.block = len(unknowns) - 1
        self.fields, self.unknowns = fields, unknowns
        residuals = [[F, *_summed(on)] for F, on in zip(bulk, terms.on_slave, strict=True)]
        residuals += [[F] for F in terms.own + controls]
        tangent = [[F, *_summed(on)] for F, on in zip(bulk, terms.on_slave_tangent, strict=True)]
        tangent += [[F] for F in terms.own_tangent + controls]
        jacobian = [
            [[d for part in row if (d := _derivative(part, f)) is not None] for f in fields]
            for row in tangent
        ]
        entity_maps = [c.slave.entity_map for c in self.contacts]
        self.residual_form = jit.form(residuals, entity_maps=entity_maps)
        # the contact terms alone
        self._contact_residual_ufl = [_summed(on) for on in terms.on_slave]
        self._contact_residual_ufl += [[F] for F in terms.own] + [[] for _ in controls]
        self._contact_residual_form = None
        self.jacobian_form = jit.form(jacobian, entity_maps=entity_maps)
        self.full_layout = StackedLayout([f.function_space for f in fields])
        self.layout = StackedLayout([f.function_space for f in unknowns])

    def _contact_terms(self, tests: list[ufl.Argument]) -> _ContactTerms:
        """The contact terms of the pairs: on the displacement rows of each mesh, and the
        residuals of the pairs' fields, with the terms only the tangent sees
        (:attr:`ContactPair.geometric_traction <contact_ufl.contact.pair.ContactPair>`)."""
        terms = _ContactTerms([[] for _ in self.bulks], [[] for _ in self.bulks], [], [])
        for c in self.contacts:
            k = c.pair.slave_domain
            F_u, F_fields = c.residuals(tests[k])
            extra_u, extra_fields = c.tangent_residuals(tests[k]) or (None, [])
            terms.on_slave[k].append(F_u)
            terms.on_slave_tangent[k].append(F_u if extra_u is None else F_u + extra_u)
            terms.own.extend(F_fields)
            terms.own_tangent.extend(F + e for F, e in zip(F_fields, extra_fields, strict=False))
            terms.own_tangent.extend(F_fields[len(extra_fields) :])
        return terms

    def _build_dirichlet(self) -> None:
        # prescribed-displacement equations k (u - g) = 0 are scaled by a stiffness k = E L^(d-2)
        # so that every row of the residual is a force (one absolute tolerance for all)
        size, E = self.scales()
        self.dirichlet_scale = E * size ** (self.gdim - 2)
        offsets = np.concatenate([[0], np.cumsum(self.layout.local_sizes)])
        rows = [offsets[k] + b.dirichlet_dofs for k, b in enumerate(self.bulks)]
        # multipliers where the slave's displacement is prescribed are held at zero
        block = {id(f): k for k, f in enumerate(self.unknowns)}
        for c in self.contacts:
            held_N, held_T = c.held_multipliers(
                self.bulks[c.pair.slave_domain].prescribed_components
            )
            rows.append(offsets[block[id(c.lambda_N)]] + held_N)
            if c.friction:
                rows.append(offsets[block[id(c.friction.lambda_T)]] + held_T)
        self.dirichlet_rows = np.concatenate(rows).astype(np.int64)
        displacements = sum(len(b.dirichlet_dofs) for b in self.bulks)
        self.held_multipliers = len(self.dirichlet_rows) - displacements

    def _report_overlaps(self) -> None:
        """Say (rank 0, when verbose) which pairs overlap at the start: a press fit, which
        the first step resolves unless the pair ramps it in (``overlap_ramp``)."""
        for c in self.contacts:
            overlap = c.initial_overlap
            if overlap > c.round_off and self.verbose and self.comm.rank == 0:
                how = (
                    "resolved in the first load step (ContactPair.overlap_ramp ramps it in)"
                    if c.pair.overlap_ramp is None
                    else f"ramped in until t = {c.pair.overlap_ramp:g}"
                )
                print(
                    f"contact pair of slave surface {c.pair.surface('slave')}: the surfaces "
                    f"overlap by up to {overlap:.4g} at the start (a press fit), {how}",
                    flush=True,
                )

    def _check_rigid_modes(self) -> None:
        """Warn of a body that nothing holds (no support, no contact pair), and of one whose
        free rigid modes only a frictionless contact could hold but whose contact normals
        near contact do not (:mod:`contact_ufl.free_bodies`): its solution is not
        unique along them (collective). A membrane's tension holds what its supports
        leave free to first order (a string turning about a point of its chord), so only
        its translations along directions no support holds count."""
        #: the pieces of the meshes with a free rigid mode, each with its contact pairs
        #: (:mod:`contact_ufl.free_bodies`; the step strategies and diagnosis use them too)
        self.free_pieces = [
            (piece, free_bodies.pairs_on(self, piece))
            for piece in free_bodies.pieces(self)
            if len(piece.modes)
        ]
        loose = []
        for piece, on in self.free_pieces:
            modes = piece.modes
            if self.bulks[piece.mesh].membrane:
                modes = np.eye(modes.shape[1])[: self.gdim][piece.free]
            if len(modes):
                loose.append((piece, modes, on))
        for piece, modes, on in loose:
            if on:
                continue
            words = "; ".join(free_bodies.describe_mode(piece, m) for m in modes)
            warnings.warn(
                f"the solution is not unique: the body {' + '.join(piece.bodies)} is held by "
                f"no support and no contact pair, so nothing holds its rigid motion ({words}): "
                "the solver picks its displacement along it, and a load along it has no "
                "solution. Add a Dirichlet support (or a contact pair) on it",
                NonUniqueSolutionWarning,
                stacklevel=3,
            )
        for piece, modes, on in [item for item in loose if item[2]]:
            unheld = free_bodies.unheld_modes(self, piece, on, modes)
            if not len(unheld):
                continue
            modes = "; ".join(free_bodies.describe_mode(piece, m) for m in unheld)
            surfaces = ", ".join(self.contacts[k].pair.surface("slave") for k in on)
            hint = _support_hint(piece, unheld)
            warnings.warn(
                f"the solution is not unique: the body {' + '.join(piece.bodies)} has a rigid "
                f"motion ({modes}) that no support holds and that its frictionless contact "
                f"(slave surface(s) {surfaces}) does not resist, the contact normals being "
                "perpendicular to it; the answer along it is arbitrary (it may differ between "
                f"runs and numbers of ranks). {hint}",
                NonUniqueSolutionWarning,
                stacklevel=3,
            )

    def block_rows(self, k: int) -> slice:
        """Local (owned) range of the displacement of mesh ``k`` in a vector of the
        unknowns."""
        offsets = np.concatenate([[0], np.cumsum(self.layout.local_sizes)])
        return slice(int(offsets[k]), int(offsets[k + 1]))

    def prescribed(self, t: float) -> np.ndarray:
        """The prescribed values ``g(t)`` of the rows :attr:`dirichlet_rows`: the
        displacements, then the held multipliers (zero)."""
        held = np.zeros(self.held_multipliers)
        return np.concatenate([*(b.prescribed(t) for b in self.bulks), held])

    def scales(self) -> tuple[float, float]:
        """The scene's diameter L and largest modulus E of its bodies (collective; a
        membrane's is ``E t0 / L``: :meth:`Body.modulus <contact_ufl.scene.Body.modulus>`)."""
        x = np.vstack([b.V.mesh.geometry.x for b in self.bulks])
        lo, hi = global_bounds(self.comm, x)
        size = float(np.linalg.norm(hi - lo))
        return size, max(body.modulus(size) for b in self.bulks for body in b.bodies)

    # -- pseudo-time and the step protocol ----------------------------------------------
    def set_time(self, t: float) -> None:
        """Set the pseudo-time (load factor) of loads, prescribed displacements and the
        motion of rigid obstacles."""
        self.t = t
        for b in self.bulks:
            b.set_time(t)
        for control in self.controls:
            control.set_time(t)
        for c in self.contacts:
            c.set_time(t)

    def _parts_with_history(self) -> list:
        return [*self.contacts, *(h for b in self.bulks for h in b.histories.values())]

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
    def solver(self) -> StepSolver:
        """The :class:`~contact_ufl.strategies.StepSolver` of this problem, made on first
        use with :attr:`petsc_options` (the state it starts from is the converged state of
        step 0). One solver per problem: its operator owns the search state of the contacts
        and the chain operator T."""
        if self._closed:
            raise RuntimeError("this problem is closed (problem.close()): make a new one")
        if self._solver is None:
            self._solver = self._make_solver()
        return self._solver

    @property
    def operator(self) -> ContactOperator:
        """The discrete operator of :attr:`solver`: the state of an iterate, the residual
        ``T^T r`` and the tangent ``T^T K T``."""
        return self.solver.operator

    def _make_solver(self, committed: bool = False) -> StepSolver:
        """The operator at the current state, committed as the converged state of step 0
        (``committed``: a restored state, committed already), the Newton driver over its
        callbacks, and the step strategies (collective)."""
        dirichlet = DirichletRows(
            self.dirichlet_rows, self.dirichlet_scale, lambda: self.prescribed(self.t)
        )
        couplings = [*self.contacts, *self.controls]
        system = AssembledSystem(
            self.fields,
            self.unknowns,
            self.layout,
            self.full_layout,
            self.residual_form,
            self.jacobian_form,
            couplings,
            dirichlet,
            len(self.bulks),
        )
        operator = ContactOperator(system, pattern_superset=self.gdim == 2)
        # the initial state is the converged state of step 0; a restored one was committed
        # but for the contacts' slip references, which come from a search there
        if committed:
            self._settle(operator, self.contacts, replan=True)
        else:
            self._settle(operator, self._parts_with_history())
        operator.first_tangent()  # the driver's first matrix
        # a force scale: 1e-11 of E_max L^(d-1) with L the scene's diameter
        size, E = self.scales()
        options = {"snes_atol": 1e-11 * E * size ** (self.gdim - 1)} | self.petsc_options
        newton = NewtonDriver(
            self.comm,
            operator.residual,
            operator.jacobian,
            operator.residual_vector,
            operator.matrix,
            options,
            self.petsc_options_prefix,
            field_splits=operator.field_splits(self.gdim),
            timings=operator.timings,
            verbose=self.verbose,
        )
        diagnosis = StepDiagnosis(
            self.comm, self.contacts, self.free_pieces, lambda: inverted_cell_centres(self)
        )
        if committed:  # as fresh_start leaves a run: the plan without its matrix
            operator.replan()
            operator.update_pairing(operator.x)
        return StepSolver(self, operator, newton, diagnosis)

    def _settle(self, operator: ContactOperator, parts: list, replan: bool = False) -> None:
        """The pairing at the operator's state, ``parts`` committed there, the next step
        begun, and the pairing again (with the slip references' gathers; ``replan``: on
        which the operator plans its pattern from nothing, as :meth:`fresh_start` does)."""
        operator.update_pairing(operator.x)
        for part in parts:
            part.commit(operator.x)
        self.begin_step()
        if replan:
            operator.replan()
        operator.update_pairing(operator.x)

    @property
    def has_solver(self) -> bool:
        """Whether :attr:`solver` was made."""
        return self._solver is not None

    def resume_solver(self) -> StepSolver:
        """Make :attr:`solver` at the current fields, taken as the committed state of a step
        (a restart: the histories hold that state already; collective)."""
        if self._solver is not None:
            raise RuntimeError("this problem has a solver already")
        self._solver = self._make_solver(committed=True)
        return self._solver

    def fresh_start(self) -> None:
        """Go on from the state of a begun step as a restart from its start would: the
        pairings met forgotten, the chain operator and sparsity plan made anew there, the
        solver matrix (and its factorisation's analysis) at the next tangent (collective).
        The load stepper does it at the start of the step after each checkpoint, so that a
        run and its restart solve the same systems: bit for bit on one rank."""
        operator = self.solver.operator
        operator.replan()
        operator.update_pairing(operator.x)

    def restart(self, folder: str | Path, step: int | None = None) -> float:
        """Continue from a checkpoint (collective).

        Sets the fields, histories, pseudo-time, step records and the schedule of the solve
        under way to those of the checkpoint of ``step`` (default: the last complete one) in
        ``folder``, written by :meth:`solve` with ``checkpoint=`` on any number of ranks;
        the next :meth:`solve` with the same ``num_steps`` and ``t_end`` goes on where that
        one stopped, and a solve that ended before is skipped, so the script that wrote the
        checkpoints restarts by calling this before its solves. Call it on a problem made
        anew from the same scene, before any solve.

        Returns
        -------
        The pseudo-time of the checkpoint.
        """
        return restart(self, folder, step)

    def net_free_load(self, residual: np.ndarray, piece: free_bodies.Piece) -> float:
        """The load of the residual (a vector of the unknowns) along the free rigid modes of
        ``piece`` (:func:`contact_ufl.free_bodies.net_free_load`; collective)."""
        return free_bodies.net_free_load(self, residual, piece)

    def close(self) -> None:
        """Free the PETSc objects of this problem's solver (collective), for scripts that make
        many problems on more than one rank (see :meth:`StepSolver.close
        <contact_ufl.strategies.StepSolver.close>`); the fields keep their values. A problem is
        also a context manager that closes on leaving: ``with ContactProblem(scene) as
        problem: ...``."""
        if self._solver is not None:
            self._solver.close()
        self._closed = True

    def __enter__(self) -> ContactProblem:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def stepper(self) -> LoadStepper:
        """The :class:`~contact_ufl.stepping.LoadStepper` of :attr:`solver`, made on first
        use."""
        if self._stepper is None:
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
        checkpoint: Checkpoints | str | Path | None = None,
    ) -> History:
        """Load stepping from the current pseudo-time to ``t_end`` in ``num_steps`` steps.

        A convenience: :meth:`LoadStepper.solve <contact_ufl.stepping.LoadStepper.solve>`
        of :attr:`stepper` (cut-back of failed steps, :class:`ConvergenceError
        <contact_ufl.errors.ConvergenceError>` when cut-backs run out). ``checkpoint``: a
        :class:`~contact_ufl.checkpoint.Checkpoints` or its folder (a checkpoint at every
        step), from which :meth:`restart` continues.

        Returns
        -------
        The :attr:`history` of all solves of this problem.
        """
        if isinstance(checkpoint, str | Path):
            checkpoint = Checkpoints(checkpoint)
        return self.stepper.solve(num_steps, t_end, max_cutbacks, callback, checkpoint)

    # -- results --------------------------------------------------------------------
    @collective
    def error_estimate(self) -> ErrorEstimate:
        """The residual error indicators and estimate of the converged state
        (:func:`contact_ufl.estimate.error_estimate`): per-cell indicators, the estimate in
        the energy norm and its parts."""
        return error_estimate(self)

    @collective
    def normal_force_error(self, pair: int | None = None) -> GoalEstimate:
        """The estimated error in the normal contact force ``int lambda_N dS_o`` of ``pair``
        (all pairs: ``None``) at the converged state, by dual-weighted residuals
        (:func:`contact_ufl.goal.normal_force_error`): signed, with each cell's share."""
        return normal_force_error(self, pair)

    @collective
    def reaction(
        self, tag: int | str | Sequence[int | str], domain: int | str | None = None
    ) -> np.ndarray:
        """Resultant of the support reaction on the facets ``tag`` (an integer or the name of
        a physical group, or several: their nodes counted once; in a scene of several
        meshes, of the mesh ``domain`` or the one whose groups have that name) at the current
        state.

        It is the residual of the displacement equations (internal minus external forces,
        contact included) summed over the dofs of those facets, without the equations that
        prescribe them (assembled by :attr:`operator`, which owns the chain rule).
        """
        local = np.zeros(self.gdim)
        for _, forces in self._nodal_reactions(tag, domain):
            local += forces.sum(axis=0)
        return self.comm.allreduce(local, MPI.SUM)

    @collective
    def reaction_moment(
        self,
        tag: int | str | Sequence[int | str],
        about: Sequence[float],
        domain: int | str | None = None,
    ) -> float | np.ndarray:
        """Moment about the point ``about`` of the support reaction on the facets ``tag``
        (as in :meth:`reaction`) at the current state: ``sum_a (x_a - about) x R_a`` over
        their nodes at their current positions ``x_a``, e.g. the torque that turns a hub
        (:class:`~contact_ufl.loads.RigidMotion`). In 2D the moment about the out-of-plane
        axis (a number), in 3D a vector."""
        local = np.zeros(3)
        p = np.zeros(3)
        p[: self.gdim] = np.asarray(about, dtype=float)
        for x, forces in self._nodal_reactions(tag, domain, positions=True):
            arm, force = np.zeros((len(x), 3)), np.zeros((len(x), 3))
            arm[:, : self.gdim], force[:, : self.gdim] = x - p[: self.gdim], forces
            local += np.cross(arm, force).sum(axis=0)
        moment = self.comm.allreduce(local, MPI.SUM)
        return float(moment[2]) if self.gdim == 2 else moment

    def _nodal_reactions(self, tag, domain, positions: bool = False) -> list[tuple]:
        """(current positions or None, reaction forces ``(n, gdim)``) of this rank's owned
        nodes of the facets ``tag``, mesh by mesh (:meth:`reaction`)."""
        keys = [tag] if isinstance(tag, int | str) else list(tag)
        nodes: dict[int, list[np.ndarray]] = {}
        for key in keys:
            k, t = self.scene.locate(key, "facet", domain)
            nodes.setdefault(k, []).append(self.bulks[k].facet_dofs(t))
        R = self.operator.assemble(self.residual_form)
        out = []
        for k, blocks in nodes.items():
            owned = keysets.unique(np.concatenate(blocks))
            forces = R.array[self.block_rows(k)].reshape(-1, self.gdim)[owned]
            x = None
            if positions:
                bulk = self.bulks[k]
                X = bulk.V.tabulate_dof_coordinates()[owned, : self.gdim]
                x = X + bulk.u.x.array.reshape(-1, self.gdim)[owned]
            out.append((x, forces))
        return out

    @collective
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
        return sum((c.integrate("traction") for c in pairs), np.zeros(self.gdim))

    @collective
    def load_resultant(self) -> np.ndarray:
        """Resultant of all applied loads (dead and follower) at the current state."""
        loads = [b.load_resultant() for b in self.bulks]
        loads += [control.load_resultant() for control in self.controls]
        return sum(loads, np.zeros(self.gdim))

    @collective
    def contact_residual(self) -> PETSc.Vec:
        """The contact terms alone of the residual at the current state, as a vector of the
        unknowns (master parts gathered through the chain rule of :attr:`operator`)."""
        if self._contact_residual_form is None:
            self._contact_residual_form = jit.form(
                self._contact_residual_ufl, entity_maps=[c.slave.entity_map for c in self.contacts]
            )
        return self.operator.assemble(self._contact_residual_form)

    @collective
    def contact_force(self, k: int | None = None) -> np.ndarray:
        """Resultant contact force on the slave body, ``int (t_N nu - P(q)) dS_o`` (all pairs;
        the frictional part only with friction)."""
        pairs = self.contacts if k is None else [self.contacts[k]]
        return sum((c.integrate("traction") for c in pairs), np.zeros(self.gdim))

    @collective
    def stored_energy(self) -> float:
        """Elastic energy ``sum_b int psi_b(F) dV`` of all bodies (reference volume), for
        hyperelastic bodies (an elastoplastic one raises)."""
        plastic = sorted(tag for b in self.bulks for tag in b.histories)
        if plastic:
            raise ValueError(
                "stored_energy covers hyperelastic bodies only; this scene has "
                f"elastoplastic bodies (cell tags {plastic})"
            )
        return sum(b.stored_energy() for b in self.bulks)

    @collective
    def active_points(self) -> int:
        """Number of slave quadrature points in contact (all pairs)."""
        return int(self.comm.allreduce(sum(c.active().sum() for c in self.contacts), MPI.SUM))

    @property
    def search_time(self) -> float:
        """Seconds spent in the closest-point projection so far."""
        return sum(c.search_time for c in self.contacts)
