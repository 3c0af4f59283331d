"""Tags without gmsh, and meshes of their own: the tags of a one-body mesh made by DOLFINx
(:func:`tag_single_body`), and one mesh split into submeshes of its cell groups
(:func:`split_by_cells`).
"""

from __future__ import annotations

from collections.abc import Callable

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.gmshio import MeshData


def tag_single_body(
    mesh: dolfinx.mesh.Mesh, sides: list[Callable[[np.ndarray], np.ndarray]]
) -> tuple[dolfinx.mesh.MeshTags, dolfinx.mesh.MeshTags]:
    """Tags of a one-body mesh made without gmsh (e.g. ``dolfinx.mesh.create_rectangle``).

    Every cell gets tag 1; the boundary facets located by ``sides[k]`` (a marker of points
    ``x`` of shape ``(3, n)``) get tag ``k + 1`` (the first marker wins where they overlap).
    """
    tdim = mesh.topology.dim
    cells = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
    cell_tags = dolfinx.mesh.meshtags(mesh, tdim, cells, np.ones_like(cells))
    facets = [dolfinx.mesh.locate_entities_boundary(mesh, tdim - 1, s) for s in sides]
    values = [np.full(len(f), k + 1, dtype=np.int32) for k, f in enumerate(facets)]
    all_facets, first = np.unique(np.concatenate(facets), return_index=True)
    facet_tags = dolfinx.mesh.meshtags(mesh, tdim - 1, all_facets, np.concatenate(values)[first])
    return cell_tags, facet_tags


def split_by_cells(data: MeshData, cell_groups: list[int | str]) -> list[MeshData]:
    """Meshes of their own for cell groups (tags or names) of one mesh: one submesh per
    group, with its cell and facet tags and the names of the groups it holds.

    The submeshes have the parent's geometry exactly and its partition, so a scene on them is
    the scene on ``data`` with each body on a mesh of its own (and its own displacement).
    """
    mesh = data.mesh
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    parts = []
    for name in cell_groups:
        tag = data.tags[name] if isinstance(name, str) else name
        cells = data.cell_tags.find(tag)
        sub, cell_map, vertex_map, _ = dolfinx.mesh.create_submesh(mesh, tdim, cells)
        sub.topology.create_connectivity(tdim - 1, tdim)
        cell_tags = dolfinx.mesh.transfer_meshtags_to_submesh(
            data.cell_tags, sub, vertex_map, cell_map
        )
        facet_tags = dolfinx.mesh.transfer_meshtags_to_submesh(
            data.facet_tags, sub, vertex_map, cell_map
        )
        held = {
            dim: mesh.comm.allreduce(set(np.unique(tags.values).tolist()), MPI.BOR)
            for dim, tags in ((tdim, cell_tags), (tdim - 1, facet_tags))
        }
        groups = {n: (d, t) for n, (d, t) in data.groups.items() if t in held.get(d, ())}
        parts.append(MeshData(sub, cell_tags, facet_tags, groups))
    return parts
