"""Checks of a solid mesh before anything is built on it: finite coordinates are checked by
the domain; here, cells that are flat or turned inside out (a fold between neighbouring
simplices, a twisted quadrilateral or hexahedron), and coincident nodes of one body that no
cell joins (a crack: a warning). Vectorised over the cells; collective.
"""

from __future__ import annotations

import warnings

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.errors import CrackWarning, collective_check

#: relative size (of the cell's extent to the power of its dimension) below which a cell's
#: Jacobian at a vertex counts as zero: a flat (degenerate) cell
FLAT_CELL = 1e-10
#: relative distance (of the mesh's extent) within which two nodes coincide
COINCIDENT_NODES = 1e-9


def _corner_jacobians(mesh: dolfinx.mesh.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """The Jacobian determinant of the map of each owned cell at each of its vertices (of its
    vertices' affine or multilinear map) ``(cells, corners)``, and each cell's extent (the
    diagonal of its vertices' box) ``(cells,)``."""
    gdim, tdim = mesh.geometry.dim, mesh.topology.dim
    owned = mesh.topology.index_map(tdim).size_local
    simplex = mesh.topology.cell_name() in ("interval", "triangle", "tetrahedron")
    corners = tdim + 1 if simplex else 2**tdim
    v = mesh.geometry.x[mesh.geometry.dofmaps[0][:owned, :corners], :gdim]
    if simplex:
        dets = np.linalg.det(v[:, 1:] - v[:, :1])[:, None]
    else:  # tensor-product vertices: vertex c has the reference coordinates of c's bits
        columns = [
            [v[:, c | (1 << k)] - v[:, c & ~(1 << k)] for k in range(tdim)] for c in range(corners)
        ]
        dets = np.stack([np.linalg.det(np.stack(c, axis=-1)) for c in columns], axis=1)
    return dets, np.linalg.norm(np.ptp(v, axis=1), axis=1)


def check_cells(mesh: dolfinx.mesh.Mesh, where: str) -> None:
    """Raise on every rank for a flat cell (zero area or volume) or one turned inside out
    (a quadrilateral or hexahedron whose Jacobian changes sign: vertices out of order)."""
    comm, tdim = mesh.comm, mesh.topology.dim
    dets, extent = _corner_jacobians(mesh)
    zero = FLAT_CELL * extent**tdim
    flat = np.abs(dets).max(axis=1, initial=0.0) <= zero
    twisted = (dets.min(axis=1, initial=0.0) < -zero) & (dets.max(axis=1, initial=0.0) > zero)
    for found, what in (
        (flat, "flat (zero area or volume)"),
        (twisted, "turned inside out (the Jacobian changes sign: vertices out of order)"),
    ):
        count = comm.allreduce(int(found.sum()), MPI.SUM)
        first = ""
        if found.any():
            cell = int(np.argmax(found))
            index = int(mesh.topology.index_map(tdim).local_to_global(np.array([cell]))[0])
            first = f", first cell {index} (vertices {_vertices(mesh, cell)})"
        collective_check(comm, count == 0, f"{where}{count} cells of the mesh are {what}{first}")


def _vertices(mesh: dolfinx.mesh.Mesh, cell: int) -> list:
    """The vertex coordinates of a local cell, for a message."""
    nv = dolfinx.cpp.mesh.cell_num_vertices(mesh.topology.cell_type)
    nodes = mesh.geometry.dofmaps[0][cell, :nv]
    return np.round(mesh.geometry.x[nodes, : mesh.geometry.dim], 6).tolist()


def check_folds(mesh: dolfinx.mesh.Mesh, where: str) -> None:
    """Raise on every rank where two simplices sharing a facet lie on the same side of it
    (the mesh folds over itself: a node moved across a facet of its neighbour). A facet
    shared across ranks without ghost cells is not checked."""
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    if mesh.topology.cell_name() not in ("triangle", "tetrahedron"):
        return
    mesh.topology.create_connectivity(tdim - 1, tdim)
    mesh.topology.create_connectivity(tdim, tdim - 1)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    c2f = mesh.topology.connectivity(tdim, tdim - 1).array.reshape(-1, tdim + 1)
    num = mesh.topology.index_map(tdim - 1).size_local
    offsets = f2c.offsets
    facets = np.flatnonzero(np.diff(offsets)[:num] == 2)
    c0, c1 = f2c.array[offsets[facets]], f2c.array[offsets[facets] + 1]
    # a simplex's local facet i is opposite its local vertex i
    i0 = np.argmax(c2f[c0] == facets[:, None], axis=1)
    i1 = np.argmax(c2f[c1] == facets[:, None], axis=1)
    dofs = mesh.geometry.dofmaps[0]
    x = mesh.geometry.x[:, :gdim]
    others = (i0[:, None] + 1 + np.arange(tdim)) % (tdim + 1)
    face = x[dofs[c0[:, None], others]]  # the facet's vertices (as c0 orders them)
    edges = face[:, 1:] - face[:, :1]

    def side(opposite: np.ndarray) -> np.ndarray:
        rows = np.concatenate([edges, (opposite - face[:, 0])[:, None]], axis=1)
        return np.linalg.det(rows)

    s0, s1 = side(x[dofs[c0, i0]]), side(x[dofs[c1, i1]])
    folded = s0 * s1 > 0.0
    count = mesh.comm.allreduce(int(folded.sum()), MPI.SUM)
    first = ""
    if folded.any():
        k = int(np.argmax(folded))
        cells = mesh.topology.index_map(tdim).local_to_global(np.array([c0[k], c1[k]]))
        first = f", first between cells {cells.tolist()} at {np.round(face[k], 6).tolist()}"
    collective_check(
        mesh.comm,
        count == 0,
        f"{where}the mesh folds over itself: {count} facets have both their cells on the same "
        f"side (cells turned inside out){first}",
    )


def warn_of_cracks(
    mesh: dolfinx.mesh.Mesh,
    cell_tags: dolfinx.mesh.MeshTags,
    bodies: dict[int, str],
    where: str,
) -> None:
    """Warn on every rank where distinct boundary nodes of one body coincide (a crack:
    pieces of a body meshed apart and not merged). Distinct bodies may touch at the start;
    a crack may be meant (a slit for self-contact): a warning, not an error. The boundary
    nodes are gathered to rank 0 (a set-up step: the surface only)."""
    comm, gdim, tdim = mesh.comm, mesh.geometry.dim, mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    facets = dolfinx.mesh.exterior_facet_indices(mesh.topology)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    cells = f2c.array[f2c.offsets[facets]]
    cell_map = mesh.topology.index_map(tdim)
    body = np.full(cell_map.size_local + cell_map.num_ghosts, -1, dtype=np.int64)
    body[cell_tags.indices] = cell_tags.values
    nodes = dolfinx.mesh.entities_to_geometry(mesh, tdim - 1, facets)
    labels = np.repeat(body[cells], nodes.shape[1])
    keys = mesh.geometry.index_map().local_to_global(nodes.ravel())
    table, first = np.unique(np.column_stack([labels, keys]), axis=0, return_index=True)
    x = mesh.geometry.x[:, :gdim]
    points = x[nodes.ravel()[first]]
    owned = x[: mesh.geometry.index_map().size_local]
    lo = np.min(comm.allgather(owned.min(axis=0, initial=np.inf)), axis=0)
    hi = np.max(comm.allgather(owned.max(axis=0, initial=-np.inf)), axis=0)
    parts = comm.gather((table, points), root=0)
    message, error = None, None
    if comm.rank == 0:
        try:
            message = _coincident(parts, lo, hi, bodies, where)
        except Exception as failure:  # never leave the other ranks waiting in the bcast
            error = f"{type(failure).__name__}: {failure}"
    message, error = comm.bcast((message, error), root=0)
    if error is not None:
        raise RuntimeError(f"the check for coincident nodes failed on rank 0: {error}")
    if message is not None:
        warnings.warn(message, CrackWarning, stacklevel=4)


def _coincident(parts: list, lo: np.ndarray, hi: np.ndarray, bodies: dict, where: str):
    """The message of :func:`warn_of_cracks` from the gathered (body, node) tables and
    points, or ``None`` (rank 0)."""
    table = np.concatenate([p[0] for p in parts])
    points = np.concatenate([p[1] for p in parts])
    table, first = np.unique(table, axis=0, return_index=True)
    points = points[first]
    keep = np.isin(table[:, 0], list(bodies))
    table, points = table[keep], points[keep]
    size = max(float(np.linalg.norm(hi - lo)), np.finfo(float).tiny)
    grid = np.round((points - lo) / (COINCIDENT_NODES * size))
    rows = np.column_stack([table[:, 0], grid])
    _, group, counts = np.unique(rows, axis=0, return_inverse=True, return_counts=True)
    cut = counts[group.ravel()] > 1
    if not cut.any():
        return None
    names = ", ".join(bodies[t] for t in sorted({int(t) for t in table[cut, 0]}))
    return (
        f"{where}{int(cut.sum())} boundary nodes of {names} coincide with other nodes of the "
        f"same body (first at {np.round(points[np.argmax(cut)], 6).tolist()}): the body is "
        "cut there, its pieces joined by contact only, if at all. Merge the mesh's coincident "
        "nodes (gmsh: Coherence, or fragment the volumes) unless the crack is meant"
    )
