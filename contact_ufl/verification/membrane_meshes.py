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

With their named groups (a :class:`~contact_ufl.gmshio.MeshData`, ghosted on shared facets
like the gmsh scenes), for scenes of membranes in contact:

* :func:`string_ring`: a quarter, the upper half or the whole of a circle (intervals in 2D),
  with the vertices on the symmetry planes;
* :func:`tube_quarter`: a quarter of a tube with layers along its axis, with the edges on the
  symmetry planes and at its ends;
* :func:`drumhead`: a flat square membrane (or its quarter) in ``z = 0``, with its edges; or
  a straight string in 2D.
"""

from __future__ import annotations

import basix.ufl
import dolfinx
import dolfinx.mesh
import numpy as np
from mpi4py import MPI

SHARED_FACET = dolfinx.mesh.GhostMode.shared_facet


def _create(
    comm: MPI.Comm,
    cell: str,
    cells: np.ndarray,
    x: np.ndarray,
    reverse: bool,
    ghost_mode: dolfinx.mesh.GhostMode | None = None,
):
    """Distribute ``cells`` and ``x`` given on rank 0; reverse every other cell if asked.

    ``ghost_mode`` None is DOLFINx's default partitioner (no ghosts)."""
    cells = np.array(cells, dtype=np.int64)
    if reverse:
        flip = {"interval": [1, 0], "triangle": [0, 2, 1], "quadrilateral": [0, 2, 1, 3]}[cell]
        cells[1::2] = cells[1::2][:, flip]
    gdim = x.shape[1]
    element = basix.ufl.element("Lagrange", cell, 1, shape=(gdim,))
    if comm.rank != 0:
        cells, x = np.empty((0, cells.shape[1]), np.int64), np.empty((0, gdim))
    if ghost_mode is None:
        return dolfinx.mesh.create_mesh(comm, cells, element, x)
    partitioner = dolfinx.mesh.create_cell_partitioner(ghost_mode, 2)
    return dolfinx.mesh.create_mesh(comm, cells, element, x, partitioner=partitioner)


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
    mesh: dolfinx.mesh.Mesh,
    planes: dict[str, tuple[int, float]],
    name: str = "membrane",
    boundary_only: bool = True,
):
    """The mesh with its groups: all cells ``name`` (tag 1), and the boundary facets (edges
    of a membrane, vertices of a string) on each plane ``x[axis] = value`` of ``planes``
    (name -> (axis, value); tags 1, 2, ... in order). With ``boundary_only`` False, all
    facets on the planes (e.g. the vertices of a closed ring where it crosses a symmetry
    plane).

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
        locate = (
            dolfinx.mesh.locate_entities_boundary if boundary_only else dolfinx.mesh.locate_entities
        )
        facets = locate(
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


# -- meshes with named groups ------------------------------------------------------------------


def _check_size(**values: float) -> None:
    for name, value in values.items():
        if not 0.0 < value < np.inf:
            raise ValueError(f"{name} must be positive, got {name} = {value}")


def string_ring(
    comm: MPI.Comm,
    R: float,
    n: int,
    quarters: int = 1,
    reverse: bool = False,
    ghost_mode: dolfinx.mesh.GhostMode = SHARED_FACET,
):
    """A string ring of radius ``R`` about the origin in 2D (intervals), or part of it.

    ``quarters`` 1 is the quarter ``x, y >= 0`` (angles 0 to pi/2), 2 the upper half ``y >=
    0`` (0 to pi), 4 the closed ring; ``n`` intervals per quarter.

    Groups: cells ``"tube"`` (dimension 1, tag 1); vertices ``"x0"`` on the plane ``x = 0``
    (dimension 0, tag 1) and ``"y0"`` on ``y = 0`` (tag 2): the end points of a quarter; the
    two ends (``y0``) and the top vertex (``x0``) of a half; the top and bottom (``x0``) and
    the left and right vertices (``y0``) of the ring. The same supports serve all three:
    ``Dirichlet("x0", 0.0, component=0)`` and ``Dirichlet("y0", 0.0, component=1)`` (the
    symmetry conditions of a quarter or a half, and in the other cases the rigid motions
    removed without constraining a solution symmetric about both axes).

    The default orientation of a membrane domain (``n0`` away from the centroid of the
    curve) points outwards, away from the origin, for all three: a positive follower
    pressure inflates the ring.

    Returns
    -------
    MeshData
    """
    _check_size(R=R, n=n)
    if quarters not in (1, 2, 4):
        raise ValueError(f"quarters must be 1, 2 or 4, got {quarters}")
    cells_around = quarters * n
    theta = np.linspace(0.0, quarters * np.pi / 2, cells_around + 1)
    start = np.arange(cells_around)
    end = start + 1
    if quarters == 4:
        theta, end = theta[:-1], end % cells_around
    x = np.stack([R * np.cos(theta), R * np.sin(theta)], 1)
    mesh = _create(comm, "interval", np.stack([start, end], 1), x, reverse, ghost_mode)
    planes = {"x0": (0, 0.0), "y0": (1, 0.0)}
    return with_tags(mesh, planes, name="tube", boundary_only=False)


def tube_quarter(
    comm: MPI.Comm,
    R: float,
    n: int,
    length: float,
    n_axial: int = 1,
    cell: str = "quadrilateral",
    reverse: bool = False,
    ghost_mode: dolfinx.mesh.GhostMode = SHARED_FACET,
):
    """A quarter (``x, y >= 0``) of the tube of radius ``R`` about the z axis, ``0 <= z <=
    length``: ``n`` cells around and ``n_axial`` along the axis (quadrilaterals, or two
    triangles per quadrilateral).

    Groups: cells ``"tube"`` (dimension 2, tag 1); edges ``"x0"`` (the axial line on the plane
    ``x = 0``, tag 1), ``"y0"`` (on ``y = 0``, tag 2), ``"z0"`` and ``"z1"`` (the arcs at the
    ends ``z = 0`` and ``z = length``, tags 3 and 4). A long tube at axial stretch 1 (the
    plane-strain tube of :func:`~contact_ufl.verification.analytic.tube_between_plates`):
    ``Dirichlet("x0", 0.0, component=0)``, ``Dirichlet("y0", 0.0, component=1)`` and
    ``Dirichlet(e, 0.0, component=2)`` for ``e`` in ``"z0", "z1"``. The default orientation
    (away from the centroid) points out of the tube.

    Returns
    -------
    MeshData
    """
    _check_size(R=R, n=n, length=length, n_axial=n_axial)
    if cell not in ("quadrilateral", "triangle"):
        raise ValueError(f"cell must be 'quadrilateral' or 'triangle', got {cell!r}")
    theta = np.linspace(0.0, np.pi / 2, n + 1)
    T, Z = np.meshgrid(theta, np.linspace(0.0, length, n_axial + 1), indexing="ij")
    x = np.stack([R * np.cos(T), R * np.sin(T), Z], -1).reshape(-1, 3)  # node i (na + 1) + k
    if cell == "quadrilateral":
        i, k = np.meshgrid(np.arange(n), np.arange(n_axial), indexing="ij")
        n00 = (i * (n_axial + 1) + k).ravel()
        cells = np.stack([n00, n00 + n_axial + 1, n00 + 1, n00 + n_axial + 2], 1)
    else:
        cells = _triangulated_grid(n, n_axial)
    mesh = _create(comm, cell, cells, x, reverse, ghost_mode)
    planes = {"x0": (0, 0.0), "y0": (1, 0.0), "z0": (2, 0.0), "z1": (2, length)}
    return with_tags(mesh, planes, name="tube")


def _union_jack(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Triangles of the grid of nodes ``(xs[i], ys[j])`` numbered ``i * len(ys) + j``, each
    square cut along the diagonal that points to the origin (the mesh of a square centred at
    the origin is then symmetric about both axes)."""
    ni, nj = len(xs) - 1, len(ys) - 1
    i, j = np.meshgrid(np.arange(ni), np.arange(nj), indexing="ij")
    i, j = i.ravel(), j.ravel()
    n00 = i * (nj + 1) + j
    n10, n01, n11 = n00 + nj + 1, n00 + 1, n00 + nj + 2
    towards = (xs[i] + xs[i + 1]) * (ys[j] + ys[j + 1]) > 0.0
    main = np.vstack([np.stack([n00, n10, n11], 1), np.stack([n00, n11, n01], 1)])
    other = np.vstack([np.stack([n00, n10, n01], 1), np.stack([n10, n11, n01], 1)])
    return np.where(np.concatenate([towards, towards])[:, None], main, other)


def drumhead(
    comm: MPI.Comm,
    a: float,
    n: int,
    quarter: bool = False,
    dim: int = 3,
    ghost_mode: dolfinx.mesh.GhostMode = SHARED_FACET,
):
    """A flat square membrane in the plane ``z = 0`` of 3D (triangles): ``[-a, a]^2``, or its
    quarter ``[0, a]^2``; ``n`` cells along ``a`` (``2 n`` along a side of the whole square).
    With ``dim`` 2, its plane-strain counterpart: the straight string ``[-a, a]`` (or its half
    ``[0, a]``) on the line ``y = 0`` of 2D (intervals).

    The squares of the grid are cut along the diagonal pointing to the centre, so the whole
    mesh is symmetric about both axes (and a quarter is one quarter of it).

    Groups: cells ``"membrane"`` (dimension ``dim - 1``, tag 1); edges ``"xmin"``,
    ``"xmax"``, ``"ymin"``, ``"ymax"`` (the edges ``x = -a``, ``x = a``, ``y = -a``, ``y = a``;
    tags 1 to 4) of the whole square; ``"x0"``, ``"y0"`` (the symmetry edges ``x = 0`` and ``y
    = 0``), ``"xmax"``, ``"ymax"`` (tags 1 to 4) of the quarter. A string has the end points
    ``"xmin"``, ``"xmax"`` (tags 1, 2), or ``"x0"``, ``"xmax"`` for its half. The edges held
    by the frame: :data:`DRUMHEAD_EDGES`. Flat: its domain needs ``direction`` (e.g. ``(0, 0,
    1)``: ``n0 = +z``, a positive follower pressure pushes it up). See
    :func:`contact_ufl.verification.scenes.pretensioned_drumhead`.

    Returns
    -------
    MeshData
    """
    _check_size(a=a, n=n)
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    xs = np.linspace(0.0 if quarter else -a, a, (1 if quarter else 2) * n + 1)
    if dim == 2:
        x = np.stack([xs, np.zeros_like(xs)], 1)
        cells = np.stack([np.arange(len(xs) - 1), np.arange(1, len(xs))], 1)
        mesh = _create(comm, "interval", cells, x, False, ghost_mode)
        planes = {"x0": (0, 0.0)} if quarter else {"xmin": (0, -a)}
        return with_tags(mesh, {**planes, "xmax": (0, a)}, name="membrane")
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    x = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    mesh = _create(comm, "triangle", _union_jack(xs, xs), x, False, ghost_mode)
    if quarter:
        planes = {"x0": (0, 0.0), "y0": (1, 0.0), "xmax": (0, a), "ymax": (1, a)}
    else:
        planes = {"xmin": (0, -a), "xmax": (0, a), "ymin": (1, -a), "ymax": (1, a)}
    return with_tags(mesh, planes, name="membrane")


#: The framed edges of :func:`drumhead`: name -> (the in-plane axis normal to it, its sign).
DRUMHEAD_EDGES = {"xmin": (0, -1.0), "xmax": (0, 1.0), "ymin": (1, -1.0), "ymax": (1, 1.0)}
