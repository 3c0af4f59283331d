"""Contact patch tests: two stacked rectangles (:func:`patch_2d`) or boxes
(:func:`patch_3d`) with non-matching meshes.
"""

from __future__ import annotations

from pathlib import Path

import dolfinx
import gmsh
import numpy as np
from mpi4py import MPI

from contact_ufl.gmshio import MeshData, generate_mesh
from contact_ufl.verification.geometries._gmsh import (
    _add_groups,
    _boundary,
    _check_common,
    _check_positive,
    _divisions,
    _extent,
    _flat,
    _generate,
    _mesh_options,
    _sizes_per_body,
    _structured,
)


def patch_2d(
    width: float = 1.0,
    height: float = 0.5,
    h_upper: float | None = None,
    h_lower: float | None = None,
    gap: float = 0.0,
    cell: str = "triangle",
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """Plane patch test: two stacked rectangles with non-matching meshes.

    Lower body ``[0, w] x [-height, 0]``, upper body ``[0, w] x [gap, gap + height]``. Every
    edge is divided uniformly into ``round(length / h)`` segments of its body (at least one);
    triangles are then unstructured, quadrilaterals structured (transfinite, recombined).

    Parameters
    ----------
    width
        Width w of both bodies.
    height
        Height of each body.
    h_upper
        Element size of the upper body (default ``width / 10``).
    h_lower
        Element size of the lower body (default ``width / 7``: 10 and 7 divisions of the contact
        edges, which meet only at their end points).
    gap
        Initial gap (>= 0).
    cell
        ``"triangle"`` or ``"quadrilateral"``.
    order
        Geometry order, 1 or 2.
    comm, msh_file, ghost_mode
        As in :func:`hertz_2d`.

    Returns
    -------
    MeshData
        Cell groups ``"upper"`` (1), ``"lower"`` (2); facet groups ``"upper_contact"`` (bottom
        of upper, 11), ``"lower_contact"`` (top of lower, 12), ``"upper_top"`` (13),
        ``"lower_bottom"`` (14), ``"upper_left"`` (15), ``"lower_left"`` (16),
        ``"upper_right"`` (17), ``"lower_right"`` (18).
    """
    h_upper = width / 10.0 if h_upper is None else h_upper
    h_lower = width / 7.0 if h_lower is None else h_lower
    _check_positive(width=width, height=height, h_upper=h_upper, h_lower=h_lower)
    _check_common(gap, order)
    if cell not in ("triangle", "quadrilateral"):
        raise ValueError(f"cell must be 'triangle' or 'quadrilateral', got {cell!r}")

    def rectangle(y0: float, h: float) -> tuple[int, list[int]]:
        geo = gmsh.model.geo
        p = [geo.addPoint(x, y, 0.0) for x, y in ((0, y0), (width, y0), (width, y0 + height))]
        p.append(geo.addPoint(0.0, y0 + height, 0.0))
        lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]  # bottom, right, top, left
        surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        # constraints through geo.mesh: a later geo.synchronize() keeps them
        nx, ny = _divisions(width, h), _divisions(height, h)
        for line, n in zip(lines, (nx, ny, nx, ny), strict=True):
            geo.mesh.setTransfiniteCurve(line, n + 1)
        if cell == "quadrilateral":
            geo.mesh.setTransfiniteSurface(surface)
            geo.mesh.setRecombine(2, surface)
        return surface, lines

    def build() -> None:
        up, (up_bottom, up_right, up_top, up_left) = rectangle(gap, h_upper)
        lo, (lo_bottom, lo_right, lo_top, lo_left) = rectangle(-height, h_lower)
        gmsh.model.geo.synchronize()
        _add_groups(
            [
                ("upper", 2, [up]),
                ("lower", 2, [lo]),
                ("upper_contact", 1, [up_bottom]),
                ("lower_contact", 1, [lo_top]),
                ("upper_top", 1, [up_top]),
                ("lower_bottom", 1, [lo_bottom]),
                ("upper_left", 1, [up_left]),
                ("lower_left", 1, [lo_left]),
                ("upper_right", 1, [up_right]),
                ("lower_right", 1, [lo_right]),
            ],
            tdim=2,
        )
        # interior sizes of the unstructured triangles
        _sizes_per_body(2, [(h_upper, [up]), (h_lower, [lo])])
        _generate(2, order)

    return generate_mesh(
        comm,
        "patch_2d",
        build,
        2,
        _mesh_options(order),
        msh_file,
        ghost_mode,
        contact_surfaces=("upper_contact", "lower_contact"),
    )


def patch_3d(
    width: float = 1.0,
    height: float = 0.5,
    h_upper: float | None = None,
    h_lower: float | None = None,
    gap: float = 0.0,
    cell: str = "tetrahedron",
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """Patch test in 3D: two stacked boxes with non-matching meshes.

    Lower body ``[0, w]^2 x [-height, 0]``, upper body ``[0, w]^2 x [gap, gap + height]``.
    Tetrahedra are unstructured with the size of their body; hexahedra are structured
    (transfinite, recombined) with ``round(length / h)`` divisions of each edge.

    Parameters
    ----------
    width
        Width w of both bodies in x and y.
    height
        Height of each body.
    h_upper
        Element size of the upper body (default ``width / 6``).
    h_lower
        Element size of the lower body (default ``width / 5``).
    gap
        Initial gap (>= 0).
    cell
        ``"tetrahedron"`` or ``"hexahedron"``.
    order
        Geometry order, 1 or 2.
    comm, msh_file, ghost_mode
        As in :func:`hertz_2d`.

    Returns
    -------
    MeshData
        Cell groups ``"upper"`` (1), ``"lower"`` (2); facet groups ``"upper_contact"`` (11),
        ``"lower_contact"`` (12), ``"upper_top"`` (13), ``"lower_bottom"`` (14), then the
        side faces ``"upper_x0"``, ``"lower_x0"``, ``"upper_y0"``, ``"lower_y0"`` (faces
        x = 0 and y = 0, 15-18) and ``"upper_x1"``, ``"lower_x1"``, ``"upper_y1"``,
        ``"lower_y1"`` (faces x = w and y = w, 19-22).
    """
    h_upper = width / 6.0 if h_upper is None else h_upper
    h_lower = width / 5.0 if h_lower is None else h_lower
    _check_positive(width=width, height=height, h_upper=h_upper, h_lower=h_lower)
    _check_common(gap, order)
    if cell not in ("tetrahedron", "hexahedron"):
        raise ValueError(f"cell must be 'tetrahedron' or 'hexahedron', got {cell!r}")
    tol = 1e-5 * max(width, height)

    def classify(volume: int, z0: float) -> dict[str, int]:
        faces: dict[str, int] = {}
        for face in _boundary(3, [volume], 2):
            axis, coord = _flat(face, tol)  # type: ignore[misc]  (all faces are flat)
            side = "0" if abs(coord - (z0 if axis == 2 else 0.0)) < tol else "1"
            faces["xyz"[axis] + side] = face
        return faces

    def build() -> None:
        up = gmsh.model.occ.addBox(0.0, 0.0, gap, width, width, height)
        lo = gmsh.model.occ.addBox(0.0, 0.0, -height, width, width, height)
        gmsh.model.occ.synchronize()
        fu, fl = classify(up, gap), classify(lo, -height)
        if cell == "hexahedron":
            for volume, h in ((up, h_upper), (lo, h_lower)):
                _structured([volume], lambda c, h=h: _divisions(float(np.max(_extent(1, c))), h))
        _add_groups(
            [
                ("upper", 3, [up]),
                ("lower", 3, [lo]),
                ("upper_contact", 2, [fu["z0"]]),
                ("lower_contact", 2, [fl["z1"]]),
                ("upper_top", 2, [fu["z1"]]),
                ("lower_bottom", 2, [fl["z0"]]),
            ]
            + [
                (f"{body}_{side}", 2, [faces[side]])
                for side in ("x0", "y0", "x1", "y1")
                for body, faces in (("upper", fu), ("lower", fl))
            ],
            tdim=3,
        )
        _sizes_per_body(3, [(h_upper, [up]), (h_lower, [lo])])
        _generate(3, order)

    return generate_mesh(
        comm,
        "patch_3d",
        build,
        3,
        _mesh_options(order),
        msh_file,
        ghost_mode,
        contact_surfaces=("upper_contact", "lower_contact"),
    )
