"""A scene: bodies of one mesh, their materials, supports, loads and contact pairs.

Tags may be given by integer or by the name of their physical group (gmsh): the scene
resolves the names to integers once, when it is made, so the forms and the solver see
integers only. :meth:`Scene.from_gmsh` reads a ``.msh`` file or a live gmsh model and builds
the scene in one call.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.errors import ContactInputError, collective_check
from contact_ufl.loads import BodyForce, Dirichlet, FollowerForce, FollowerPressure, Load, evaluate
from contact_ufl.materials import Hyperelastic
from contact_ufl.plasticity import J2Plasticity

if TYPE_CHECKING:
    from contact_ufl.gmshio import MeshData

#: A tag: its integer value or the name of its physical group.
Tag = int | str


@dataclass(frozen=True)
class Body:
    """A body: the cells with ``tag`` (an integer or a physical group name) and their
    material."""

    tag: int | str
    material: Hyperelastic | J2Plasticity
    name: str = ""


@dataclass
class Scene:
    """Everything the forms are built from.

    Parameters
    ----------
    mesh
        One mesh holding all bodies (disjoint, non-matching).
    cell_tags, facet_tags
        Tags of the bodies and of the boundary parts.
    bodies
        The bodies (cell tag and material).
    contacts
        Contact pairs (slave and master facet tags, parameters).
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

    Notes
    -----
    Every tag (``Body.tag``, ``Dirichlet.tag``, the loads' ``tag``, ``ContactPair.slave``
    and ``.master``) may be a physical group name (a rigid obstacle as ``.master`` is left as
    it is): it is replaced by its integer when the
    scene is made. An unknown name, or a group of the wrong dimension (a cell group as a
    contact surface, a facet group as a body), raises
    :class:`~contact_ufl.errors.ContactInputError` on every rank.
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTags
    facet_tags: dolfinx.mesh.MeshTags
    bodies: list[Body]
    contacts: list[ContactPair] = field(default_factory=list)
    dirichlet: list[Dirichlet] = field(default_factory=list)
    loads: list[Load] = field(default_factory=list)
    tags: dict[str, int] = field(default_factory=dict)
    groups: dict[str, tuple[int, int]] = field(default_factory=dict)

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
        contacts: Sequence[ContactPair] = (),
        dirichlet: Sequence[Dirichlet] = (),
        loads: Sequence[Load] = (),
        comm: MPI.Comm = MPI.COMM_WORLD,
        gdim: int | None = None,
        rank: int = 0,
        ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
    ) -> Scene:
        """The scene on the mesh of a ``.msh`` file or a live gmsh model, in one call.

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
        from contact_ufl.gmshio import read_gmsh

        parts = [*bodies, *dirichlet, *loads]
        keys = [p.tag for p in parts] + [k for c in contacts for k in (c.slave, c.master)]
        # (rigid obstacles among the keys are not strings: they need no physical group)
        data = read_gmsh(
            source,
            comm,
            gdim=gdim,
            rank=rank,
            ghost_mode=ghost_mode,
            require_names=any(isinstance(k, str) for k in keys),
            tdim=gdim,
        )
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
        """The scene on a mesh read by :mod:`contact_ufl.gmshio` (tags by name or integer)."""
        return cls(
            data.mesh,
            data.cell_tags,
            data.facet_tags,
            list(bodies),
            list(contacts),
            list(dirichlet),
            list(loads),
            tags=data.tags,
            groups=dict(data.groups),
        )

    def cell_tag(self, key: Tag) -> int:
        """The integer cell tag of ``key`` (an integer, or a cell group's name)."""
        return self._lookup(key, self.mesh.topology.dim, f"cell tag {key!r}")

    def facet_tag(self, key: Tag) -> int:
        """The integer facet tag of ``key`` (an integer, or a facet group's name)."""
        return self._lookup(key, self.mesh.topology.dim - 1, f"facet tag {key!r}")

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
            names = {
                kind: sorted(n for n, (d, _) in self.groups.items() if d == k)
                for kind, k in (("cell", tdim), ("facet", tdim - 1))
            }
            raise ContactInputError(
                f"{what}: no physical group is named {key!r}; cell groups: {names['cell']}, "
                f"facet groups: {names['facet']}"
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

        def resolve(item: Any, attribute: str, dim: int, what: str, **extra: Any) -> Any:
            key = getattr(item, attribute)
            if not isinstance(key, str):
                return item
            try:
                return dataclasses.replace(
                    item, **{attribute: self._lookup(key, dim, what)}, **extra
                )
            except ContactInputError as error:
                errors.append(str(error))
                return item

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
                tdim if isinstance(ld, BodyForce) else tdim - 1,
                f"{type(ld).__name__} {ld.tag!r}",
            )
            for ld in self.loads
        ]
        contacts = []
        for k, pair in enumerate(self.contacts):
            for side in ("slave", "master"):
                pair = resolve(pair, side, tdim - 1, f"contact pair {k}, {side} surface")
            contacts.append(pair)
        self.contacts = contacts
        if errors:
            raise ContactInputError(errors[0])

    def validate(self) -> None:
        """Check the scene against its mesh; raise a clear error on every rank."""
        self._resolve_names()
        comm = self.mesh.comm
        gdim, tdim = self.mesh.geometry.dim, self.mesh.topology.dim
        collective_check(
            comm,
            gdim == tdim and gdim in (2, 3),
            f"solid bodies need a 2D (plane strain) or 3D mesh of full dimension; "
            f"got topological dimension {tdim} in {gdim}D",
        )
        collective_check(
            comm,
            self.cell_tags.dim == tdim,
            f"cell_tags have dimension {self.cell_tags.dim}, the mesh {tdim}",
        )
        collective_check(
            comm,
            self.facet_tags.dim == tdim - 1,
            f"facet_tags have dimension {self.facet_tags.dim}, expected {tdim - 1}",
        )
        collective_check(comm, len(self.bodies) > 0, "a scene needs at least one body")
        for pair in self.contacts:
            pair.validate(comm)
        for body in self.bodies:
            count = comm.allreduce(len(self.cell_tags.find(body.tag)), MPI.SUM)
            collective_check(
                comm, count > 0, f"body {body.name or body.tag}: cell tag {body.tag} has no cells"
            )
        facet_values = comm.allreduce(set(np.unique(self.facet_tags.values).tolist()), MPI.BOR)
        surface_loads = [ld for ld in self.loads if not isinstance(ld, BodyForce)]
        for item in [*self.dirichlet, *surface_loads]:
            collective_check(
                comm,
                item.tag in facet_values,
                f"{type(item).__name__}: facet tag {item.tag} does not exist "
                f"(facet tags: {sorted(facet_values)})",
            )
        for load in self.loads:
            if isinstance(load, FollowerPressure | FollowerForce):
                shape = evaluate(load.value, 0.0).shape
                collective_check(
                    comm,
                    shape == (),
                    f"{type(load).__name__} on facet tag {load.tag}: the value is a scalar "
                    f"magnitude, got shape {shape}",
                )
            if isinstance(load, FollowerForce):
                d0 = np.asarray(load.direction, dtype=float)
                collective_check(
                    comm,
                    d0.shape == (gdim,) and bool(np.linalg.norm(d0) > 0.0),
                    f"FollowerForce on facet tag {load.tag}: direction must be a nonzero "
                    f"vector of dimension {gdim}, got {tuple(d0.tolist())}",
                )


def _kind(dim: int, tdim: int) -> str:
    """What a group of dimension ``dim`` is in a mesh of dimension ``tdim``."""
    return {tdim: "cell group (a body)", tdim - 1: "facet group (a boundary part)"}.get(
        dim, "group"
    )
