"""What the user writes for a contact pair: the two surfaces, the laws and the rules."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from mpi4py import MPI

from contact_ufl.contact.obstacles import RigidObstacle
from contact_ufl.contact.quadrature import QUADRATURE_RULES
from contact_ufl.contact.slave import ISO_MULTIPLIER, MULTIPLIER_DEGREES
from contact_ufl.errors import check_positive, collective_check

#: Values of :attr:`ContactPair.geometric_traction`.
GEOMETRIC_TRACTIONS = ("bracket", "multiplier")


@dataclass(frozen=True)
class ContactPair:
    """A contact pair of a scene.

    Parameters
    ----------
    slave
        Facet tag (or physical-group name) of the slave (contactor) surface; it carries the
        multipliers. Make it the finer of the two surfaces. The same surface as ``master``
        (same tag, same domain) makes a self-contact pair (frictionless, solid bodies): each
        point pairs with the facets of the surface that share no vertex with its own facet
        and whose normals oppose its own (no tolerance to set).
    master
        Facet tag (or physical-group name) of the master (target) surface, or a rigid
        obstacle (:class:`~contact_ufl.contact.obstacles.RigidPlane`, ``RigidSphere``,
        ``RigidCylinder``): an analytic surface with a prescribed motion, no mesh and no
        unknowns.
    eps_N
        Normal augmentation parameter (> 0). It does not change the exact solution. Default
        (``None``): ``E / L``, with ``E`` the smaller Young's modulus of the two bodies and
        ``L`` the diameter of the slave surface: a length of the scene, not of the mesh, so
        that it does not grow under refinement.
    mu
        Coulomb friction coefficient (>= 0). Friction terms and the tangential multiplier
        exist only where ``mu > 0``.
    eps_T
        Tangential augmentation parameter (> 0), defaults to ``eps_N``.
    search_radius
        Distance beyond which a slave point is known not to be in contact in a Newton
        iteration; only master facets within it are searched. Defaults to a quarter of the
        diagonal of the bounding box of the two surfaces.
    quadrature_degree
        Degree of the Gauss rule of the contact integrals (defaults to ``2 p + 1`` for
        displacement degree ``p``).
    quadrature_subdivisions
        Repeat that rule on a uniform split of every slave facet (composite rule): the master
        facet edges put kinks into the integrand that one Gauss rule resolves poorly.
    quadrature_rule
        ``"gauss"`` (default) or ``"lobatto"`` (Gauss-Lobatto-Legendre, intervals and
        quadrilaterals): the Lobatto points include the vertices of the slave facets, so a
        slave edge or corner that meets the master surface (the tip of a beam) is itself a
        contact point and cannot sink into the master between Gauss points.
    master_normal
        ``"facet"``: the normal of the master facet. ``"smoothed"``: the normal interpolated
        over the facet from averaged nodal normals, continuous from one facet to the next; a
        slave point sliding over a master vertex or edge then meets no jump of the contact
        force's direction (large sliding, ironing, deep indentation). The nodal normals
        depend on the neighbouring nodes, which are gathered with the facet's own: in 2D the
        nodes before and after the segment, in 3D (triangles, bilinear quadrilaterals;
        area-weighted nodal normals) the ring of facets around each node (at most
        :data:`~contact_ufl.contact.master.MAX_FACETS_AROUND_NODE` facets). ``None``
        (default): :meth:`resolved_master_normal`, ``"smoothed"`` on a 2D solid master of a
        degree-1 displacement, else ``"facet"``. In 2D the smoothed normal costs little, and
        the facet normal makes Newton cycle between the normals of neighbouring segments
        once the master curves. In 3D it costs about twice the time per iteration (each
        point carries ``nn (K + 2)`` master nodes, 27 on tetrahedra) and minutes of form
        compilation: ask for it there by name (see :doc:`/guide/contact`). With degree 2 the
        normal is the quadratic facet's (no smoothed normal); membranes, self-contact and
        rigid obstacles keep the facet (or the obstacle's exact) normal. On a flat master
        both normals are the same.
    slave_domain, master_domain
        The domains (meshes) of the scene that hold the two surfaces: an index in
        :attr:`Scene.parts <contact_ufl.scene.Scene.parts>` or a domain's name. Needed only
        to tell apart integer tags in a scene of several meshes; by default a surface is
        found by its group name. The scene sets both to indices when it is made.
    multiplier_degree
        The continuous multipliers on the slave surface: 1 (default: Lagrange P1, also with a
        degree-2 displacement: smooth and non-negative nodal pressures on 3-node segments and
        6-node triangles), 2 (Lagrange P2, with a degree-2 displacement only) or ``"iso"``
        (:data:`~contact_ufl.contact.slave.ISO_MULTIPLIER`, with a degree-2 displacement
        only): P1-iso-P2, piecewise linear on the once-refined slave facets, one node at each
        node of the displacement's trace (the resolution of the P2 nodes, h / 2); the contact
        rule is then composite over the refined facets (``quadrature_subdivisions`` rounded
        up to an even number: 1 -> 2, 3 -> 4). See :doc:`/quadratic-contact` for the
        comparison.
    geometric_traction
        The normal traction that weights the master's geometric terms of the Newton tangent
        (the variation of the master normal and the sliding of the closest point; the
        residual, and so the solution, is the same either way): ``"bracket"`` (default) the
        consistent ``t_N = <lambda_N + eps_N g>``, ``"multiplier"`` ``min(t_N,
        max(lambda_N, 0))`` (a meshed master only). The two differ where a point is deep in
        the master with a small multiplier, as after the contact-free first iterate of a
        step that starts open: that iterate's penetration ``g`` weights the terms by
        ``eps_N g``, of the order of the bulk stiffness ``E / h`` once ``eps_N g h / E``
        nears 1 (the 3D Hertz with ``eps_N = E / h`` and a step's depth near a master
        element), and the next iterate crushes the master's facets; there ``"multiplier"``
        converges with full Newton steps to the same solution (see :doc:`/guide/robustness`).
    overlap_ramp
        Where the surfaces overlap in the reference configuration (a press fit, see
        :attr:`ContactInterface.initial_overlap
        <contact_ufl.contact.interface.ContactInterface.initial_overlap>`): ``None``
        (default) resolves the whole overlap in the first load step; a pseudo-time ``t_r``
        ramps it in linearly, the gap the laws see being ``g - (1 - t / t_r) g0`` until
        ``t_r``, ``g0`` the initial overlap of each slave point (see
        :doc:`/guide/contact`).
    """

    slave: int | str
    master: int | str | RigidObstacle
    eps_N: float | None = None
    mu: float = 0.0
    eps_T: float | None = None
    search_radius: float | None = None
    quadrature_degree: int | None = None
    quadrature_subdivisions: int = 1
    quadrature_rule: str = "gauss"
    master_normal: str | None = None
    slave_domain: int | str | None = None
    master_domain: int | str | None = None
    multiplier_degree: int | str = 1
    geometric_traction: str = "bracket"
    overlap_ramp: float | None = None
    #: how messages name the slave and the master surface (set by the scene: the physical
    #: group's name and its tag, where the surface has a name)
    labels: tuple[str, str] = field(default=("", ""), repr=False, compare=False)

    def surface(self, side: str) -> str:
        """The ``"slave"`` or ``"master"`` surface in words for a message:
        ``'top' (tag 3)`` where its group has a name, else ``tag 3`` (or the obstacle)."""
        key = getattr(self, side)
        if isinstance(key, RigidObstacle):
            return f"the {type(key).__name__}"
        return self.labels[side == "master"] or f"tag {key}"

    @property
    def frictional(self) -> bool:
        """Whether the pair has Coulomb friction (``mu > 0``)."""
        return self.mu > 0.0

    @property
    def self_contact(self) -> bool:
        """Whether slave and master are the same surface of the same domain (self-contact:
        a point pairs only with the facets that share no vertex with its own and face it)."""
        return not self.on_obstacle and (self.slave_domain, self.slave) == (
            self.master_domain,
            self.master,
        )

    @property
    def iso_multipliers(self) -> bool:
        """Whether the multipliers are P1-iso-P2 (``multiplier_degree="iso"``)."""
        return self.multiplier_degree == ISO_MULTIPLIER

    @property
    def on_obstacle(self) -> bool:
        """Whether the master side is a rigid obstacle."""
        return isinstance(self.master, RigidObstacle)

    def resolved_master_normal(self, gdim: int, degree: int, membrane_master: bool) -> str:
        """The master normal of the pair: ``master_normal`` if given, else (``None``)
        ``"smoothed"`` on a meshed solid master (not a membrane, not self-contact) of a 2D
        scene with a degree-1 displacement, and ``"facet"`` otherwise: 3D (where the smoothed
        normal costs twice the time per Newton iteration and minutes of form compilation),
        degree 2 (the normal of the quadratic facet: no smoothed normal), membranes and
        self-contact (facet normal), rigid obstacles (their exact normal).

        Parameters
        ----------
        gdim
            Geometric dimension of the scene (2 or 3).
        degree
            Degree of the displacement of the master body.
        membrane_master
            Whether the master surface is a membrane's (two-sided).
        """
        if self.master_normal is not None:
            return self.master_normal
        smooth = (
            gdim == 2
            and degree == 1
            and not (self.on_obstacle or self.self_contact or membrane_master)
        )
        return "smoothed" if smooth else "facet"

    def validate(self, comm: MPI.Comm) -> None:
        """Raise a clear error (on every rank) for invalid parameters."""
        collective_check(
            comm,
            not isinstance(self.slave, RigidObstacle),
            f"a rigid obstacle cannot be the slave of a contact pair (it has no mesh to carry "
            f"the multipliers): make it the master, got slave = {type(self.slave).__name__}",
        )
        if self.eps_N is not None:
            check_positive(comm, eps_N=self.eps_N)
        collective_check(
            comm, bool(0.0 <= self.mu < math.inf), f"mu must be >= 0 and finite, got mu = {self.mu}"
        )
        if self.eps_T is not None:
            check_positive(comm, eps_T=self.eps_T)
        if self.search_radius is not None:
            check_positive(comm, search_radius=self.search_radius)
        if self.overlap_ramp is not None:
            check_positive(comm, overlap_ramp=self.overlap_ramp)
        collective_check(
            comm,
            int(self.quadrature_subdivisions) >= 1,
            f"quadrature_subdivisions must be >= 1, got {self.quadrature_subdivisions}",
        )
        collective_check(
            comm,
            self.quadrature_rule in QUADRATURE_RULES,
            f"quadrature_rule must be one of {sorted(QUADRATURE_RULES)}, "
            f"got {self.quadrature_rule!r}",
        )
        collective_check(
            comm,
            self.master_normal in (None, "facet", "smoothed"),
            f"master_normal must be 'facet', 'smoothed' or None (the default: smoothed on a 2D "
            f"solid master of degree 1, else facet), got {self.master_normal!r}",
        )
        collective_check(
            comm,
            self.geometric_traction in GEOMETRIC_TRACTIONS,
            f"geometric_traction must be one of {GEOMETRIC_TRACTIONS}, "
            f"got {self.geometric_traction!r}",
        )
        collective_check(
            comm,
            self.multiplier_degree in MULTIPLIER_DEGREES,
            f"multiplier_degree must be 1 or 2 (Lagrange) or {ISO_MULTIPLIER!r} (P1-iso-P2), "
            f"got {self.multiplier_degree!r}",
        )
        collective_check(
            comm,
            not (self.on_obstacle and self.master_normal == "smoothed"),
            f"master_normal={self.master_normal!r} applies to a meshed master surface; a rigid "
            "obstacle has its own exact normal",
        )
        collective_check(
            comm,
            not (self.self_contact and self.frictional),
            "a self-contact pair (slave and master the same surface, tag "
            f"{self.slave}) is frictionless for now: got mu = {self.mu}",
        )
