"""One contact pair's terms of the weak form, composed of its parts.

A :class:`ContactInterface` is what the problem assembles for one :class:`.ContactPair`:

* the slave side (:class:`.SlaveSurface`): the slave facets, their quadrature points and the
  data carried at them;
* the master side (:class:`.MeshMaster`): a meshed master surface, with
* the search (:class:`.ClosestPointSearch`): the Python closest-point mapping, and
* the kinematics (:class:`.MeshKinematics`): the projected point, the normal, the gap and
  the master virtual displacement in UFL;
* or, for a rigid obstacle as the master (:mod:`.obstacles`), its kinematics
  (:class:`.ObstacleKinematics`), with no fields and no unknowns;
* the normal law (:class:`.NormalLaw`) and, where ``mu > 0``, the Coulomb law
  (:class:`.CoulombLaw`).

Its terms (``docs/theory.md``, times -1 so that the bulk term reads ``+ int Pi : Grad U*``):

    - int_{S_oc} T . (U1* - U2*(Y)) dS_o,     T = t_N nu - P(q)
    - int_{S_oc} (lambda_N - t_N) lambda_N* dS_o  [ - int (lambda_T - P(q)) . lambda_T* dS_o ]

assembled over the fields ``[xhat, lambda_N (, lambda_T, xhat_n)]`` after the displacement;
the problem maps them to the unknowns through the chain operator (:mod:`contact_ufl.layout`).
"""

from __future__ import annotations

import dataclasses

import basix
import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import jit
from contact_ufl.contact.coulomb import CoulombLaw
from contact_ufl.contact.facets import scalar_element
from contact_ufl.contact.kinematics import MeshKinematics
from contact_ufl.contact.master import MeshMaster
from contact_ufl.contact.normal import NormalLaw
from contact_ufl.contact.obstacles import ObstacleKinematics
from contact_ufl.contact.pair import ContactPair
from contact_ufl.contact.search import ClosestPointSearch, Projection
from contact_ufl.contact.slave import SlaveSurface
from contact_ufl.errors import collective_check
from contact_ufl.layout import StackedLayout
from contact_ufl.mpi import global_diameter


def check_multiplier_degree(comm: MPI.Comm, pair: ContactPair, degree: int) -> None:
    """Raise (on every rank) if the pair's multipliers do not fit a degree-``degree``
    displacement: Lagrange multipliers of at most that degree, P1-iso-P2 with degree 2
    only (its nodes are those of the P2 trace)."""
    if pair.iso_multipliers:
        collective_check(
            comm,
            degree == 2,
            f"multiplier_degree={pair.multiplier_degree!r} (P1-iso-P2) of the pair with slave "
            f"surface {pair.surface('slave')} needs a degree-2 displacement (got degree {degree}): "
            "use multiplier_degree=1 with a degree-1 displacement",
        )
        return
    collective_check(
        comm,
        pair.multiplier_degree <= degree,
        f"multiplier_degree={pair.multiplier_degree} of the pair with slave surface (tag "
        f"{pair.slave}) needs a displacement of that degree (got degree {degree})",
    )


class ContactInterface:
    """The contact terms of one pair, and what its converged state says.

    Parameters
    ----------
    u
        The displacement of the slave's mesh.
    facet_tags
        The tags of the contact surfaces of that mesh: its facet tags, or the cell tags of a
        membrane (string) mesh, whose cells are its contact surface.
    pair
        The contact pair (integer tags).
    modulus
        Young's modulus of the softer of the two bodies: the scale of the default ``eps_N``
        (needed only when ``pair.eps_N`` is ``None``).
    master_u, master_facet_tags
        The displacement and contact-surface tags of the master's mesh (default: those of
        the slave: both surfaces on one mesh).
    master_block
        The block of ``master_u`` in the unknowns of the problem (one block per mesh).
    master_orientation
        (membrane master) The sign per cell of the membrane's oriented normal
        (:func:`contact_ufl.membranes.cell_orientation`).

    Attributes
    ----------
    slave
        The slave side.
    master
        The master side: a :class:`.MeshMaster`, or the rigid obstacle of the pair.
    kinematics
        The master side as the laws see it: :class:`.MeshKinematics` or
        :class:`.ObstacleKinematics`.
    normal, friction
        The normal law and the Coulomb law (``None`` without friction).
    """

    def __init__(
        self,
        u: dolfinx.fem.Function,
        facet_tags: dolfinx.mesh.MeshTags,
        pair: ContactPair,
        modulus: float | None = None,
        master_u: dolfinx.fem.Function | None = None,
        master_facet_tags: dolfinx.mesh.MeshTags | None = None,
        master_block: int = 0,
        master_orientation: dolfinx.fem.Function | None = None,
    ):
        V = u.function_space
        mesh = V.mesh
        comm = mesh.comm
        pair.validate(comm)
        pair = with_master_normal(pair, u, facet_tags, master_u, master_facet_tags)
        self.u, self.V, self.pair = u, V, pair
        self.gdim = mesh.geometry.dim
        degree = V.ufl_element().embedded_superdegree
        check_degrees(u, pair, facet_tags, "slave")
        if not pair.on_obstacle:
            other = u if master_u is None else master_u
            other_tags = facet_tags if master_facet_tags is None else master_facet_tags
            check_degrees(other, pair, other_tags, "master")
            master_degree = other.function_space.ufl_element().embedded_superdegree
            collective_check(
                comm,
                master_degree == degree,
                f"the slave surface {pair.surface('slave')} has a degree-{degree} displacement "
                f"and the master surface {pair.surface('master')} a degree-{master_degree} "
                "one: a contact pair "
                "needs one displacement degree on both sides",
            )
        qdeg = pair.quadrature_degree or 2 * degree + 1
        check_multiplier_degree(comm, pair, degree)
        self.slave = SlaveSurface(
            V,
            facet_tags,
            pair.slave,
            qdeg,
            pair.quadrature_subdivisions,
            pair.quadrature_rule,
            pair.multiplier_degree,
        )
        #: the master side as the laws see it (gap, normal, projected point, master fields)
        if pair.on_obstacle:
            self.kinematics = self._obstacle_side(pair)
        else:
            master_u = u if master_u is None else master_u
            master_tags = facet_tags if master_facet_tags is None else master_facet_tags
            self.kinematics = self._mesh_side(
                master_u, master_tags, master_block, master_orientation, pair
            )
        eps_N = pair.eps_N if pair.eps_N is not None else default_eps(self.slave, modulus)
        self.normal = NormalLaw(self.slave, eps_N, self.round_off)
        #: the initial overlap of each slave point (a positive reference gap), and the gap
        #: the laws see: less the part of it not yet ramped in (``ContactPair.overlap_ramp``)
        self.overlap = np.where(self.reference.facet >= 0, np.maximum(self.reference.gap, 0), 0)
        if self.master_two_sided:
            self.overlap[:] = 0.0  # either side of a membrane master may face: no inside
        self.gap = self.kinematics.gap
        self._remaining = None
        if pair.overlap_ramp is not None:
            self._remaining = dolfinx.fem.Constant(mesh, 1.0)
            overlap = dolfinx.fem.Function(self.slave.point_space(()))
            self.slave.set_at_points(overlap, self.overlap)
            self.gap = self.gap - overlap * self._remaining
        self.t_N = self.normal.traction(self.gap, self.kinematics.mask)
        #: the Coulomb law, or ``None`` for a frictionless pair
        self.friction = (
            CoulombLaw(
                self.kinematics,
                self.t_N,
                pair.mu,
                pair.eps_T or eps_N,
                self.normal.in_contact_condition(self.gap, self.kinematics.mask),
                self.round_off,
            )
            if pair.frictional
            else None
        )
        self._surface_forms: dict[str, list[dolfinx.fem.Form]] = {}
        #: the shift of the traction in the master geometric terms of the tangent (None:
        #: the consistent tangent; see :meth:`tangent_residuals`)
        self.geometric_shift = None
        if pair.geometric_traction == "multiplier" and not pair.on_obstacle:
            self.geometric_shift = dolfinx.fem.Function(self.slave.point_space(()))

    def _mesh_side(
        self,
        master_u: dolfinx.fem.Function,
        facet_tags: dolfinx.mesh.MeshTags,
        block: int,
        orientation: dolfinx.fem.Function | None,
        pair: ContactPair,
    ) -> MeshKinematics:
        """The kinematics of a meshed master surface (with its search)."""
        comm, gdim = self.V.mesh.comm, self.gdim
        smoothed = pair.master_normal == "smoothed"
        self.master = MeshMaster(master_u, facet_tags, pair.master, smoothed, block, orientation)
        size = global_diameter(
            comm,
            np.vstack([self.slave.X.reshape(-1, gdim), self.master.X_nodes.reshape(-1, gdim)]),
        )
        #: a gap within round-off of zero, ``1e-12`` of the surfaces' size (see ``macaulay``)
        self.round_off = 1e-12 * size
        #: the margin of the points whose master terms enter the tangent (``_engaged_only``)
        self.engaged_margin = 1e-6 * size
        radius = pair.search_radius or 0.25 * size
        collective_check(
            comm,
            not (pair.self_contact and (self.master.two_sided or self.slave.membrane)),
            f"self-contact of a membrane ({pair.surface('slave')}) is not implemented: its "
            "two sides would both have to be searched",
        )
        search = ClosestPointSearch(
            self.slave, self.master, radius, self.round_off, pair.self_contact
        )
        kinematics = MeshKinematics(self.u, self.slave, self.master, search)
        self.reference = kinematics.check_facing(
            f"slave surface {pair.surface('slave')} of the pair with master surface "
            f"{pair.surface('master')}"
            if not pair.self_contact
            else f"the self-contact surface {pair.surface('slave')}"
        )
        return kinematics

    def _obstacle_side(self, pair: ContactPair) -> ObstacleKinematics:
        """The kinematics of a rigid obstacle: the sizes are those of the slave surface."""
        comm, gdim = self.V.mesh.comm, self.gdim
        self.master = obstacle = pair.master
        obstacle.validate(comm, gdim)
        size = global_diameter(comm, self.slave.X.reshape(-1, gdim))
        self.round_off = 1e-12 * size
        radius = pair.search_radius or 0.25 * size
        kinematics = ObstacleKinematics(self.u, self.slave, obstacle, radius)
        self.reference = kinematics.check_facing(
            f"slave surface {pair.surface('slave')} of the pair with a {type(obstacle).__name__}"
        )
        return kinematics

    # -- what the problem assembles ----------------------------------------------------
    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """Fields of the assembled system this pair adds (after the displacement)."""
        own = [*self.kinematics.fields, self.normal.lambda_N]
        return own + (self.friction.fields if self.friction else [])

    @property
    def unknowns(self) -> list[dolfinx.fem.Function]:
        """Unknowns this pair adds (after the displacement)."""
        own = [self.normal.lambda_N]
        return own + (self.friction.unknowns if self.friction else [])

    def traction(self) -> ufl.core.expr.Expr:
        """Contact traction on the slave surface, ``T = t_N nu - P(q)`` (``-P(q)`` only with
        friction)."""
        T = self.t_N * self.kinematics.nu
        return T + self.friction.traction() if self.friction else T

    def residuals(self, v: ufl.Argument) -> tuple[ufl.Form, list[ufl.Form]]:
        """Contact part of the displacement residual, and the residuals of :attr:`fields`."""
        traction = self.traction()
        F_u = -ufl.dot(traction, v) * self.slave.ds
        own = [*self.kinematics.master_residuals(traction), self.normal.residual(self.t_N)]
        return F_u, own + (self.friction.residuals() if self.friction else [])

    def tangent_residuals(self, v: ufl.Argument) -> tuple[ufl.Form, list[ufl.Form]] | None:
        """Terms added to :meth:`residuals` for the tangent only: the virtual work of the
        traction ``c nu``, ``c`` a point coefficient (:attr:`geometric_shift`), whose
        derivative is ``c`` times the master geometric terms (normal variation, sliding of
        the closest point). ``None`` without a shift."""
        if self.geometric_shift is None:
            return None
        T = self.geometric_shift * self.kinematics.nu
        F_u = -ufl.dot(T, v) * self.slave.ds
        return F_u, self.kinematics.master_residuals(T)

    def _set_geometric_shift(self) -> None:
        if self.geometric_shift is None:
            return
        t_N = self.normal.traction_at_points(self.projection)
        lam = np.maximum(self.normal.multiplier_at_points(), 0.0)
        self.slave.set_at_points(self.geometric_shift, np.minimum(t_N, lam) - t_N)

    def update(
        self, x: PETSc.Vec, layout: StackedLayout
    ) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """Search, refresh the point data of the kinematics, and move the slip reference
        with the master (:class:`~contact_ufl.coupling.Coupling`).

        Parameters
        ----------
        x
            The unknowns (whose values the displacements hold).
        layout
            Layout of the unknowns (one displacement block per mesh, then the multipliers).

        Returns
        -------
        The gathered fields: pairs of a field and, for every owned dof of it (unrolled, local
        order), the stacked index of the (master) displacement unknown it gathers, or -1.
        """
        gathers = self.kinematics.update(layout)
        if self._remaining is not None:  # the laws' gap: the overlap not yet ramped in off
            proj = self.kinematics.projection
            shift = self.overlap * float(self._remaining.value)
            proj.gap = np.where(proj.facet >= 0, proj.gap - shift, proj.gap)
        self._set_geometric_shift()
        gathers += self.friction.gathers() if self.friction else []
        gathers = gathers if self.pair.on_obstacle else self._engaged_only(gathers)
        if self.friction:
            self.friction.follow(x, gathers)
        return gathers

    def _engaged_only(
        self, gathers: list[tuple[dolfinx.fem.Function, np.ndarray]]
    ) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """The gathers of the points in contact (the bracket positive, within a margin of a
        millionth of the surfaces' size, far above the round-off between these NumPy values
        and the forms'); -1 for the others. Their normal and frictional tractions and the
        derivatives of both are exactly zero, so their rows of the master's residual are zero
        and they would add only structural zeros to ``T^T K T``: couplings of the two bodies
        that cost fill in the factorisation, and pairing changes away from the contact that
        cost analyses: dropping them makes a large 3D Newton iteration markedly cheaper, with
        the same iterations and answer (see ``docs/developer.md``). The values of the gathered
        fields stay those of the search (the last step's master nodes of a frictional point
        out of contact are not moved with the master: its slip is not used)."""
        proj = self.kinematics.projection
        engaged = self.normal.in_contact(proj, margin=self.engaged_margin)
        masked = []
        for f, cols in gathers:
            bs = f.function_space.dofmap.index_map_bs
            at_points = np.repeat(engaged[:, None], bs, axis=1)
            mask = self.slave.unrolled(f.function_space, at_points, fill=False)
            masked.append((f, np.where(mask, cols, -1)))
        return masked

    def pattern_gathers(self) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """A superset of the gathers of the last :meth:`update` (each dof may gather several
        unknowns: ``(ndofs, width)`` arrays, ``-1`` padded) from which the solver makes its
        sparsity pattern: the master nodes of the points' facets and of those beside them (see
        :meth:`MeshKinematics.pattern_gathers
        <contact_ufl.contact.kinematics.MeshKinematics.pattern_gathers>`)."""
        wide = self.kinematics.pattern_gathers()
        return wide + (self.friction.gathers() if self.friction else [])

    def held_multipliers(self, prescribed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The multiplier dofs to hold at zero where the slave's displacement is prescribed.

        A multiplier at a node whose displacement is prescribed along the normal constrains
        what the support holds already: the two equations are dependent and the tangent is
        singular (likewise ``lambda_T`` where the tangential displacement is prescribed, at a
        sticking point). Those multipliers are held at zero; the contact there is carried by
        the neighbouring nodes and the supports. Where the prescribed axes span the whole
        tangent plane every component of ``lambda_T`` is held; where they span only part of
        it (3D), only the prescribed tangential components (holding all would remove the
        friction along the free directions).

        Parameters
        ----------
        prescribed
            Which components of each (local) dof block of the slave's displacement are
            prescribed, ``(blocks, gdim)``.

        Returns
        -------
        Owned local indices of ``lambda_N`` and of ``lambda_T`` (unrolled; empty without
        friction) to hold.
        """
        held = prescribed[self.slave.node_blocks()].astype(float)  # (n, gdim)
        projector = self.slave.nodal_normal_projectors()
        normal_k = np.einsum("nkk->nk", projector)  # the normal's share of each axis
        normal_part = np.einsum("nk,nk->n", held, normal_k)
        tangential_k = held * (1.0 - normal_k)  # prescribed axes along the tangent plane
        tangential_part = tangential_k.sum(axis=1)
        rows_N = np.flatnonzero(normal_part > 0.5)
        if not self.friction:
            return rows_N, np.zeros(0, dtype=np.int64)
        # the whole tangent plane prescribed: every component of lambda_T held (in 2D any
        # prescribed tangential axis); only some tangential axes (3D: u_z = 0 on a plane-strain
        # face, a symmetry plane across the slip): only those components, the slave still
        # slides, with friction, along the others
        whole = tangential_part > self.gdim - 1.5
        components = np.where(whole[:, None], True, tangential_k > 0.5)
        nodes_T, axes = np.nonzero(components)
        rows_T = nodes_T * self.gdim + axes
        return rows_N, rows_T

    # -- pseudo-time and the step protocol ------------------------------------------------
    def set_time(self, t: float) -> None:
        """Set the pseudo-time of the master side (the pose of a rigid obstacle) and of the
        initial overlap's ramp."""
        self.kinematics.set_time(t)
        if self._remaining is not None:
            self._remaining.value = max(0.0, 1.0 - t / self.pair.overlap_ramp)

    @property
    def master_two_sided(self) -> bool:
        """Whether the master is a membrane (either side may face a slave point)."""
        return not self.pair.on_obstacle and self.master.two_sided

    @property
    def initial_overlap(self) -> float:
        """The largest overlap of the two surfaces in the reference configuration (a press
        fit; 0 where they do not overlap), over all ranks (collective)."""
        return float(self.V.mesh.comm.allreduce(self.overlap.max(initial=0.0), MPI.MAX))

    def begin_step(self) -> None:
        """Start a load step from the last committed state."""
        if self.friction:
            self.friction.begin_step()

    def commit(self, x) -> None:
        """Accept the current state as the converged state of a load step."""
        if self.friction:
            self.friction.commit(x, self.normal_traction_at_points(), self.active())

    # -- results ------------------------------------------------------------------------
    @property
    def projection(self) -> Projection:
        """The closest points of the last search."""
        return self.kinematics.projection

    @property
    def search_time(self) -> float:
        """Seconds spent in the closest-point search so far."""
        return self.kinematics.search_time

    @property
    def lambda_N(self) -> dolfinx.fem.Function:
        """The normal multiplier."""
        return self.normal.lambda_N

    @property
    def ds(self) -> ufl.Measure:
        """The contact measure over the slave facets."""
        return self.slave.ds

    def surface_integrands(self) -> dict[str, ufl.core.expr.Expr]:
        """Named integrands over the slave surface for :meth:`integrate`: ``"traction"``, the
        whole contact traction (:meth:`traction`), ``"normal"``, its normal-pressure part
        ``t_N nu``, and with friction ``"friction"`` and ``"dissipation"``
        (:meth:`.CoulombLaw.surface_integrands`)."""
        own = {"traction": self.traction(), "normal": self.t_N * self.kinematics.nu}
        return own | (self.friction.surface_integrands() if self.friction else {})

    def integrate(self, name: str) -> np.ndarray:
        """``int integrand dS_o`` over the slave surface, summed over all ranks, of the
        integrand ``name`` of :meth:`surface_integrands` (its forms compiled once)."""
        if name not in self._surface_forms:
            expr = self.surface_integrands()[name]
            parts = [expr[i] for i in range(expr.ufl_shape[0])] if expr.ufl_shape else [expr]
            self._surface_forms[name] = [
                jit.form(e * self.ds, entity_maps=[self.slave.entity_map]) for e in parts
            ]
        local = np.array([dolfinx.fem.assemble_scalar(f) for f in self._surface_forms[name]])
        return self.V.mesh.comm.allreduce(local, MPI.SUM)

    def multiplier_at_points(self) -> np.ndarray:
        """lambda_N at the owned slave quadrature points, ``(ncells * nq,)``."""
        return self.normal.multiplier_at_points()

    def active(self) -> np.ndarray:
        """Mask of the owned slave quadrature points in contact (``lambda_N + eps_N g > 0``,
        or within round-off of it)."""
        return self.normal.in_contact(self.projection)

    def normal_traction_at_points(self) -> np.ndarray:
        """``t_N = <lambda_N + eps_N g>`` at the owned slave points (0 where unpaired)."""
        return self.normal.traction_at_points(self.projection)

    def traction_at_points(self) -> np.ndarray:
        """Contact traction on the slave body at the owned slave points, ``(n, gdim)``: the
        integrand of :meth:`traction` (nominal, per unit reference area)."""
        t_N = self.normal_traction_at_points()
        T = t_N[:, None] * self.projection.normal
        if not self.friction:
            return T
        return T + self.friction.traction_at_points(t_N, self.active())

    def stick(self) -> np.ndarray:
        """Mask of the owned points in stick (with friction; see :meth:`.CoulombLaw.stick`)."""
        return self.friction.stick(self.normal_traction_at_points(), self.active())


#: What contact supports: (displacement degree, geometry degree) of a body's mesh.
SUPPORTED_DEGREES = ((1, 1), (2, 1), (2, 2))


def check_degrees(
    u: dolfinx.fem.Function, pair: ContactPair, surface_tags: dolfinx.mesh.MeshTags, side: str
) -> None:
    """Raise (on every rank) unless the displacement ``u`` of one side of ``pair`` and its
    mesh are of a supported degree (:data:`SUPPORTED_DEGREES`): linear facets of a degree-1
    displacement, or the quadratic facets of a degree-2 Lagrange displacement (3-node
    segments, 6-node triangles, 9-node quadrilaterals of quadratic hexahedra) on a straight
    or curved (degree-2) geometry. The quadratic facets are not implemented for membranes,
    the smoothed master normal and serendipity (8-node) quadrilaterals."""
    mesh = u.function_space.mesh
    comm = mesh.comm
    degree = u.function_space.ufl_element().embedded_superdegree
    family = scalar_element(u.function_space).family
    collective_check(
        comm,
        family == basix.ElementFamily.P,
        f"the {side} body's displacement is of the {family.name} family: contact supports "
        "Lagrange displacements (of degree 1 or 2; 8-node serendipity facets are not "
        "implemented)",
    )
    geometry_degree = mesh.geometry.cmaps[0].degree
    tag = pair.surface(side)
    supported = (
        "contact supports a degree-1 displacement on a degree-1 geometry, or a degree-2 "
        "displacement on a degree-1 or degree-2 geometry"
    )
    collective_check(
        comm,
        (degree, geometry_degree) in SUPPORTED_DEGREES,
        f"the {side} surface {tag} has a degree-{degree} displacement on a "
        f"degree-{geometry_degree} geometry: {supported}",
    )
    if degree == 1:
        return
    tdim = mesh.topology.dim
    collective_check(
        comm,
        surface_tags.dim == tdim - 1,
        f"the {side} surface {tag} is a membrane's: membranes in contact need a "
        "degree-1 displacement",
    )
    collective_check(
        comm,
        side == "slave" or pair.master_normal == "facet",
        f'master_normal="{pair.master_normal}" of the pair with master surface {tag} '
        "needs a degree-1 displacement: with degree 2 the master normal is that of the "
        'quadratic facet (master_normal="facet")',
    )


def with_master_normal(
    pair: ContactPair,
    u: dolfinx.fem.Function,
    facet_tags: dolfinx.mesh.MeshTags,
    master_u: dolfinx.fem.Function | None,
    master_facet_tags: dolfinx.mesh.MeshTags | None,
) -> ContactPair:
    """``pair`` with its master normal resolved (:meth:`.ContactPair.resolved_master_normal`:
    the default ``None`` becomes ``"smoothed"`` or ``"facet"``)."""
    master_u = u if master_u is None else master_u
    tags = facet_tags if master_facet_tags is None else master_facet_tags
    mesh = master_u.function_space.mesh
    normal = pair.resolved_master_normal(
        mesh.geometry.dim,
        master_u.function_space.ufl_element().embedded_superdegree,
        tags.dim == mesh.topology.dim,
    )
    return dataclasses.replace(pair, master_normal=normal)


def default_eps(slave: SlaveSurface, modulus: float | None) -> float:
    """The default ``eps_N = E / L``: ``E`` the Young's modulus of the softer body of the
    pair, ``L`` the diameter of the slave surface (a length of the scene, not of the mesh)."""
    comm = slave.V.mesh.comm
    collective_check(
        comm,
        modulus is not None and modulus > 0.0,
        "the default eps_N needs the Young's modulus of the bodies of the pair",
    )
    return modulus / global_diameter(comm, slave.X.reshape(-1, slave.V.mesh.geometry.dim))
