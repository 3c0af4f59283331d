"""A scene: meshes with their bodies, materials, supports and loads, and the contact pairs
between them.

A :class:`Domain` is one mesh and what lives on it: bodies (cell tags and materials),
supports and loads. A :class:`Scene` is one or more domains and the contact pairs between
their surfaces. A one-mesh scene gives its mesh, tags, bodies, supports and loads directly
(``Scene(mesh, cell_tags, facet_tags, bodies, contacts, ...)``); a scene of bodies on
meshes of their own lists them as ``domains`` (each mesh then has its own displacement
field). Both may be combined: the scene's own mesh is then the first domain.

Tags may be given by integer or by the name of their physical group (gmsh): names are
resolved to integers once, when the scene is made, so the forms and the solver see integers
only. A contact pair's surfaces are found in the domain whose facet groups have their name
(or in the domain the pair names: ``ContactPair(slave_domain=..., master_domain=...)``).
:meth:`Scene.from_gmsh` and :meth:`Domain.from_gmsh` read a ``.msh`` file or a live gmsh
model in one call.
"""

from __future__ import annotations

import dataclasses
import difflib
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl import mesh_checks
from contact_ufl.contact import ContactPair
from contact_ufl.contact.obstacles import RigidObstacle
from contact_ufl.control import VolumeControl
from contact_ufl.errors import ContactInputError, collective_check
from contact_ufl.loads import BodyForce, FollowerForce, FollowerPressure, Load, evaluate
from contact_ufl.materials import Hyperelastic
from contact_ufl.membranes import MembraneLaw, check_manifold
from contact_ufl.plasticity import J2Plasticity

if TYPE_CHECKING:
    from contact_ufl.gmshio import MeshData
    from contact_ufl.loads import Dirichlet

#: A tag: its integer value or the name of its physical group.
Tag = int | str


@dataclass(frozen=True)
class Body:
    """A body: the cells with ``tag`` (an integer or a physical group name) and their
    material."""

    tag: int | str
    material: Hyperelastic | J2Plasticity | MembraneLaw
    name: str = ""

    @property
    def membrane(self) -> bool:
        """Whether the body is a membrane (string): its material a membrane law."""
        return isinstance(self.material, MembraneLaw)

    def modulus(self, size: float) -> float:
        """The stiffness scale of the body in a scene of size ``size``: Young's modulus of a
        solid, ``E t0 / size`` of a membrane (the modulus of a solid of that size with the
        membrane's stiffness per unit area). It scales eps_N, the supports' equations and
        the Newton tolerance."""
        E = self.material.E
        return E * self.material.thickness / size if self.membrane else E


@dataclass
class Domain:
    """One mesh and what lives on it: bodies, supports and loads.

    Parameters
    ----------
    mesh
        The mesh (its bodies are disjoint or non-matching; it has one displacement field).
    cell_tags, facet_tags
        Tags of the bodies and of the boundary parts.
    bodies
        The bodies (cell tag and material).
    dirichlet
        Prescribed displacements.
    loads
        Dead tractions, body forces and follower loads (:mod:`contact_ufl.loads`).
    tags
        Names of the tags (name -> integer), e.g. :attr:`contact_ufl.gmshio.MeshData.tags`.
    groups
        Physical groups (name -> ``(dimension, tag)``), e.g.
        :attr:`contact_ufl.gmshio.MeshData.groups`; derived from ``tags`` (and the dimension
        whose tags hold each value) when not given.
    name
        A name for messages and output files (default: ``mesh <index>``).
    outward, direction
        (membranes) The side the oriented reference normal ``n0`` of a membrane (string)
        mesh points to: away from the point ``outward``, or along ``direction``; by default
        away from the centroid of each connected piece of the surface (right for tubes,
        spheres and their symmetry sectors; a flat membrane needs one of the two). A follower
        pressure on a membrane pushes along ``n0`` (inflates it when ``n0`` points out).

    Notes
    -----
    Every tag (``Body.tag``, ``Dirichlet.tag``, the loads' ``tag``) may be a physical group
    name: it is replaced by its integer when the domain is made. An unknown name, or a group of
    the wrong dimension (a facet group as a body), raises
    :class:`~contact_ufl.errors.ContactInputError` on every rank.
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTags
    facet_tags: dolfinx.mesh.MeshTags
    bodies: list[Body]
    dirichlet: list[Dirichlet] = field(default_factory=list)
    loads: list[Load] = field(default_factory=list)
    tags: dict[str, int] = field(default_factory=dict)
    groups: dict[str, tuple[int, int]] = field(default_factory=dict)
    name: str = ""
    outward: Sequence[float] | None = None
    direction: Sequence[float] | None = None

    def __post_init__(self) -> None:
        if self.tags and not self.groups:
            self.groups = self._groups_from_tags()
        elif self.groups and not self.tags:
            self.tags = {name: tag for name, (_, tag) in self.groups.items()}
        self._resolve_names()

    @classmethod
    def from_gmsh(
        cls,
        source: str | os.PathLike | Any,
        bodies: Sequence[Body],
        dirichlet: Sequence[Dirichlet] = (),
        loads: Sequence[Load] = (),
        comm: MPI.Comm = MPI.COMM_WORLD,
        gdim: int | None = None,
        rank: int = 0,
        ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
        name: str = "",
        outward: Sequence[float] | None = None,
        direction: Sequence[float] | None = None,
    ) -> Domain:
        """The domain on the mesh of a ``.msh`` file or a live gmsh model, in one call.

        Parameters are those of :meth:`Scene.from_gmsh` (and ``name``, ``outward``,
        ``direction``, as in :class:`Domain`). For membranes (strings) give ``gdim``, 3 (2):
        the mesh is then a surface (curve) in it.
        """
        data = _read(source, [*bodies, *dirichlet, *loads], [], comm, gdim, rank, ghost_mode)
        domain = cls.from_mesh_data(data, bodies, dirichlet, loads, name)
        domain.outward, domain.direction = outward, direction
        return domain

    @classmethod
    def from_mesh_data(
        cls,
        data: MeshData,
        bodies: Sequence[Body],
        dirichlet: Sequence[Dirichlet] = (),
        loads: Sequence[Load] = (),
        name: str = "",
    ) -> Domain:
        """The domain on a mesh read by :mod:`contact_ufl.gmshio` (tags by name or
        integer)."""
        parts = {"bodies": list(bodies), "dirichlet": list(dirichlet), "loads": list(loads)}
        return cls(**_mesh_fields(data), **parts, name=name)

    @property
    def membrane(self) -> bool:
        """Whether the mesh is a membrane (string): topological dimension ``gdim - 1``."""
        return self.mesh.topology.dim < self.mesh.geometry.dim

    def cell_tag(self, key: Tag) -> int:
        """The integer cell tag of ``key`` (an integer, or a cell group's name)."""
        return self._lookup(key, self.mesh.topology.dim, f"cell tag {key!r}")

    def facet_tag(self, key: Tag) -> int:
        """The integer facet tag of ``key`` (an integer, or a facet group's name)."""
        return self._lookup(key, self.mesh.topology.dim - 1, f"facet tag {key!r}")

    def on_cells(self, load: Load) -> bool:
        """Whether ``load`` acts on cells (a body force, a pressure on a membrane) rather
        than on facets."""
        return isinstance(load, BodyForce) or (
            self.membrane and isinstance(load, FollowerPressure | VolumeControl)
        )

    @property
    def surface_dim(self) -> int:
        """The dimension of the contact surfaces of this mesh: its facets, or the cells of
        a membrane (string)."""
        tdim = self.mesh.topology.dim
        return tdim if self.membrane else tdim - 1

    @property
    def surface_tags(self) -> dolfinx.mesh.MeshTags:
        """The tags of the contact surfaces: the facet tags, or a membrane's cell tags."""
        return self.cell_tags if self.membrane else self.facet_tags

    def group_names(self) -> dict[str, list[str]]:
        """The names of the cell, facet and contact-surface groups (``"cell"``,
        ``"facet"``, ``"surface"``)."""
        return {
            kind: sorted(n for n, (d, _) in self.groups.items() if d in (self.dimension(kind), -1))
            for kind in ("cell", "facet", "surface")
        }

    def dimension(self, kind: str) -> int:
        """The dimension of the entities of ``kind``: ``"cell"``, ``"facet"`` or
        ``"surface"`` (a contact surface: :attr:`surface_dim`)."""
        tdim = self.mesh.topology.dim
        return {"cell": tdim, "facet": tdim - 1, "surface": self.surface_dim}[kind]

    def _groups_from_tags(self) -> dict[str, tuple[int, int]]:
        """Name -> (dimension, tag) from :attr:`tags`: the dimension whose tags hold the
        value (-1 if both or neither do). Collective."""
        comm, tdim = self.mesh.comm, self.mesh.topology.dim
        values = {}
        for dim, meshtags in ((tdim, self.cell_tags), (tdim - 1, self.facet_tags)):
            values[dim] = comm.allreduce(set(np.unique(meshtags.values).tolist()), MPI.BOR)
        groups = {}
        for name, tag in self.tags.items():
            dims = [dim for dim, found in values.items() if tag in found]
            groups[name] = (dims[0] if len(dims) == 1 else -1, int(tag))
        return groups

    def _lookup(self, key: Tag, dim: int, what: str) -> int:
        """The integer tag of ``key``, which must name a group of dimension ``dim``.

        Raises the same error on every rank (the groups are the same on every rank)."""
        if not isinstance(key, str):
            return key
        tdim = self.mesh.topology.dim
        if key not in self.groups:
            names = self.group_names()
            where = f" of {self.name}" if self.name else ""
            wanted = [n for n, (d, _) in self.groups.items() if d in (dim, -1)]
            raise ContactInputError(
                f"{what}: no physical group{where} is named {key!r}; cell groups: "
                f"{names['cell']}, facet groups: {names['facet']}{_suggest(key, wanted)}"
            )
        group_dim, tag = self.groups[key]
        if group_dim not in (dim, -1):
            raise ContactInputError(
                f"{what}: physical group {key!r} has dimension {group_dim} "
                f"({_kind(group_dim, tdim)}), but a {_kind(dim, tdim)} of dimension {dim} "
                "is expected here"
            )
        return tag

    def _resolve_names(self) -> None:
        """Replace every tag given by name with its integer; errors on every rank."""
        tdim = self.mesh.topology.dim
        errors: list[str] = []
        resolve = _resolver(self._lookup, errors)
        self.bodies = [
            resolve(b, "tag", tdim, f"body {b.name or b.tag!r}", name=b.name or str(b.tag))
            for b in self.bodies
        ]
        self.dirichlet = [
            resolve(d, "tag", tdim - 1, f"Dirichlet {d.tag!r}") for d in self.dirichlet
        ]
        self.loads = [
            resolve(
                ld,
                "tag",
                tdim if self.on_cells(ld) else tdim - 1,
                f"{type(ld).__name__} {ld.tag!r}",
            )
            for ld in self.loads
        ]
        if errors:
            raise ContactInputError(errors[0])

    def validate(self) -> None:
        """Check the domain against its mesh; raise a clear error on every rank."""
        self._resolve_names()
        comm = self.mesh.comm
        gdim, tdim = self.mesh.geometry.dim, self.mesh.topology.dim
        where = f"{self.name}: " if self.name else ""
        self._check_dimensions(where)
        collective_check(
            comm,
            self.cell_tags.dim == tdim,
            f"{where}cell_tags have dimension {self.cell_tags.dim}, the mesh {tdim}",
        )
        collective_check(
            comm,
            self.facet_tags.dim == tdim - 1,
            f"{where}facet_tags have dimension {self.facet_tags.dim}, expected {tdim - 1}",
        )
        collective_check(comm, len(self.bodies) > 0, f"{where}a mesh needs at least one body")
        for body in self.bodies:
            count = comm.allreduce(len(self.cell_tags.find(body.tag)), MPI.SUM)
            collective_check(
                comm,
                count > 0,
                f"{where}body {body.name or body.tag}: cell tag {body.tag}"
                f"{self._group_of(body.tag, tdim)} has no cells",
            )
        facet_values = comm.allreduce(set(np.unique(self.facet_tags.values).tolist()), MPI.BOR)
        cell_values = comm.allreduce(set(np.unique(self.cell_tags.values).tolist()), MPI.BOR)
        surface_loads = [ld for ld in self.loads if not self.on_cells(ld)]
        for item in [*self.dirichlet, *surface_loads]:
            collective_check(
                comm,
                item.tag in facet_values,
                f"{where}{type(item).__name__}: facet tag {item.tag} does not exist or has no "
                f"facets{self._group_of(item.tag, tdim - 1)} (facet tags: {sorted(facet_values)})",
            )
        for bc in self.dirichlet:
            what = f"{where}Dirichlet {self._describe(bc.tag, tdim - 1)}"
            _validate_dirichlet(comm, bc, gdim, what)
        for load in self.loads:
            collective_check(
                comm,
                self.membrane or not isinstance(load, VolumeControl),
                f"{where}a VolumeControl (cell tag {load.tag}) needs a membrane: the pressure "
                "whose enclosed volume it controls acts on membrane cells",
            )
            if self.on_cells(load):
                collective_check(
                    comm,
                    load.tag in cell_values,
                    f"{where}{type(load).__name__}: cell tag {load.tag} does not exist or has "
                    f"no cells{self._group_of(load.tag, tdim)} (cell tags: {sorted(cell_values)})",
                )
            dim = tdim if self.on_cells(load) else tdim - 1
            _validate_load(comm, load, gdim, where, self._describe(load.tag, dim))
        self._check_geometry(where)

    def _check_geometry(self, where: str) -> None:
        """Finite node coordinates; of a solid mesh, cells that are neither flat nor turned
        inside out, and no crack within a body (a warning). Vectorised over the cells; on
        every rank."""
        mesh, comm = self.mesh, self.mesh.comm
        gdim = mesh.geometry.dim
        x = mesh.geometry.x[:, :gdim]
        owned = mesh.geometry.index_map().size_local
        bad = np.flatnonzero(~np.isfinite(x[:owned]).all(axis=1))
        count = comm.allreduce(bad.size, MPI.SUM)
        first = ""
        if bad.size:
            node = int(mesh.geometry.index_map().local_to_global(bad[:1])[0])
            first = f", node {node} at {x[bad[0]].tolist()}"
        collective_check(
            comm,
            count == 0,
            f"{where}{count} mesh nodes have non-finite coordinates (NaN or infinity){first}",
        )
        if self.membrane:
            return
        mesh_checks.check_cells(mesh, where)
        mesh_checks.check_folds(mesh, where)
        mesh_checks.warn_of_cracks(mesh, self.cell_tags, self._body_labels(), where)

    def _body_labels(self) -> dict[int, str]:
        """Each body's cell tag -> how messages name it."""
        tdim = self.mesh.topology.dim
        return {
            int(b.tag): f"body {b.name!r} ({self._describe(b.tag, tdim)})"
            if b.name
            else f"body {self._describe(b.tag, tdim)}"
            for b in self.bodies
        }

    def _group_of(self, tag: int, dim: int) -> str:
        """`` (physical group 'top')`` where the tag has a group's name, else ``""``."""
        names = [n for n, (d, t) in self.groups.items() if t == tag and d in (dim, -1)]
        return f" (physical group {names[0]!r})" if names else ""

    def _describe(self, tag: int, dim: int) -> str:
        """A tag by its physical group's name where the domain has one (``'top' (tag 3)``)."""
        names = [n for n, (d, t) in self.groups.items() if t == tag and d in (dim, -1)]
        return f"{names[0]!r} (tag {tag})" if names else f"on tag {tag}"

    def _surface_label(self, tag: int) -> str:
        """A contact surface (facets of a solid, cells of a membrane) by its group's name
        and tag, or ``""`` where it has no name."""
        dim = self.mesh.topology.dim - (not self.membrane)
        names = [n for n, (d, t) in self.groups.items() if t == tag and d in (dim, -1)]
        return f"{names[0]!r} (tag {tag})" if names else ""

    def _check_dimensions(self, where: str) -> None:
        """Solids on a mesh of full dimension, membranes (strings) on a surface (curve)
        mesh: a clear error on every rank for a mismatch."""
        comm = self.mesh.comm
        gdim, tdim = self.mesh.geometry.dim, self.mesh.topology.dim
        kinds = {b.membrane for b in self.bodies}
        collective_check(
            comm,
            len(kinds) <= 1,
            f"{where}a mesh holds solids or membranes, not both: bodies "
            f"{[b.name or b.tag for b in self.bodies if b.membrane]} are membranes, "
            f"{[b.name or b.tag for b in self.bodies if not b.membrane]} solids (give the "
            "membranes a mesh of their own: a Domain)",
        )
        if self.membrane:
            check_manifold(self.mesh)
            collective_check(
                comm,
                kinds <= {True},
                f"{where}solid bodies need a 2D (plane strain) or 3D mesh of full dimension; "
                f"got topological dimension {tdim} in {gdim}D (a membrane mesh: give its "
                "bodies a membrane law, e.g. MembraneNeoHookean)",
            )
        else:
            collective_check(
                comm,
                gdim in (2, 3),
                f"{where}solid bodies need a 2D (plane strain) or 3D mesh, got {gdim}D",
            )
            collective_check(
                comm,
                kinds <= {False},
                f"{where}membrane bodies need a membrane mesh (triangles or quadrilaterals in "
                f"3D, intervals in 2D), got a mesh of topological dimension {tdim} in {gdim}D "
                "(a solid mesh: give its bodies a solid material)",
            )


@dataclass
class Scene:
    """Everything the forms are built from: domains (meshes with their bodies, supports and
    loads) and the contact pairs between their surfaces.

    Parameters
    ----------
    mesh
        The mesh of a one-mesh scene (or of the first of several; ``None`` when all meshes
        are given as ``domains``).
    cell_tags, facet_tags, bodies, dirichlet, loads, tags, groups
        Those of ``mesh``, as in :class:`Domain`.
    contacts
        Contact pairs (slave and master surfaces, parameters).
    domains
        Further meshes with their bodies, supports and loads (:class:`Domain`): bodies on
        meshes of their own.

    Notes
    -----
    Every tag may be a physical group name (a rigid obstacle as ``ContactPair.master`` is
    left as it is): it is replaced by its integer when the scene is made. A contact
    surface's name is looked up in the facet groups of all domains; the pair's
    ``slave_domain`` and ``master_domain`` become the indices of the domains that hold them
    (in :attr:`parts`). An integer tag needs the domain named when the scene has several. An
    unknown name, a name found in two domains, or a group of the wrong dimension raises
    :class:`~contact_ufl.errors.ContactInputError` on every rank.
    """

    mesh: dolfinx.mesh.Mesh | None = None
    cell_tags: dolfinx.mesh.MeshTags | None = None
    facet_tags: dolfinx.mesh.MeshTags | None = None
    bodies: list[Body] = field(default_factory=list)
    contacts: list[ContactPair] = field(default_factory=list)
    dirichlet: list[Dirichlet] = field(default_factory=list)
    loads: list[Load] = field(default_factory=list)
    tags: dict[str, int] = field(default_factory=dict)
    groups: dict[str, tuple[int, int]] = field(default_factory=dict)
    domains: list[Domain] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.mesh is None and not self.domains:
            raise ContactInputError("a scene needs a mesh, or domains=[Domain(...), ...]")
        if self.mesh is not None:
            own = self._own_domain()  # resolves the names of the scene's own mesh
            self.bodies, self.dirichlet, self.loads = own.bodies, own.dirichlet, own.loads
            self.tags, self.groups = own.tags, own.groups
        self._resolve_contacts()

    @classmethod
    def from_gmsh(
        cls,
        source: str | os.PathLike | Any,
        bodies: Sequence[Body],
        contacts: Sequence[ContactPair] = (),
        dirichlet: Sequence[Dirichlet] = (),
        loads: Sequence[Load] = (),
        comm: MPI.Comm = MPI.COMM_WORLD,
        gdim: int | None = None,
        rank: int = 0,
        ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
    ) -> Scene:
        """The one-mesh scene on the mesh of a ``.msh`` file or a live gmsh model, in one call.

        Parameters
        ----------
        source
            Path of a ``.msh`` file, or ``gmsh.model`` (meshed, with named physical groups)
            on rank ``rank`` (the other ranks may pass ``None``).
        bodies, contacts, dirichlet, loads
            As in :class:`Scene`; tags by physical group name or by integer.
        comm
            Communicator of the mesh.
        gdim
            Dimension of the bodies, 2 (plane strain) or 3 (default: that of the mesh); a
            mesh of another dimension is refused.
        rank, ghost_mode
            As in :func:`contact_ufl.gmshio.read_gmsh`.
        """
        parts = [*bodies, *dirichlet, *loads]
        data = _read(source, parts, contacts, comm, gdim, rank, ghost_mode)
        return cls.from_mesh_data(data, bodies, contacts, dirichlet, loads)

    @classmethod
    def from_mesh_data(
        cls,
        data: MeshData,
        bodies: Sequence[Body],
        contacts: Sequence[ContactPair] = (),
        dirichlet: Sequence[Dirichlet] = (),
        loads: Sequence[Load] = (),
    ) -> Scene:
        """The one-mesh scene on a mesh read by :mod:`contact_ufl.gmshio` (tags by name or
        integer)."""
        parts = {"bodies": list(bodies), "dirichlet": list(dirichlet), "loads": list(loads)}
        return cls(**_mesh_fields(data), **parts, contacts=list(contacts))

    # -- the domains ------------------------------------------------------------------
    @property
    def parts(self) -> list[Domain]:
        """All domains: the scene's own mesh (if any) first, then :attr:`domains`. A
        contact pair's ``slave_domain`` and ``master_domain`` index this list."""
        own = [self._own_domain()] if self.mesh is not None else []
        parts = own + list(self.domains)
        for k, part in enumerate(parts):
            if not part.name:
                part.name = f"mesh {k}" if len(parts) > 1 else ""
        return parts

    def _own_domain(self) -> Domain:
        return Domain(
            self.mesh,
            self.cell_tags,
            self.facet_tags,
            list(self.bodies),
            list(self.dirichlet),
            list(self.loads),
            dict(self.tags),
            dict(self.groups),
        )

    def cell_tag(self, key: Tag) -> int:
        """The integer cell tag of ``key`` (an integer, or a cell group's name in any
        domain)."""
        return self.locate(key, "cell")[1]

    def facet_tag(self, key: Tag) -> int:
        """The integer facet tag of ``key`` (an integer, or a facet group's name in any
        domain)."""
        return self.locate(key, "facet")[1]

    def locate(
        self, key: Tag, kind: str = "facet", domain: int | str | None = None, what: str = ""
    ) -> tuple[int, int]:
        """The domain (index in :attr:`parts`) and integer tag of ``key``.

        Parameters
        ----------
        key
            An integer tag, or the name of a physical group.
        kind
            ``"facet"``, ``"cell"`` or ``"surface"`` (a contact surface: facets of a solid
            mesh, cells of a membrane).
        domain
            The domain (index or name) that holds ``key``; default: the one whose groups
            have the name ``key``, or the only domain.
        what
            What ``key`` is, for the error messages (default: ``"<kind> tag <key>"``).
        """
        parts = self.parts
        what = what or f"{kind} tag {key!r}"
        if domain is not None:
            k = self._domain_index(domain, parts)
        elif len(parts) == 1:
            k = 0
        elif isinstance(key, str):
            holders = [k for k, d in enumerate(parts) if key in d.group_names()[kind]]
            if len(holders) != 1:
                names = {d.name: d.group_names()[kind] for d in parts}
                if holders:
                    raise ContactInputError(
                        f"{what}: several domains of the scene "
                        f"({', '.join(parts[k].name for k in holders)}) have a {kind} group "
                        f"named {key!r}: name the domain (a contact pair's slave_domain or "
                        "master_domain)"
                    )
                everywhere = [n for group in names.values() for n in group]
                raise ContactInputError(
                    f"{what}: no domain of the scene has a {kind} group named {key!r}; "
                    f"{kind} groups: {names}{_suggest(key, everywhere)}"
                )
            (k,) = holders
        else:
            raise ContactInputError(
                f"{what}: an integer tag in a scene of {len(parts)} meshes needs its domain "
                "(give the group's name, or the domain)"
            )
        return k, parts[k]._lookup(key, parts[k].dimension(kind), what)

    def _domain_index(self, domain: int | str, parts: list[Domain]) -> int:
        names = [d.name for d in parts]
        if isinstance(domain, str):
            if domain not in names:
                raise ContactInputError(f"no domain of the scene is named {domain!r}: {names}")
            return names.index(domain)
        if not 0 <= domain < len(parts):
            raise ContactInputError(
                f"domain index {domain} out of range: the scene has {len(parts)} meshes"
            )
        return int(domain)

    def _resolve_contacts(self) -> None:
        """Each pair's surfaces as integer tags of the domains that hold them; errors on
        every rank (the groups are the same on every rank)."""
        contacts = []
        for k, pair in enumerate(self.contacts):
            changes: dict[str, Any] = {}
            labels = ["", ""]
            for n, side in enumerate(("slave", "master")):
                key = getattr(pair, side)
                if not isinstance(key, RigidObstacle):
                    domain = getattr(pair, f"{side}_domain")
                    what = f"contact pair {k}, {side} surface"
                    d, tag = self.locate(key, "surface", domain, what)
                    changes[side], changes[f"{side}_domain"] = tag, d
                    labels[n] = self.parts[d]._surface_label(tag)
            contacts.append(dataclasses.replace(pair, **changes, labels=tuple(labels)))
        self.contacts = contacts

    def validate(self) -> None:
        """Check the scene against its meshes; raise a clear error on every rank."""
        parts = self.parts
        comm = parts[0].mesh.comm
        gdims = {d.mesh.geometry.dim for d in parts}
        collective_check(
            comm,
            len(gdims) == 1,
            f"the meshes of a scene must have one geometric dimension, got {sorted(gdims)}",
        )
        sizes = {d.mesh.comm.size for d in parts}
        collective_check(
            comm, len(sizes) == 1, "the meshes of a scene must share one MPI communicator"
        )
        for part in parts:
            part.validate()
        for k, pair in enumerate(self.contacts):
            for side in ("slave", "master"):
                key, domain = getattr(pair, side), getattr(pair, f"{side}_domain")
                if isinstance(key, RigidObstacle) or domain is None:
                    continue
                part = parts[domain]
                count = comm.allreduce(len(part.surface_tags.find(key)), MPI.SUM)
                kind = "cell" if part.membrane else "facet"
                collective_check(
                    comm,
                    count > 0,
                    f"contact pair {k}, {side} surface: {kind} tag {key}"
                    f"{part._group_of(key, part.surface_dim)} is empty or does not exist",
                )
            pair.validate(comm)


def _mesh_fields(data: MeshData) -> dict[str, Any]:
    """The mesh, tags and groups of ``data`` as the fields of a :class:`Domain` or a
    :class:`Scene`."""
    return {
        "mesh": data.mesh,
        "cell_tags": data.cell_tags,
        "facet_tags": data.facet_tags,
        "tags": data.tags,
        "groups": dict(data.groups),
    }


def _resolver(lookup, errors: list[str]):
    """A function replacing ``item.attribute`` given by name with its integer tag (errors
    collected in ``errors``)."""

    def resolve(item: Any, attribute: str, dim: int, what: str, **extra: Any) -> Any:
        key = getattr(item, attribute)
        if not isinstance(key, str):
            return item
        try:
            return dataclasses.replace(item, **{attribute: lookup(key, dim, what)}, **extra)
        except ContactInputError as error:
            errors.append(str(error))
            return item

    return resolve


def _read(source, parts, contacts, comm, gdim, rank, ghost_mode) -> MeshData:
    """The mesh data of ``source`` (names required where any tag is a name)."""
    from contact_ufl.gmshio import read_gmsh

    keys = [p.tag for p in parts] + [k for c in contacts for k in (c.slave, c.master)]
    # (rigid obstacles among the keys are not strings: they need no physical group)
    bodies = [p for p in parts if isinstance(p, Body)]
    membranes = bool(bodies) and all(b.membrane for b in bodies)
    # a membrane (string) mesh is a surface (curve) in gdim: one dimension less
    tdim = gdim - 1 if membranes and gdim is not None else None if membranes else gdim
    return read_gmsh(
        source,
        comm,
        gdim=gdim,
        rank=rank,
        ghost_mode=ghost_mode,
        require_names=any(isinstance(k, str) for k in keys),
        tdim=tdim,
        contact_surfaces=[k for c in contacts for k in (c.slave, c.master) if _is_tag(k)],
    )


def _is_tag(key: Any) -> bool:
    """Whether ``key`` names a physical group (a name or an integer tag, not an obstacle)."""
    return isinstance(key, str | int | np.integer)


def _validate_load(comm: MPI.Comm, load: Load, gdim: int, where: str, label: str) -> None:
    """Check a load's value (a vector of the mesh's dimension for a dead load, a scalar
    magnitude for a follower load; finite at t = 0) and a follower force's direction (on
    every rank); ``label`` names its tag (:meth:`Domain._describe`)."""
    if not isinstance(load, FollowerPressure | FollowerForce | VolumeControl):
        try:
            shape = evaluate(load.value, 0.0).shape
        except Exception as error:  # a callable that fails at t = 0, or no numbers
            shape = f"none: its value at t = 0 cannot be evaluated ({error})"
        collective_check(
            comm,
            shape == (gdim,),
            f"{where}{type(load).__name__} on tag {load.tag}: the value is a vector of "
            f"{gdim} components in {gdim}D, got shape {shape}",
        )
    if isinstance(load, FollowerPressure | FollowerForce):
        shape = evaluate(load.value, 0.0).shape
        collective_check(
            comm,
            shape == (),
            f"{where}{type(load).__name__} on facet tag {load.tag}: the value is a scalar "
            f"magnitude, got shape {shape}",
        )
    if not isinstance(load, VolumeControl):
        try:
            value = evaluate(load.value, 0.0)
        except Exception:  # a value that cannot be evaluated: refused above
            value = np.zeros(0)
        collective_check(
            comm,
            bool(np.all(np.isfinite(value))),
            f"{where}{type(load).__name__} {label}: the value at t = 0 is not finite: "
            f"{value.tolist()}",
        )
    if isinstance(load, FollowerForce):
        d0 = np.asarray(load.direction, dtype=float)
        collective_check(
            comm,
            d0.shape == (gdim,) and bool(np.isfinite(d0).all() and np.linalg.norm(d0) > 0.0),
            f"{where}FollowerForce on facet tag {load.tag}: direction must be a nonzero "
            f"vector of dimension {gdim}, got {tuple(d0.tolist())}",
        )


def _validate_dirichlet(comm: MPI.Comm, bc: Dirichlet, gdim: int, what: str) -> None:
    """Check a prescribed displacement against the mesh's dimension when the scene is made
    (on every rank): one component within ``gdim``, a scalar for it; else a scalar (every
    component) or a vector of ``gdim`` finite components."""
    if bc.component is not None:
        collective_check(
            comm,
            isinstance(bc.component, int | np.integer) and 0 <= bc.component < gdim,
            f"{what}: component must be one of {list(range(gdim))} in {gdim}D, got "
            f"{bc.component!r}",
        )
    if bc.varies_along_facets:
        x = np.zeros((2, gdim))  # two points at the origin: the shape of the answer
        try:
            value = bc.values_at(0.0, x)
        except Exception as error:  # a callable that fails, or of the wrong shape
            problem = f"its value(t, x) at t = 0 cannot be evaluated ({error})"
        else:
            problem = None if np.all(np.isfinite(value)) else "value(0, x) is not finite"
        collective_check(comm, problem is None, f"{what}: {problem}")
        return
    try:
        value = evaluate(bc.value, 0.0)
    except Exception as error:  # a callable that fails at t = 0, or no numbers
        problem = f"its value at t = 0 cannot be evaluated ({error})"
    else:
        shapes = [()] if bc.component is not None else [(), (gdim,)]
        problem = None
        if value.shape not in shapes:
            wanted = "a scalar" if bc.component is not None else f"a scalar or {gdim} components"
            problem = f"the value must be {wanted} in {gdim}D, got shape {value.shape}"
        elif not np.all(np.isfinite(value)):
            problem = f"the value at t = 0 is not finite: {value.tolist()}"
    collective_check(comm, problem is None, f"{what}: {problem}")


def _suggest(key: str, names: Sequence[str]) -> str:
    """``; did you mean 'name'?`` for the existing name closest to a mistyped ``key``
    (:func:`difflib.get_close_matches`), or ``""`` where none is close."""
    close = difflib.get_close_matches(key, sorted(set(names)), n=1)
    return f"; did you mean {close[0]!r}?" if close else ""


def _kind(dim: int, tdim: int) -> str:
    """What a group of dimension ``dim`` is in a mesh of dimension ``tdim``."""
    return {tdim: "cell group (a body)", tdim - 1: "facet group (a boundary part)"}.get(
        dim, "group"
    )
