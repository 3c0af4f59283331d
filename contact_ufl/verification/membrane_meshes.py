"""Small membrane and string meshes built with NumPy (verification; not part of the library).

Each builder makes the cells on rank 0 and lets DOLFINx distribute them. ``reverse``
reverses the vertex order of every other cell (their vertex-order normals then point the
other way), to check that the membrane orientation does not depend on it.

* :func:`sphere_octant`: the octant ``x, y, z >= 0`` of a sphere, triangles.
* :func:`tube_sector`: a quarter of a tube, one layer of quadrilaterals (or triangles) along
  its axis.
* :func:`ring_sector`: a quarter of a circle, intervals in 2D.
* :func:`moebius_strip`: a Moebius strip, triangles (not orientable).
* :func:`flat_square`: the unit square in the plane ``z = 0`` of 3D, triangles.
"""

from __future__ import annotations

import basix.ufl
import dolfinx
import numpy as np
from mpi4py import MPI


def _create(comm: MPI.Comm, cell: str, cells: np.ndarray, x: np.ndarray, reverse: bool):
    """Distribute ``cells`` and ``x`` given on rank 0; reverse every other cell if asked."""
    cells = np.array(cells, dtype=np.int64)
    if reverse:
        flip = {"interval": [1, 0], "triangle": [0, 2, 1], "quadrilateral": [0, 2, 1, 3]}[cell]
        cells[1::2] = cells[1::2][:, flip]
    gdim = x.shape[1]
    element = basix.ufl.element("Lagrange", cell, 1, shape=(gdim,))
    if comm.rank != 0:
        cells, x = np.empty((0, cells.shape[1]), np.int64), np.empty((0, gdim))
    return dolfinx.mesh.create_mesh(comm, cells, element, x)


def _triangulated_grid(ni: int, nj: int) -> np.ndarray:
    """Triangles of an ``(ni + 1) x (nj + 1)`` grid of nodes numbered ``i * (nj + 1) + j``."""
    i, j = np.meshgrid(np.arange(ni), np.arange(nj), indexing="ij")
    n00 = (i * (nj + 1) + j).ravel()
    n10, n01, n11 = n00 + nj + 1, n00 + 1, n00 + nj + 2
    return np.vstack([np.stack([n00, n10, n11], 1), np.stack([n00, n11, n01], 1)])


def sphere_octant(comm: MPI.Comm, R: float, n: int, reverse: bool = False):
    """The octant of the sphere of radius ``R`` about the origin: the flat triangle
    ``(1,0,0), (0,1,0), (0,0,1)`` cut into ``n^2`` triangles, its nodes projected radially."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    index = np.full((n + 1, n + 1), -1)
    index[keep] = np.arange(keep.sum())
    ijk = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], 1).astype(float)
    x = R * ijk / np.linalg.norm(ijk, axis=1)[:, None]
    up = (i + j <= n - 1)[:-1, :-1]
    iu, ju = np.nonzero(up)
    down = (i + j <= n - 2)[:-1, :-1]
    idn, jdn = np.nonzero(down)
    cells = np.vstack(
        [
            np.stack([index[iu, ju], index[iu + 1, ju], index[iu, ju + 1]], 1),
            np.stack([index[idn + 1, jdn], index[idn + 1, jdn + 1], index[idn, jdn + 1]], 1),
        ]
    )
    return _create(comm, "triangle", cells, x, reverse)


def tube_sector(
    comm: MPI.Comm,
    R: float,
    n: int,
    length: float,
    cell: str = "quadrilateral",
    reverse: bool = False,
):
    """A quarter of the tube of radius ``R`` about the z axis, ``0 <= z <= length``: ``n``
    cells around, one along the axis (quadrilaterals, or triangles two per quadrilateral)."""
    theta = np.linspace(0.0, np.pi / 2, n + 1)
    ring = np.stack([R * np.cos(theta), R * np.sin(theta)], 1)
    x = np.vstack([np.hstack([ring, np.full((n + 1, 1), z)]) for z in (0.0, length)])
    x = x.reshape(2, n + 1, 3).transpose(1, 0, 2).reshape(-1, 3)  # node i * 2 + k
    if cell == "quadrilateral":
        k = np.arange(n)
        cells = np.stack([2 * k, 2 * k + 2, 2 * k + 1, 2 * k + 3], 1)
    else:
        cells = _triangulated_grid(n, 1)
    return _create(comm, cell, cells, x, reverse)


def ring_sector(comm: MPI.Comm, R: float, n: int, reverse: bool = False):
    """A quarter of the circle of radius ``R`` about the origin: ``n`` intervals in 2D."""
    theta = np.linspace(0.0, np.pi / 2, n + 1)
    x = np.stack([R * np.cos(theta), R * np.sin(theta)], 1)
    cells = np.stack([np.arange(n), np.arange(1, n + 1)], 1)
    return _create(comm, "interval", cells, x, reverse)


def moebius_strip(comm: MPI.Comm, n: int = 12, m: int = 2, R: float = 1.0, width: float = 0.4):
    """A Moebius strip: ``n`` columns of ``m`` quadrilaterals, two triangles each, around a
    circle of radius ``R``; the last column joins the first with the strip turned over."""
    theta = 2.0 * np.pi * np.arange(n) / n
    s = np.linspace(-width / 2, width / 2, m + 1)
    T, S = np.meshgrid(theta, s, indexing="ij")
    r = R + S * np.cos(T / 2)
    x = np.stack([r * np.cos(T), r * np.sin(T), S * np.sin(T / 2)], -1).reshape(-1, 3)
    cells = _triangulated_grid(n, m)  # nodes of column n (not made) ...
    last = cells >= n * (m + 1)
    j = cells[last] - n * (m + 1)
    cells[last] = m - j  # ... are column 0 turned over
    return _create(comm, "triangle", cells, x, False)


def flat_square(comm: MPI.Comm, n: int = 4):
    """The unit square in the plane ``z = 0`` of 3D: ``2 n^2`` triangles."""
    i, j = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    x = np.stack([i.ravel(), j.ravel(), np.zeros(i.size)], 1)
    return _create(comm, "triangle", _triangulated_grid(n, n), x, False)


def with_tags(
    mesh: dolfinx.mesh.Mesh, planes: dict[str, tuple[int, float]], name: str = "membrane"
):
    """The mesh with its groups: all cells ``name`` (tag 1), and the boundary facets (edges
    of a membrane, vertices of a string) on each plane ``x[axis] = value`` of ``planes``
    (name -> (axis, value); tags 1, 2, ... in order).

    Returns a :class:`~contact_ufl.gmshio.MeshData`.
    """
    from contact_ufl.gmshio import MeshData

    tdim = mesh.topology.dim
    num_cells = mesh.topology.index_map(tdim).size_local + mesh.topology.index_map(tdim).num_ghosts
    cells = np.arange(num_cells, dtype=np.int32)
    cell_tags = dolfinx.mesh.meshtags(mesh, tdim, cells, np.ones_like(cells))
    mesh.topology.create_connectivity(tdim - 1, tdim)
    scale = np.abs(mesh.geometry.x).max(initial=1.0)
    found, values = [], []
    groups = {name: (tdim, 1)}
    for tag, (plane, (axis, value)) in enumerate(planes.items(), start=1):
        facets = dolfinx.mesh.locate_entities_boundary(
            mesh, tdim - 1, lambda x, a=axis, v=value: np.isclose(x[a], v, atol=1e-9 * scale)
        )
        found.append(facets)
        values.append(np.full(len(facets), tag, dtype=np.int32))
        groups[plane] = (tdim - 1, tag)
    facets = np.concatenate(found) if found else np.zeros(0, np.int32)
    order = np.argsort(facets, kind="stable")
    facet_values = np.concatenate(values) if values else np.zeros(0, np.int32)
    facet_tags = dolfinx.mesh.meshtags(mesh, tdim - 1, facets[order], facet_values[order])
    return MeshData(mesh, cell_tags, facet_tags, groups)
