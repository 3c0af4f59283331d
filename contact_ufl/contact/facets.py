"""Contact surfaces as facets of a mesh: the tagged facets, their cells and normals.

Conventions shared by the slave and the master side: the facet kinds of
:mod:`contact_ufl.contact.search.kinds` (a segment in 2D, a triangle or a bilinear
quadrilateral in basix vertex order in 3D, and their quadratic versions).
"""

from __future__ import annotations

import basix
import dolfinx
import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from contact_ufl.errors import collective_check


def basix_cell(mesh: dolfinx.mesh.Mesh, dim: int) -> basix.CellType:
    topology = mesh.topology
    cell = topology.cell_type if dim == topology.dim else topology.entity_types[dim][0]
    return getattr(basix.CellType, cell.name)


def coordinate_element(mesh: dolfinx.mesh.Mesh) -> basix.finite_element.FiniteElement:
    return mesh.ufl_domain().ufl_coordinate_element().basix_element


def scalar_element(V: dolfinx.fem.FunctionSpace) -> basix.finite_element.FiniteElement:
    element = V.ufl_element()
    if element.num_sub_elements:
        element = element.sub_elements[0]
    return element.basix_element


def tagged_facets(facet_tags: dolfinx.mesh.MeshTags, tag: int, role: str) -> npt.NDArray[np.int32]:
    """Local facets carrying ``tag``; raise on every rank when no rank has any."""
    comm = facet_tags.topology.comm
    facets = facet_tags.find(tag)
    total = comm.allreduce(len(facets), op=MPI.SUM)
    known = comm.allreduce(set(np.unique(facet_tags.values).tolist()), op=MPI.BOR)
    collective_check(
        comm,
        total > 0,
        f"{role} surface: facet tag {tag} is empty or does not exist "
        f"(tags present: {sorted(known)})",
    )
    return facets


def exterior_facet_cells(
    mesh: dolfinx.mesh.Mesh, facets: npt.NDArray[np.int32], role: str
) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.int32]]:
    """The (cell, local facet) of boundary facets; raise if a facet is interior."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    mesh.topology.create_connectivity(tdim, tdim - 1)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    c2f = mesh.topology.connectivity(tdim, tdim - 1)
    offsets = f2c.offsets
    ncells = offsets[facets + 1] - offsets[facets]
    collective_check(
        mesh.comm,
        bool(np.all(ncells == 1)),
        f"{role} surface: {int(np.sum(ncells != 1))} tagged facets are interior facets "
        "(a contact surface must be on the boundary of its body)",
    )
    cells = f2c.array[offsets[facets]]
    nfc = len(basix.topology(basix_cell(mesh, tdim))[tdim - 1])  # (a rank may have no cell)
    cell_facets = c2f.array.reshape(-1, nfc)[cells]
    local = np.argmax(cell_facets == facets[:, None], axis=1).astype(np.int32)
    return cells.astype(np.int32), local


def facet_normals(X: np.ndarray) -> np.ndarray:
    """Un-normalised normals of oriented facets under the projection's conventions."""
    if X.shape[1] == 2:
        a = X[:, 1] - X[:, 0]
        return np.stack([a[:, 1], -a[:, 0]], axis=1)
    if X.shape[1] == 3:
        return np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    return np.cross(X[:, 1] - X[:, 0] + X[:, 3] - X[:, 2], X[:, 2] - X[:, 0] + X[:, 3] - X[:, 1])


def outward_normals(vertices: np.ndarray, cell_centres: np.ndarray) -> np.ndarray:
    """Unit normals of facets given by their vertices, pointing away from their cells."""
    n = facet_normals(vertices)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    sign = np.sign(np.einsum("fd,fd->f", n, vertices.mean(axis=1) - cell_centres))
    return n * sign[:, None]
