"""A scene: bodies of one mesh, their materials, supports, loads and contact pairs."""

from __future__ import annotations

from dataclasses import dataclass, field

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.errors import collective_check
from contact_ufl.loads import BodyForce, Dirichlet, FollowerForce, FollowerPressure, Load, evaluate
from contact_ufl.materials import Hyperelastic
from contact_ufl.plasticity import J2Plasticity


@dataclass(frozen=True)
class Body:
    """A body: the cells with ``tag`` and their material."""

    tag: int
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
        Names of the tags (for look-up and messages), e.g. from :mod:`contact_ufl.meshes`.
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTags
    facet_tags: dolfinx.mesh.MeshTags
    bodies: list[Body]
    contacts: list[ContactPair] = field(default_factory=list)
    dirichlet: list[Dirichlet] = field(default_factory=list)
    loads: list[Load] = field(default_factory=list)
    tags: dict[str, int] = field(default_factory=dict)

    def validate(self) -> None:
        """Check the scene against its mesh; raise a clear error on every rank."""
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
