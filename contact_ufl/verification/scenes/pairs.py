"""Curved pairs without supports, for Taylor tests (:func:`curved_pair`,
:func:`warp_saddle`), and a one-mesh scene with each body on a mesh of its own
(:func:`on_meshes_of_their_own`).
"""

from __future__ import annotations

import dataclasses

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.gmshio import MeshData
from contact_ufl.materials import (
    NeoHookean,
)
from contact_ufl.scene import Body, Domain, Scene
from contact_ufl.verification import geometries


def curved_pair(
    dim: int,
    comm: MPI.Comm = MPI.COMM_WORLD,
    E: float = 1.0,
    nu: float = 0.3,
    eps_N: float = 10.0,
    cell: str = "tetrahedron",
    order: int = 1,
) -> Scene:
    """Two bodies with curved contact surfaces and no supports (for Taylor tests).

    ``dim = 2``: a half disc above a block with a circular top; ``dim = 3``: a half cylinder
    above a block with a cylindrical top of crossed axis, or with ``cell="hexahedron"`` the
    hexahedral stacked boxes of :func:`~contact_ufl.verification.geometries.patch_3d` warped
    (:func:`warp_saddle`) so that their common surface is a saddle; the lower body is the
    finer (element size 0.1 against 1/6), so a partition into two ranks splits it and its
    master surface. ``order``: that of the geometry of the gmsh meshes (2: curved cells).
    """
    if dim == 3 and cell == "hexahedron":
        sm = geometries.patch_3d(cell=cell, h_lower=0.1, comm=comm)
        warp_saddle(sm.mesh)
        names = ("upper", "lower", "upper_contact", "lower_contact")
    elif dim == 2:
        sm = geometries.curved_2d(h_contact=0.05, h_far=0.3, order=order, comm=comm)
        names = ("cylinder", "block", "cylinder_contact", "block_contact")
    else:
        sm = geometries.cylinders_3d(h_contact=0.15, h_far=0.4, order=order, comm=comm)
        names = ("upper", "lower", "upper_contact", "lower_contact")
    return Scene.from_mesh_data(
        sm,
        bodies=[
            Body(names[0], NeoHookean(E, nu), "upper"),
            Body(names[1], NeoHookean(E, nu), "lower"),
        ],
        contacts=[ContactPair(names[2], names[3], eps_N=eps_N)],
    )


def warp_saddle(mesh: dolfinx.mesh.Mesh, depth: float = 0.2) -> None:
    """Move the nodes of a mesh of the unit-square boxes vertically (in place) by
    ``depth ((x - 1/2)^2 - (y - 1/2)^2 / 2)``: flat faces ``z = c`` become saddles."""
    x = mesh.geometry.x
    x[:, 2] += depth * ((x[:, 0] - 0.5) ** 2 - 0.5 * (x[:, 1] - 0.5) ** 2)


def on_meshes_of_their_own(scene: Scene) -> Scene:
    """The one-mesh ``scene`` with each body on a mesh of its own (a submesh of its cells,
    the same geometry and partition): each body then has its own displacement field.

    Supports and loads go to the meshes whose facets they tag; each contact pair names the
    domains of its two surfaces (integer tags need them in a scene of several meshes).
    """
    data = MeshData(scene.mesh, scene.cell_tags, scene.facet_tags, dict(scene.groups))
    parts = geometries.split_by_cells(data, [b.tag for b in scene.bodies])
    comm = scene.mesh.comm

    def holds(part: MeshData, tag: int) -> bool:
        return comm.allreduce(len(part.facet_tags.find(tag)), MPI.SUM) > 0

    domains = [
        Domain(
            part.mesh,
            part.cell_tags,
            part.facet_tags,
            [body],
            [d for d in scene.dirichlet if holds(part, d.tag)],
            [ld for ld in scene.loads if holds(part, ld.tag)],
            groups=part.groups,
            name=body.name or f"body {body.tag}",
        )
        for part, body in zip(parts, scene.bodies, strict=True)
    ]

    def domain_of(tag) -> int | None:
        if not isinstance(tag, int | np.integer):
            return None
        (k,) = [k for k, part in enumerate(parts) if holds(part, tag)]
        return k

    contacts = [
        dataclasses.replace(p, slave_domain=domain_of(p.slave), master_domain=domain_of(p.master))
        for p in scene.contacts
    ]
    return Scene(domains=domains, contacts=contacts)
