"""Gmsh meshes of the two-body benchmark scenes (verification; not part of the library).

Each generator builds two disjoint bodies, each meshed on its own (the meshes do not match
at the contact interface and share no node, even where the bodies touch), and returns them
as *one* DOLFINx mesh with named cell and facet tags. The gmsh model is built on rank 0 of
``comm`` and distributed by :func:`contact_ufl.gmshio.generate_mesh`.

Generators
----------
* :func:`hertz_2d`: half disc on a rectangular block (plane, Hertz problem).
* :func:`curved_2d`: half disc on a block whose top is a circular arc.
* :func:`patch_2d`: two stacked rectangles (contact patch test), triangles or quadrilaterals.
* :func:`patch_3d`: two stacked boxes, tetrahedra or hexahedra.
* :func:`cylinders_3d`: half cylinder on a block with a cylindrical top of crossed axis.
* :func:`hemisphere_3d`: a hemispherical indenter (one body; for a solid pressed into a
  membrane).
* :func:`beams_3d`: two cantilever beams, clamped on the same side or at opposite ends,
  overlapping in plan.
* :func:`sphere_on_block_3d`: a half ball on a block, quarter model (3D Hertz).
* :func:`ironing_3d`: a cylindrical die over a slab (3D ironing, Puso & Laursen 2004).
* :func:`ironing_extruded`: the 2D shallow ironing on quadrilaterals, or extruded through a
  thickness by one layer of hexahedra (plane strain in 3D).

Tag values are the same for every scene: cell groups get the values 1, 2 and facet groups
11, 12, ... in the order they are listed in each generator's documentation; always look them
up by name through :attr:`contact_ufl.gmshio.MeshData.tags`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import dolfinx
import gmsh
import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from contact_ufl.gmshio import MeshData, generate_mesh

__all__ = [
    "hertz_2d",
    "curved_2d",
    "patch_2d",
    "patch_3d",
    "cylinders_3d",
    "hemisphere_3d",
    "ironing_2d",
    "ironing_3d",
    "ironing_extruded",
    "BeamPair",
    "beams_3d",
    "sphere_on_block_3d",
    "tag_single_body",
]

_CELL_TAG0 = 1
_FACET_TAG0 = 11


# --------------------------------------------------------------------------------------------
# gmsh helpers of the geometries
# --------------------------------------------------------------------------------------------


def _add_groups(groups: list[tuple[str, int, list[int]]], tdim: int) -> None:
    """Add named physical groups: cells numbered from 1, facets from 11."""
    next_tag = {tdim: _CELL_TAG0, tdim - 1: _FACET_TAG0}
    for name, dim, entities in groups:
        if len(entities) == 0:
            raise RuntimeError(f"physical group '{name}' has no geometric entity")
        gmsh.model.addPhysicalGroup(dim, list(entities), tag=next_tag[dim], name=name)
        next_tag[dim] += 1


def _mesh_options(order: int) -> dict[str, float]:
    """Options common to all scenes: sizes from the background field only."""
    return {
        "Mesh.MeshSizeFromPoints": 0.0,
        "Mesh.MeshSizeFromCurvature": 0.0,
        "Mesh.MeshSizeExtendFromBoundary": 0.0,
        "Mesh.Algorithm": 6.0,  # Frontal-Delaunay
        "Mesh.Algorithm3D": 1.0,  # Delaunay
        "Mesh.ElementOrder": float(order),
        "Mesh.SecondOrderLinear": 0.0,  # high-order nodes on the curved geometry
        "Mesh.HighOrderOptimize": 0.0,
        "Mesh.SecondOrderIncomplete": 0.0,
    }


def _restricted(field: int, dim: int, entities: list[int]) -> int:
    """Restrict ``field`` to entities of dimension ``dim`` and their boundaries."""
    key = {1: "CurvesList", 2: "SurfacesList", 3: "VolumesList"}[dim]
    restrict = gmsh.model.mesh.field.add("Restrict")
    gmsh.model.mesh.field.setNumber(restrict, "InField", field)
    gmsh.model.mesh.field.setNumbers(restrict, key, entities)
    gmsh.model.mesh.field.setNumber(restrict, "IncludeBoundary", 1)
    return restrict


def _constant(h: float) -> int:
    """A constant size field."""
    field = gmsh.model.mesh.field.add("MathEval")
    gmsh.model.mesh.field.setString(field, "F", repr(float(h)))
    return field


def _threshold(distance: int, h_min: float, h_max: float, d_min: float, d_max: float) -> int:
    """Size ``h_min`` within ``d_min`` of the distance field, growing to ``h_max`` at ``d_max``."""
    field = gmsh.model.mesh.field.add("Threshold")
    gmsh.model.mesh.field.setNumber(field, "InField", distance)
    gmsh.model.mesh.field.setNumber(field, "SizeMin", h_min)
    gmsh.model.mesh.field.setNumber(field, "SizeMax", h_max)
    gmsh.model.mesh.field.setNumber(field, "DistMin", d_min)
    gmsh.model.mesh.field.setNumber(field, "DistMax", d_max)
    return field


def _distance_to(point: tuple[float, float, float]) -> int:
    """Distance to a point that need not be a vertex of the geometry (a MathEval field)."""
    x0, y0, z0 = (repr(float(c)) for c in point)
    field = gmsh.model.mesh.field.add("MathEval")
    gmsh.model.mesh.field.setString(field, "F", f"Sqrt((x-{x0})^2+(y-{y0})^2+(z-{z0})^2)")
    return field


def _set_background(fields: list[int]) -> None:
    """The minimum of ``fields`` as the background size field."""
    field = gmsh.model.mesh.field.add("Min")
    gmsh.model.mesh.field.setNumbers(field, "FieldsList", fields)
    gmsh.model.mesh.field.setAsBackgroundMesh(field)


def _boundary(dim: int, entities: list[int], target: int) -> list[int]:
    """Entities of dimension ``target`` < ``dim`` on the boundary of the given entities."""
    tags = {(dim, e) for e in entities}
    for _ in range(dim - target):
        tags = set(gmsh.model.getBoundary(sorted(tags), combined=False, oriented=False))
    return sorted({abs(t) for _, t in tags})


def _bbox(dim: int, tag: int) -> npt.NDArray[np.float64]:
    """Bounding box ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` of an entity."""
    return np.asarray(gmsh.model.getBoundingBox(dim, tag)).reshape(2, 3)


def _extent(dim: int, tag: int) -> npt.NDArray[np.float64]:
    """Extent of the bounding box of an entity along each axis."""
    lo, hi = _bbox(dim, tag)
    return hi - lo


def _flat(tag: int, tol: float) -> tuple[int, float] | None:
    """``(axis, coordinate)`` if the surface ``tag`` lies in a plane normal to an axis."""
    lo, hi = _bbox(2, tag)
    extent = hi - lo
    axis = int(np.argmin(extent))
    if extent[axis] > tol:
        return None
    return axis, float(0.5 * (lo[axis] + hi[axis]))


def _check_positive(**values: float) -> None:
    for key, value in values.items():
        if not (value > 0.0 and math.isfinite(value)):
            raise ValueError(f"{key} must be positive and finite, got {value}")


def _check_common(gap: float, order: int) -> None:
    if not (gap >= 0.0 and math.isfinite(gap)):
        raise ValueError(f"gap must be >= 0, got {gap}")
    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, got {order}")


def _divisions(length: float, h: float) -> int:
    """Number of element edges of size about ``h`` on a line of the given length."""
    return max(1, int(math.floor(length / h + 0.5)))


def _generate(dim: int, order: int = 1) -> None:
    """Mesh the model in dimension ``dim``, then raise it to the geometry ``order``."""
    gmsh.model.mesh.generate(dim)
    if order > 1:
        gmsh.model.mesh.setOrder(order)


def _sizes_per_body(dim: int, sizes: list[tuple[float, list[int]]]) -> None:
    """A constant element size in each body: ``sizes`` lists ``(h, entities)`` of dimension
    ``dim``; their minimum is the background field."""
    _set_background([_restricted(_constant(h), dim, entities) for h, entities in sizes])


def _structured(volumes: list[int], divisions: Callable[[int], int]) -> None:
    """Transfinite hexahedra in ``volumes``: ``divisions(curve)`` element edges on each of
    their curves, their faces recombined."""
    for curve in _boundary(3, volumes, 1):
        gmsh.model.mesh.setTransfiniteCurve(curve, divisions(curve) + 1)
    for face in _boundary(3, volumes, 2):
        gmsh.model.mesh.setTransfiniteSurface(face)
        gmsh.model.mesh.setRecombine(2, face)
    for volume in volumes:
        gmsh.model.mesh.setTransfiniteVolume(volume)


def _sort_faces(
    volume: int, tol: float, names: dict[str, list[int]], curved: str, flat: tuple[str, ...]
) -> None:
    """Append each face of ``volume`` to a list of ``names``: a curved face to ``curved``, a
    plane face normal to axis ``k`` to ``flat[k]``."""
    for face in _boundary(3, [volume], 2):
        plane = _flat(face, tol)
        names[curved if plane is None else flat[plane[0]]].append(face)


@dataclass(frozen=True)
class _Grading:
    """Element sizes graded about the point of first contact of two bodies: ``h_contact``
    within ``refine_radius * radius`` of it (the master body ``master_ratio`` times coarser
    there), growing to ``h_far`` over a further ``radius``."""

    h_contact: float
    h_far: float
    master_ratio: float
    refine_radius: float

    def __post_init__(self) -> None:
        _check_positive(
            h_contact=self.h_contact,
            h_far=self.h_far,
            master_ratio=self.master_ratio,
            refine_radius=self.refine_radius,
        )

    def set_background(
        self, distance: int, radius: float, dim: int, upper: list[int], lower: list[int]
    ) -> None:
        """The graded sizes about the ``distance`` field, in the ``upper`` (slave) and
        ``lower`` (master) entities of dimension ``dim``, as the background field."""
        d_min = self.refine_radius * radius
        d_max = d_min + radius
        fine = _threshold(distance, self.h_contact, self.h_far, d_min, d_max)
        coarse = _threshold(distance, self.master_ratio * self.h_contact, self.h_far, d_min, d_max)
        _set_background([_restricted(fine, dim, upper), _restricted(coarse, dim, lower)])


# --------------------------------------------------------------------------------------------
# 2D: half disc on a block (flat or curved top)
# --------------------------------------------------------------------------------------------


def _disc_sizes(
    radius: float,
    block: tuple[float, float],
    h_contact: float | None,
    h_far: float | None,
    master_ratio: float,
    refine_radius: float,
    gap: float,
    order: int,
) -> tuple[_Grading, float, float]:
    """The checked sizes of the half disc on a block (:func:`hertz_2d`): the grading (its
    defaults filled in), the width and the height of the block."""
    h_contact = 0.02 * radius if h_contact is None else h_contact
    h_far = 0.2 * radius if h_far is None else h_far
    width, height = block
    _check_positive(radius=radius, width=width, height=height)
    grading = _Grading(h_contact, h_far, master_ratio, refine_radius)
    _check_common(gap, order)
    return grading, width, height


def _disc_on_block(
    radius: float,
    gap: float,
    width: float,
    height: float,
    lower_radius: float | None,
    grading: _Grading,
    order: int,
    x_disc: float = 0.0,
    axis: bool = False,
) -> None:
    """Build and mesh the half disc over a block with a flat (``lower_radius`` None) or arc top.

    The disc's centre is at ``(x_disc, R + gap)``; with ``axis``, the disc's vertical radius
    from its lowest point to its centre is a line of the mesh (group ``"cylinder_axis"``)."""
    geo = gmsh.model.geo
    R, a = radius, 0.5 * width
    yc = R + gap
    # upper body: lower half of the circle of centre (x_disc, R + gap)
    c = geo.addPoint(x_disc, yc, 0.0)
    p_left = geo.addPoint(x_disc - R, yc, 0.0)
    p_bottom = geo.addPoint(x_disc, gap, 0.0)
    p_right = geo.addPoint(x_disc + R, yc, 0.0)
    arc_left = geo.addCircleArc(p_left, c, p_bottom)
    arc_right = geo.addCircleArc(p_bottom, c, p_right)
    if axis:  # the diameter split at the centre, where the axis ends
        diameter = [geo.addLine(p_right, c), geo.addLine(c, p_left)]
        radius_line = geo.addLine(p_bottom, c)
    else:
        diameter = [geo.addLine(p_right, p_left)]
    disc = geo.addPlaneSurface([geo.addCurveLoop([arc_left, arc_right, *diameter])])
    # lower body: [-a, a] x [-height, top(x)]
    q0 = geo.addPoint(-a, -height, 0.0)
    q1 = geo.addPoint(a, -height, 0.0)
    if lower_radius is None:
        y_top = 0.0
        q2 = geo.addPoint(a, y_top, 0.0)
        q3 = geo.addPoint(-a, y_top, 0.0)
        top = [geo.addLine(q2, q3)]
    else:
        R2 = abs(lower_radius)
        sign = 1.0 if lower_radius > 0 else -1.0  # convex (centre below) or concave
        y_top = sign * (math.sqrt(R2 * R2 - a * a) - R2)
        q2 = geo.addPoint(a, y_top, 0.0)
        q3 = geo.addPoint(-a, y_top, 0.0)
        c2 = geo.addPoint(0.0, -sign * R2, 0.0)
        top = [geo.addCircleArc(q2, c2, q3)]
    bottom = geo.addLine(q0, q1)
    right = geo.addLine(q1, q2)
    left = geo.addLine(q3, q0)
    block = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, *top, left])])
    geo.synchronize()
    if axis:
        gmsh.model.mesh.embed(1, [radius_line], 2, disc)

    _add_groups(
        [
            ("cylinder", 2, [disc]),
            ("block", 2, [block]),
            ("cylinder_contact", 1, [arc_left, arc_right]),
            ("cylinder_top", 1, diameter),
            ("block_contact", 1, top),
            ("block_bottom", 1, [bottom]),
            ("block_sides", 1, [left, right]),
        ]
        + ([("cylinder_axis", 1, [radius_line])] if axis else []),
        tdim=2,
    )
    distance = gmsh.model.mesh.field.add("Distance")
    gmsh.model.mesh.field.setNumbers(distance, "PointsList", [p_bottom])
    grading.set_background(distance, R, 2, [disc], [block])
    _generate(2, order)


def hertz_2d(
    radius: float = 1.0,
    block: tuple[float, float] = (4.0, 1.5),
    gap: float = 0.0,
    h_contact: float | None = None,
    h_far: float | None = None,
    master_ratio: float = 1.3,
    refine_radius: float = 0.3,
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
    x_disc: float = 0.0,
    axis: bool = False,
) -> MeshData:
    """Plane Hertz scene: a half disc resting on a rectangular block.

    The half disc is the lower half of the circle of radius ``radius`` and centre
    ``(0, radius + gap)``; the block is ``[-w/2, w/2] x [-height, 0]``. Both bodies are refined
    near the contact point ``(0, 0)`` (size ``h_contact`` within ``refine_radius * radius`` of
    the lowest point of the disc, growing to ``h_far`` over a further ``radius``); the block is
    ``master_ratio`` times coarser there, so the interface meshes do not match.

    Parameters
    ----------
    radius
        Radius R of the disc.
    block
        ``(width, height)`` of the block.
    gap
        Initial gap between the lowest point of the disc and the block (>= 0).
    h_contact
        Element size near the contact point (default ``0.02 * radius``).
    h_far
        Element size away from it (default ``0.2 * radius``).
    master_ratio
        Block size / disc size near the contact point.
    refine_radius
        Radius of the refined zone, in units of ``radius``.
    order
        Geometry order, 1 or 2 (P2 nodes lie on the arcs).
    comm
        Communicator of the mesh; the model is built on its rank 0.
    msh_file
        If given, the gmsh mesh is also written there (e.g. ``"meshes/hertz_2d.msh"``).
    ghost_mode
        Ghost mode of the cell partitioner.
    x_disc
        Horizontal position of the disc's centre (and of the refinement).
    axis
        Mesh the disc's vertical radius, from its lowest point to its centre, as a line of
        facets (group ``"cylinder_axis"``, 16; the diameter is then split at the centre):
        a support there holds the disc's rotation about its centre.

    Returns
    -------
    MeshData
        Cell groups ``"cylinder"`` (1), ``"block"`` (2); facet groups ``"cylinder_contact"``
        (lower arc, 11), ``"cylinder_top"`` (diameter, 12), ``"block_contact"`` (top edge, 13),
        ``"block_bottom"`` (14), ``"block_sides"`` (left and right, 15), with ``axis``
        ``"cylinder_axis"`` (16, interior facets).
    """
    sizes = radius, block, h_contact, h_far, master_ratio, refine_radius, gap, order
    grading, width, height = _disc_sizes(*sizes)

    def build() -> None:
        _disc_on_block(radius, gap, width, height, None, grading, order, x_disc, axis)

    return generate_mesh(
        comm,
        "hertz_2d",
        build,
        2,
        _mesh_options(order),
        msh_file,
        ghost_mode,
        contact_surfaces=("cylinder_contact", "block_contact"),
    )


def curved_2d(
    radius: float = 1.0,
    lower_radius: float | None = None,
    block: tuple[float, float] = (4.0, 1.5),
    gap: float = 0.0,
    h_contact: float | None = None,
    h_far: float | None = None,
    master_ratio: float = 1.3,
    refine_radius: float = 0.3,
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """Plane curved-on-curved scene: the half disc of :func:`hertz_2d` on an arched block.

    The lower body is ``{-w/2 <= x <= w/2, -height <= y <= top(x)}`` whose top is a circular
    arc of radius ``R2 = |lower_radius|`` through ``(0, 0)``: convex, ``top(x) =
    sqrt(R2^2 - x^2) - R2``, for ``lower_radius > 0``; concave, ``top(x) = R2 - sqrt(R2^2 -
    x^2)``, for ``lower_radius < 0`` (then ``R2 > radius`` is required).

    Parameters
    ----------
    radius
        Radius R of the disc.
    lower_radius
        Signed radius of the top arc of the lower body (default ``3 * radius``, convex).
    block
        ``(width, height)`` of the lower body; ``width / 2 < |lower_radius|``.
    gap, h_contact, h_far, master_ratio, refine_radius, order, comm, msh_file, ghost_mode
        As in :func:`hertz_2d`.

    Returns
    -------
    MeshData
        The names and values of :func:`hertz_2d`; ``"block_contact"`` is the top arc.
    """
    sizes = radius, block, h_contact, h_far, master_ratio, refine_radius, gap, order
    grading, width, height = _disc_sizes(*sizes)
    lower_radius = 3.0 * radius if lower_radius is None else lower_radius
    R2 = abs(lower_radius)
    if not 0.5 * width < R2:
        raise ValueError(f"need width / 2 < |lower_radius|, got {width}, {lower_radius}")
    if lower_radius < 0 and not R2 > radius:
        raise ValueError(f"a concave top needs |lower_radius| > radius, got {lower_radius}")
    if lower_radius > 0 and not (math.sqrt(R2 * R2 - 0.25 * width * width) - R2) > -height:
        raise ValueError("the top arc of the lower body goes below its bottom: increase height")

    def build() -> None:
        _disc_on_block(radius, gap, width, height, lower_radius, grading, order)

    return generate_mesh(
        comm,
        "curved_2d",
        build,
        2,
        _mesh_options(order),
        msh_file,
        ghost_mode,
        contact_surfaces=("cylinder_contact", "block_contact"),
    )


# --------------------------------------------------------------------------------------------
# Patch tests
# --------------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------------
# 3D curved-on-curved: half cylinder on a block with a cylindrical top (crossed axes)
# --------------------------------------------------------------------------------------------


def cylinders_3d(
    radius: float = 1.0,
    length: float = 1.0,
    lower_radius: float | None = None,
    block: tuple[float, float, float] | None = None,
    gap: float = 0.0,
    h_contact: float | None = None,
    h_far: float | None = None,
    master_ratio: float = 1.3,
    refine_radius: float = 0.3,
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """3D curved-on-curved scene: a half cylinder on a block with a cylindrical top.

    Upper body: the lower half of the cylinder of radius R with axis along y through
    ``(0, ., R + gap)``, for ``-length/2 <= y <= length/2``. Lower body: ``{|x| <= wx/2,
    |y| <= wy/2, -height <= z <= top(y)}`` whose top is the convex cylinder of radius
    ``R2 = lower_radius`` with axis along x through ``(., 0, -R2)``: ``top(y) = sqrt(R2^2 -
    y^2) - R2``. The axes cross, so the bodies touch at the origin only (for ``gap = 0``) and
    the contact surfaces are curved in different directions. (A concave top would meet the
    straight generators of the upper body at its ends first, so it is not offered.)
    Tetrahedra, refined near the origin as in :func:`hertz_2d`.

    Parameters
    ----------
    radius
        Radius R of the upper half cylinder.
    length
        Length of the upper half cylinder along y.
    lower_radius
        Radius of the convex top of the lower body (default ``3 * radius``).
    block
        ``(wx, wy, height)`` of the lower body (default ``(2 R, 1.5 length, 0.5 R)``);
        ``wy / 2 < lower_radius``.
    gap
        Initial gap (>= 0).
    h_contact
        Element size near the contact point (default ``0.1 * radius``).
    h_far
        Element size away from it (default ``0.25 * radius``).
    master_ratio, refine_radius, order, comm, msh_file, ghost_mode
        As in :func:`hertz_2d`.

    Returns
    -------
    MeshData
        Cell groups ``"upper"`` (1), ``"lower"`` (2); facet groups ``"upper_contact"``
        (curved face, 11), ``"lower_contact"`` (curved top, 12), ``"upper_top"`` (flat face
        z = R + gap, 13), ``"lower_bottom"`` (14), ``"upper_ends"`` (faces y = +-length/2,
        15), ``"lower_sides"`` (the four vertical faces, 16).
    """
    R = radius
    h_contact = 0.1 * R if h_contact is None else h_contact
    h_far = 0.25 * R if h_far is None else h_far
    lower_radius = 3.0 * R if lower_radius is None else lower_radius
    wx, wy, height = (2.0 * R, 1.5 * length, 0.5 * R) if block is None else block
    _check_positive(radius=R, length=length, wx=wx, wy=wy, height=height)
    grading = _Grading(h_contact, h_far, master_ratio, refine_radius)
    _check_common(gap, order)
    _check_positive(lower_radius=lower_radius)
    R2 = lower_radius
    if not 0.5 * wy < R2:
        raise ValueError(f"need wy / 2 < lower_radius, got {wy}, {lower_radius}")
    if not (math.sqrt(R2 * R2 - 0.25 * wy * wy) - R2) > -height:
        raise ValueError("the top of the lower body goes below its bottom: increase height")
    tol = 1e-5 * max(R, length, wx, wy, height)

    def build() -> None:
        occ = gmsh.model.occ
        zc = R + gap
        # upper body: cylinder along y intersected with the half space z <= zc (the cutting
        # box overhangs the cylinder, so no face of it is tangent to the cylinder)
        cyl = occ.addCylinder(0.0, -0.5 * length, zc, 0.0, length, 0.0, R)
        cut = occ.addBox(-2 * R, -length, zc - 2 * R, 4 * R, 2 * length, 2 * R)
        (upper_dt,), _ = occ.intersect([(3, cyl)], [(3, cut)])
        # lower body: a box, overhanging at the top, intersected with a cylinder along x
        cyl2 = occ.addCylinder(-wx, 0.0, -R2, 2 * wx, 0.0, 0.0, R2)
        box = occ.addBox(-0.5 * wx, -0.5 * wy, -height, wx, wy, 2 * height)
        (lower_dt,), _ = occ.intersect([(3, box)], [(3, cyl2)])
        occ.synchronize()
        up, lo = upper_dt[1], lower_dt[1]

        names: dict[str, list[int]] = {
            "upper_contact": [],
            "lower_contact": [],
            "upper_top": [],
            "lower_bottom": [],
            "upper_ends": [],
            "lower_sides": [],
        }
        _sort_faces(up, tol, names, "upper_contact", ("upper_ends", "upper_ends", "upper_top"))
        sides = ("lower_sides", "lower_sides", "lower_bottom")
        _sort_faces(lo, tol, names, "lower_contact", sides)
        _add_groups(
            [("upper", 3, [up]), ("lower", 3, [lo])]
            + [(key, 2, value) for key, value in names.items()],
            tdim=3,
        )
        grading.set_background(_distance_to((0.0, 0.0, gap)), R, 3, [up], [lo])
        _generate(3, order)

    return generate_mesh(
        comm,
        "cylinders_3d",
        build,
        3,
        _mesh_options(order),
        msh_file,
        ghost_mode,
        contact_surfaces=("upper_contact", "lower_contact"),
    )


def hemisphere_3d(
    radius: float = 0.25,
    gap: float = 0.0,
    h_contact: float | None = None,
    h_far: float | None = None,
    refine_radius: float = 0.3,
    quarter: bool = False,
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """A hemispherical indenter (one body): the lower half of the ball of radius R centred
    at ``(0, 0, R + gap)``, its lowest point ``(0, 0, gap)``; or its quarter ``x, y >= 0``.
    Tetrahedra of size ``h_contact`` within ``refine_radius * R`` of the lowest point, growing
    to ``h_far`` over a further R. For a solid pressed into a flat membrane (the drumhead of
    :func:`contact_ufl.verification.membrane_meshes.drumhead`, its centre under the
    indenter): move ``"indenter_top"`` down.

    Parameters
    ----------
    radius
        Radius R.
    gap
        Height of the lowest point (>= 0).
    h_contact, h_far
        Element sizes near the lowest point and far from it (defaults ``0.1 R``, ``0.3 R``).
    refine_radius, order, comm, msh_file, ghost_mode
        As in :func:`hertz_2d`.
    quarter
        The quarter ``x, y >= 0`` (symmetry faces ``x = 0`` and ``y = 0``).

    Returns
    -------
    MeshData
        Cell group ``"indenter"`` (1); facet groups ``"indenter_contact"`` (the spherical
        face, 11), ``"indenter_top"`` (the flat face ``z = R + gap``, 12), and for a quarter
        ``"indenter_x0"``, ``"indenter_y0"`` (the symmetry faces, 13, 14).
    """
    R = radius
    h_contact = 0.1 * R if h_contact is None else h_contact
    h_far = 0.3 * R if h_far is None else h_far
    _check_positive(radius=R, h_contact=h_contact, h_far=h_far, refine_radius=refine_radius)
    _check_common(gap, order)
    tol = 1e-5 * R

    def build() -> None:
        occ = gmsh.model.occ
        zc = R + gap
        ball = occ.addSphere(0.0, 0.0, zc, R)
        lo = 0.0 if quarter else -2.0 * R
        box = occ.addBox(lo, lo, zc - 2.0 * R, 2.0 * R - lo, 2.0 * R - lo, 2.0 * R)
        (body_dt,), _ = occ.intersect([(3, ball)], [(3, box)])
        occ.synchronize()
        body = body_dt[1]
        names: dict[str, list[int]] = {"indenter_contact": [], "indenter_top": []}
        if quarter:
            names.update({"indenter_x0": [], "indenter_y0": []})
        flat = ("indenter_x0", "indenter_y0", "indenter_top")
        _sort_faces(body, tol, names, "indenter_contact", flat)
        _add_groups([("indenter", 3, [body])] + [(k, 2, v) for k, v in names.items()], tdim=3)
        distance = _distance_to((0.0, 0.0, gap))
        d_min = refine_radius * R
        _set_background([_threshold(distance, h_contact, h_far, d_min, d_min + R)])
        _generate(3, order)

    return generate_mesh(
        comm,
        "hemisphere_3d",
        build,
        3,
        _mesh_options(order),
        msh_file,
        ghost_mode,
        contact_surfaces=("indenter_contact",),
    )


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


def _ironing_sizes(
    radius: float,
    chord: float,
    punch_height: float,
    block: tuple[float, float],
    gap: float,
    h_punch: float,
    h_block: float,
) -> tuple[float, float, float]:
    """Check the shallow ironing's dimensions; the block's width and height and the sag of
    the punch's arc."""
    _check_positive(
        radius=radius, chord=chord, punch_height=punch_height, h_punch=h_punch, h_block=h_block
    )
    if chord > 2.0 * radius:
        raise ValueError(f"the punch's chord {chord} is wider than its arc's diameter {2 * radius}")
    _check_common(gap, 1)
    width, height = block
    return width, height, radius - np.sqrt(radius**2 - chord**2 / 4.0)


def _ironing_size_field(
    punch: int, body: int, block_top: int, h_punch: float, h_block: float, height: float
) -> None:
    """The shallow ironing's sizes: ``h_punch`` in the punch, ``h_block`` on the block's top
    growing to 4 ``h_block`` below it."""
    distance = gmsh.model.mesh.field.add("Distance")
    gmsh.model.mesh.field.setNumbers(distance, "CurvesList", [block_top])
    lower = _threshold(distance, h_block, 4.0 * h_block, 0.5, height)
    _set_background([_restricted(_constant(h_punch), 2, [punch]), _restricted(lower, 2, [body])])


def ironing_2d(
    radius: float = 0.75,
    chord: float = 1.2,
    punch_height: float = 0.9,
    block: tuple[float, float] = (12.0, 4.0),
    x_punch: float = 0.8,
    gap: float = 0.2,
    h_punch: float = 0.05,
    h_block: float = 0.2,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """The "shallow ironing" scene: a punch with a rounded bottom over a long block.

    The defaults are the published geometry (Yang, Laursen & Meng 2005, as drawn by
    Yastrebov 2011 and used by the solids4foam ``shallowIroning`` tutorial): block ``[0, w]
    x [-height, 0]``; punch ``chord`` wide with its axis at ``x_punch``, a rectangle
    ``punch_height`` tall over a circular segment of radius ``radius`` spanning the whole
    width (sag ``radius - sqrt(radius^2 - chord^2 / 4)``, 0.3 here), its lowest point
    ``gap`` above the block.

    Returns
    -------
    MeshData
        Cells ``"punch"`` (1), ``"block"`` (2); facets ``"punch_contact"`` (the arc and the
        vertical sides, 11), ``"punch_top"`` (12), ``"block_contact"`` (top, 13),
        ``"block_bottom"`` (14), ``"block_sides"`` (15).
    """
    width, height, sag = _ironing_sizes(radius, chord, punch_height, block, gap, h_punch, h_block)

    def build() -> None:
        geo = gmsh.model.geo
        half, corner = chord / 2.0, gap + sag
        c = geo.addPoint(x_punch, gap + radius, 0.0)
        p_left = geo.addPoint(x_punch - half, corner, 0.0)
        p_bottom = geo.addPoint(x_punch, gap, 0.0)
        p_right = geo.addPoint(x_punch + half, corner, 0.0)
        t_right = geo.addPoint(x_punch + half, corner + punch_height, 0.0)
        t_left = geo.addPoint(x_punch - half, corner + punch_height, 0.0)
        arc_left = geo.addCircleArc(p_left, c, p_bottom)
        arc_right = geo.addCircleArc(p_bottom, c, p_right)
        side_right = geo.addLine(p_right, t_right)
        top = geo.addLine(t_right, t_left)
        side_left = geo.addLine(t_left, p_left)
        punch = geo.addPlaneSurface(
            [geo.addCurveLoop([arc_left, arc_right, side_right, top, side_left])]
        )
        q = [
            geo.addPoint(x, y, 0.0)
            for x, y in [(0.0, -height), (width, -height), (width, 0.0), (0.0, 0.0)]
        ]
        bottom, right, block_top, left = (geo.addLine(q[i], q[(i + 1) % 4]) for i in range(4))
        body = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, block_top, left])])
        geo.synchronize()
        _add_groups(
            [
                ("punch", 2, [punch]),
                ("block", 2, [body]),
                ("punch_contact", 1, [arc_left, arc_right, side_right, side_left]),
                ("punch_top", 1, [top]),
                ("block_contact", 1, [block_top]),
                ("block_bottom", 1, [bottom]),
                ("block_sides", 1, [left, right]),
            ],
            tdim=2,
        )
        _ironing_size_field(punch, body, block_top, h_punch, h_block, height)
        _generate(2)

    return generate_mesh(
        comm,
        "ironing_2d",
        build,
        2,
        _mesh_options(1),
        msh_file,
        ghost_mode,
        contact_surfaces=("punch_contact", "block_contact"),
    )


def ironing_3d(
    radius: float = 3.0,
    die_width: float = 5.2,
    die_height: float = 2.0,
    slab: tuple[float, float, float] = (9.0, 4.0, 3.0),
    x_die: float = 2.5,
    gap: float = 0.0,
    h_die: float = 0.3,
    h_slab: float = 0.5,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """The 3D ironing scene: a cylindrical die over a slab (Puso & Laursen 2004, example 2).

    Slab ``[0, lx] x [-ly/2, ly/2] x [-lz, 0]`` (9 x 4 x 3). Die: the part of the cylinder
    of radius ``radius`` (3) with axis along y through ``(x_die, ., radius + gap)`` that lies
    below ``z = gap + die_height``, for ``|y| <= die_width / 2`` (5.2, wider than the slab),
    its lowest line ``gap`` above the slab. The publication's die is a cylindrical shell 0.2
    thick; a thousand times stiffer than the slab it is all but rigid, so its contact face
    (the same cylinder) is what matters, and it is meshed here as a solid segment.
    Tetrahedra of size ``h_die`` in the die and ``h_slab`` in the slab.

    Returns
    -------
    MeshData
        Cells ``"die"`` (1), ``"slab"`` (2); facets ``"die_contact"`` (the curved face, 11),
        ``"die_top"`` (the flat face, 12), ``"slab_contact"`` (top, 13), ``"slab_bottom"``
        (14), ``"slab_sides"`` (15), ``"die_ends"`` (the faces y = +-die_width/2, 16).
    """
    lx, ly, lz = slab
    _check_positive(
        radius=radius, die_width=die_width, die_height=die_height, lx=lx, ly=ly, lz=lz,
        h_die=h_die, h_slab=h_slab,
    )  # fmt: skip
    if die_height >= radius:
        raise ValueError(f"die_height {die_height} must be below the radius {radius}")
    _check_common(gap, 1)
    tol = 1e-5 * max(radius, lx, ly, lz)

    def build() -> None:
        occ = gmsh.model.occ
        zc = radius + gap
        cyl = occ.addCylinder(x_die, -0.5 * die_width, zc, 0.0, die_width, 0.0, radius)
        cut = occ.addBox(
            x_die - 2 * radius, -die_width, gap - radius, 4 * radius, 2 * die_width,
            radius + die_height,
        )  # fmt: skip
        (die_dt,), _ = occ.intersect([(3, cyl)], [(3, cut)])
        slab_v = occ.addBox(0.0, -0.5 * ly, -lz, lx, ly, lz)
        occ.synchronize()
        die = die_dt[1]
        names: dict[str, list[int]] = {
            "die_contact": [], "die_top": [], "slab_contact": [], "slab_bottom": [],
            "slab_sides": [], "die_ends": [],
        }  # fmt: skip
        _sort_faces(die, tol, names, "die_contact", ("die_ends", "die_ends", "die_top"))
        for face in _boundary(3, [slab_v], 2):
            axis, coord = _flat(face, tol)
            if axis == 2:
                names["slab_contact" if coord > -0.5 * lz else "slab_bottom"].append(face)
            else:
                names["slab_sides"].append(face)
        _add_groups(
            [("die", 3, [die]), ("slab", 3, [slab_v])]
            + [(key, 2, value) for key, value in names.items()],
            tdim=3,
        )
        _sizes_per_body(3, [(h_die, [die]), (h_slab, [slab_v])])
        _generate(3)

    return generate_mesh(
        comm,
        "ironing_3d",
        build,
        3,
        _mesh_options(1),
        msh_file,
        ghost_mode,
        contact_surfaces=("die_contact", "slab_contact"),
    )


# --------------------------------------------------------------------------------------------
# 3D: two cantilever beams, overlapping in plan (the showcase)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BeamPair:
    """Geometry of :func:`beams_3d` (lengths in the units of the mesh).

    The lower beam occupies ``[0, lower_length] x [-e, width + e] x [-lower_height, 0]`` with
    ``e = (lower_width - width) / 2``; the upper beam ``[tip, tip + length] x [0, width] x
    [gap, gap + height]`` is clamped at ``x = tip + length`` and free at ``x = tip``, above
    the lower beam. With ``clamps = "opposite"`` the lower beam is clamped at ``x = 0``: its
    top, pressed down by the upper tip, falls away from the upper beam, which touches it
    with its tip corner only. With ``clamps = "same"`` it is clamped at ``x = lower_length``,
    on the side of the upper clamp but nearer the tip (``lower_arm < length``): pressed at
    the tip, the lower beam turns faster than the upper one, and the upper beam's underside
    bends onto it over a length. The lower beam is the wider one, so the side edges of the
    two beams do not lie on top of each other (an edge-on-edge contact is degenerate: a
    slave point on the edge of the master surface is in or out by round-off).
    """

    length: float = 10.0
    lower_length: float = 10.0
    width: float = 1.0
    height: float = 1.0
    lower_height: float = 1.0
    lower_width: float = 1.5
    gap: float = 0.5
    tip: float = 2.0
    master_start: float = 1.0
    clamps: str = "same"

    @property
    def overlap(self) -> float:
        """Length of the upper beam's part above the lower beam."""
        return self.lower_length - self.tip

    @property
    def lower_arm(self) -> float:
        """Distance from the lower beam's clamp to the point under the upper tip."""
        return self.tip if self.clamps == "opposite" else self.lower_length - self.tip


def beams_3d(
    geometry: BeamPair = BeamPair(),
    divisions: int = 4,
    master_ratio: float = 1.25,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """Two hexahedral cantilever beams, overlapping in plan (clamps: :class:`BeamPair`).

    Structured hexahedra: ``divisions`` elements through the width and the height of the
    upper beam, and elements of that height through the lower one; along the axis the upper
    beam has elements of size ``height / divisions`` and the lower beam ``master_ratio``
    times longer (and wider, an odd number across) ones, so the interface meshes do not
    match.
    The contact surfaces are only the parts that can touch: the bottom of the upper beam
    above the lower beam (``tip <= x <= lower_length``) and the top of the lower beam from
    ``master_start`` to its free end.

    Parameters
    ----------
    geometry
        Lengths of the pair (:class:`BeamPair`); ``gap > 0`` and
        ``0 < master_start < tip < lower_length < tip + length``.
    divisions
        Elements through the height (and width) of each beam.
    master_ratio
        Axial element length of the lower beam / that of the upper beam.
    comm, msh_file, ghost_mode
        As in :func:`hertz_2d`.

    Returns
    -------
    MeshData
        Cell groups ``"upper"`` (1), ``"lower"`` (2); facet groups ``"upper_contact"`` (11),
        ``"lower_contact"`` (12), ``"upper_clamp"`` (end x = tip + length, 13),
        ``"lower_clamp"`` (end x = 0, or x = lower_length with ``clamps = "same"``, 14),
        ``"upper_tip"`` (end x = tip, 15).
    """
    g = geometry
    _check_positive(
        length=g.length,
        width=g.width,
        height=g.height,
        lower_height=g.lower_height,
        gap=g.gap,
        master_ratio=master_ratio,
        divisions=float(divisions),
    )
    if g.clamps not in ("opposite", "same"):
        raise ValueError(f"clamps must be 'opposite' or 'same', got {g.clamps!r}")
    if not g.lower_width > g.width:
        raise ValueError(f"need lower_width > width, got {g.lower_width} and {g.width}")
    if not 0.0 < g.master_start < g.tip < g.lower_length < g.tip + g.length:
        raise ValueError(
            "need 0 < master_start < tip < lower_length < tip + length, got "
            f"{g.master_start}, {g.tip}, {g.lower_length}, {g.tip + g.length}"
        )
    h_upper = g.height / divisions
    h_lower = master_ratio * h_upper
    tol = 1e-6 * g.length

    def box(x0: float, x1: float, z0: float, height: float, width: float) -> int:
        y0 = 0.5 * (g.width - width)
        return gmsh.model.occ.addBox(x0, y0, z0, x1 - x0, width, height)

    def face(volume: int, axis: int, coord: float) -> int:
        """The face of ``volume`` in the plane ``x[axis] = coord``."""
        for f in _boundary(3, [volume], 2):
            flat = _flat(f, tol)
            if flat is not None and flat[0] == axis and abs(flat[1] - coord) < tol:
                return f
        raise RuntimeError(f"volume {volume} has no face at x[{axis}] = {coord}")

    def divisions_of(curve: int, sizes: tuple[float, float, float], odd_across: bool) -> int:
        """Element edges on ``curve`` of element ``sizes`` along the axes."""
        extent = _extent(1, curve)
        axis = int(np.argmax(extent))
        n = _divisions(extent[axis], sizes[axis])
        if odd_across and axis == 1:
            # an odd number of master facets across the width: the plane of symmetry
            # y = width / 2, where the slave sits, is inside a facet and not on an
            # edge (the faceted master normal jumps there)
            n += 1 - n % 2
        return n

    def build() -> None:
        occ = gmsh.model.occ
        # each beam in two boxes, so that the contact surfaces are faces of their own
        boxes = [
            box(0.0, g.master_start, -g.lower_height, g.lower_height, g.lower_width),
            box(g.master_start, g.lower_length, -g.lower_height, g.lower_height, g.lower_width),
            box(g.tip, g.lower_length, g.gap, g.height, g.width),
            box(g.lower_length, g.tip + g.length, g.gap, g.height, g.width),
        ]
        _, pieces = occ.fragment([(3, b) for b in boxes[:2]], [(3, b) for b in boxes[2:]])
        occ.synchronize()
        lower_start, master_part, slave_part, clamped_upper = (p[0][1] for p in pieces)
        lower, upper = [lower_start, master_part], [slave_part, clamped_upper]
        if g.clamps == "opposite":
            lower_clamp = face(lower_start, 0, 0.0)
        else:
            lower_clamp = face(master_part, 0, g.lower_length)
        h_width = g.width / divisions
        for volumes, sizes, odd_across in (
            (lower, (h_lower, master_ratio * h_width, g.height / divisions), True),
            (upper, (h_upper, h_width, g.height / divisions), False),
        ):
            _structured(volumes, lambda c, s=sizes, odd=odd_across: divisions_of(c, s, odd))
        _add_groups(
            [
                ("upper", 3, upper),
                ("lower", 3, lower),
                ("upper_contact", 2, [face(slave_part, 2, g.gap)]),
                ("lower_contact", 2, [face(master_part, 2, 0.0)]),
                ("upper_clamp", 2, [face(clamped_upper, 0, g.tip + g.length)]),
                ("lower_clamp", 2, [lower_clamp]),
                ("upper_tip", 2, [face(slave_part, 0, g.tip)]),
            ],
            tdim=3,
        )
        _generate(3)

    return generate_mesh(
        comm,
        "beams_3d",
        build,
        3,
        _mesh_options(1),
        msh_file,
        ghost_mode,
        contact_surfaces=("upper_contact", "lower_contact"),
    )


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


# --------------------------------------------------------------------------------------------
# 3D Hertz: a quarter of a half ball on a quarter block (two symmetry planes)
# --------------------------------------------------------------------------------------------


def _split(volume: int, tool: int) -> tuple[int, int]:
    """Split ``volume`` by the volume ``tool`` into the part inside the tool and the rest,
    meshed conformally (the part of the tool outside ``volume`` is removed)."""
    occ = gmsh.model.occ
    _, pieces = occ.fragment([(3, volume)], [(3, tool)])
    own = {t for _, t in pieces[0]}
    inside = [t for _, t in pieces[1] if t in own]
    occ.remove([(3, t) for _, t in pieces[1] if t not in own], recursive=True)
    rest = [t for t in own if t not in inside]
    if len(inside) != 1 or len(rest) != 1:
        raise RuntimeError(f"splitting volume {volume} gave {len(inside)} + {len(rest)} parts")
    return inside[0], rest[0]


def _quarter_half_ball(R: float, gap: float, zone: float) -> tuple[int, int]:
    """The OCC volume ``{x >= 0, y >= 0, z <= R + gap}`` of the ball of radius R centred at
    ``(0, 0, R + gap)``, split by the plane through the circle of radius ``zone`` about the
    axis: returns the cap below that plane (whose curved face is the contact surface) and the
    rest.

    The sphere is first turned by 90 degrees about ``(1, 1, 0)``: OCC's sphere has its poles
    on its axis and a seam meridian; the turn puts the poles at ``(R / sqrt 2)(+-1, -+1, 0)``
    from the centre, outside the quarter, so that no pole lies at the point of first contact.
    """
    occ = gmsh.model.occ
    zc = R + gap
    ball = occ.addSphere(0.0, 0.0, zc, R)
    occ.rotate([(3, ball)], 0.0, 0.0, zc, 1.0, 1.0, 0.0, 0.5 * math.pi)
    cut = occ.addBox(0.0, 0.0, zc - 2.0 * R, 2.0 * R, 2.0 * R, 2.0 * R)
    (quarter,), _ = occ.intersect([(3, ball)], [(3, cut)])
    z_zone = gap + R - math.sqrt(R * R - zone * zone)
    below = occ.addBox(0.0, 0.0, gap - R, 2.0 * R, 2.0 * R, z_zone - gap + R)
    return _split(quarter[1], below)


def _faces(volume: int, tol: float) -> dict[tuple[int, float] | None, list[int]]:
    """Faces of ``volume`` keyed by ``(axis, coordinate)`` of their plane (normal to an axis,
    the coordinate rounded to ``tol``) or ``None`` (the other faces)."""
    faces: dict[tuple[int, float] | None, list[int]] = {}
    for face in _boundary(3, [volume], 2):
        flat = _flat(face, tol)
        key = None if flat is None else (flat[0], round(flat[1] / tol) * tol)
        faces.setdefault(key, []).append(face)
    return faces


def _distance_to_circle(radius: float, z0: float) -> int:
    """Distance to the circle of ``radius`` about the z axis in the plane ``z = z0`` (a
    MathEval field)."""
    r, z = repr(float(radius)), repr(float(z0))
    field = gmsh.model.mesh.field.add("MathEval")
    gmsh.model.mesh.field.setString(field, "F", f"Sqrt((Sqrt(x^2+y^2)-{r})^2+(z-{z})^2)")
    return field


def _on(faces: dict, axis: int, coord: float, tol: float) -> list[int]:
    """The faces of :func:`_faces` in the plane ``x[axis] = coord``."""
    return [
        f
        for key, fs in faces.items()
        if key and key[0] == axis and abs(key[1] - coord) < tol
        for f in fs
    ]


def _block_groups(
    pieces: tuple[int, int], block: tuple[float, float], tol: float
) -> list[tuple[str, int, list[int]]]:
    """Facet groups of the block of :func:`sphere_on_block_3d`, made of the quarter cylinder
    under the contact disc and the rest."""
    (w, height), fd, fb = block, _faces(pieces[0], tol), _faces(pieces[1], tol)
    return [
        ("block_contact", 2, _on(fd, 2, 0.0, tol)),
        ("block_bottom", 2, _on(fb, 2, -height, tol)),
        ("block_x0", 2, _on(fd, 0, 0.0, tol) + _on(fb, 0, 0.0, tol)),
        ("block_y0", 2, _on(fd, 1, 0.0, tol) + _on(fb, 1, 0.0, tol)),
        ("block_sides", 2, _on(fb, 0, w, tol) + _on(fb, 1, w, tol)),
    ]


def sphere_on_block_3d(
    radius: float = 1.0,
    block: tuple[float, float] | None = (1.0, 1.0),
    gap: float = 0.0,
    h_contact: float | None = None,
    h_far: float | None = None,
    master_ratio: float = 1.3,
    refine_radius: float = 0.15,
    growth: float = 0.3,
    contact_zone: float = 0.3,
    edge: tuple[float, float, float] | None = None,
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """3D Hertz scene, quarter model: a half ball resting on a block, cut by the symmetry
    planes x = 0 and y = 0.

    The upper body is ``{x >= 0, y >= 0, z <= R + gap}`` of the ball of radius R centred at
    ``(0, 0, R + gap)``; the lower body the box ``[0, w] x [0, w] x [-height, 0]``. Tetrahedra,
    graded about the point of first contact, the origin: size ``h_contact`` within
    ``refine_radius * R`` of it (the block ``master_ratio`` times coarser there, so the
    interface meshes do not match), growing linearly with the distance, by ``growth`` per unit
    length, up to ``h_far``. The contact surfaces are only the parts of the two surfaces
    within ``contact_zone * R`` of the axis (the ball's cap below the circle of that radius,
    the quarter disc of that radius on the block's top): beyond it the surfaces stay apart,
    and leaving the large facets out keeps the closest-point search local.

    Parameters
    ----------
    radius
        Radius R of the ball.
    block
        ``(w, height)`` of the quarter block, or ``None``: the quarter half ball alone (to be
        pressed onto a rigid obstacle).
    gap
        Initial gap between the ball and the block (>= 0).
    h_contact
        Element size near the contact point (default ``0.02 * radius``).
    h_far
        Element size far from it (default ``0.25 * radius``).
    master_ratio
        Block size / ball size near the contact point.
    refine_radius
        Radius of the zone of size ``h_contact``, in units of ``radius``.
    growth
        Slope of the element size with the distance beyond that zone (> 0).
    contact_zone
        Radius of the contact surfaces about the axis, in units of ``radius`` (< 1, and
        less than ``w / radius``).
    edge
        ``(r_edge, h_edge, width)``: also size ``h_edge`` (the block ``master_ratio`` times
        coarser) within ``width`` of the circle of radius ``r_edge`` about the axis in the
        plane of first contact (the edge of the contact zone), growing by ``growth`` beyond.
    order
        Geometry order, 1 or 2 (2: 10-node tetrahedra, the edge nodes on the sphere).
    comm, msh_file, ghost_mode
        As in :func:`hertz_2d`.

    Returns
    -------
    MeshData
        Cell groups ``"sphere"`` (1) and ``"block"`` (2); facet groups ``"sphere_contact"``
        (the cap's curved face, 11), ``"sphere_top"`` (z = R + gap, 12), ``"sphere_x0"``,
        ``"sphere_y0"`` (the symmetry faces, 13-14), then, with a block, ``"block_contact"``
        (the quarter disc on its top, 15), ``"block_bottom"`` (16), ``"block_x0"``,
        ``"block_y0"`` (17-18), ``"block_sides"`` (faces x = w and y = w, 19).
    """
    R = radius
    h_contact = 0.02 * R if h_contact is None else h_contact
    h_far = 0.25 * R if h_far is None else h_far
    _check_positive(
        radius=R,
        h_contact=h_contact,
        h_far=h_far,
        master_ratio=master_ratio,
        refine_radius=refine_radius,
        growth=growth,
        contact_zone=contact_zone,
    )
    if not contact_zone < 1.0:
        raise ValueError(f"contact_zone must be < 1, got {contact_zone}")
    if edge is not None:
        _check_positive(r_edge=edge[0], h_edge=edge[1], edge_width=edge[2])
    if block is not None:
        _check_positive(width=block[0], height=block[1])
        if not contact_zone * R < min(block):
            raise ValueError(f"contact_zone * radius must be less than the block {block}")
    _check_common(gap, order)
    tol = 1e-6 * R
    zone = contact_zone * R

    def build() -> None:
        occ = gmsh.model.occ
        cap, rest = _quarter_half_ball(R, gap, zone)
        pieces = None
        if block is not None:
            w, height = block
            box = occ.addBox(0.0, 0.0, -height, w, w, height)
            disc = occ.addCylinder(0.0, 0.0, -zone, 0.0, 0.0, zone, zone, angle=0.5 * math.pi)
            pieces = _split(box, disc)
        occ.synchronize()
        fc, fr = _faces(cap, tol), _faces(rest, tol)
        groups = [("sphere", 3, [cap, rest])]
        if pieces is not None:
            groups.append(("block", 3, list(pieces)))
        groups += [
            ("sphere_contact", 2, fc[None]),
            ("sphere_top", 2, _on(fr, 2, R + gap, tol)),
            ("sphere_x0", 2, _on(fc, 0, 0.0, tol) + _on(fr, 0, 0.0, tol)),
            ("sphere_y0", 2, _on(fc, 1, 0.0, tol) + _on(fr, 1, 0.0, tol)),
        ]
        distance = _distance_to((0.0, 0.0, gap))
        d_min = refine_radius * R
        d_max = d_min + h_far / growth
        fine = _threshold(distance, h_contact, h_far, d_min, d_max)
        fields = [_restricted(fine, 3, [cap, rest])]
        if edge is not None:
            ring = _distance_to_circle(edge[0], gap)
            d_ring = edge[2] + h_far / growth
            fields.append(
                _restricted(_threshold(ring, edge[1], h_far, edge[2], d_ring), 3, [cap, rest])
            )
        if pieces is not None:
            groups += _block_groups(pieces, block, tol)
            coarse = _threshold(distance, master_ratio * h_contact, h_far, d_min, d_max)
            fields.append(_restricted(coarse, 3, list(pieces)))
            if edge is not None:
                coarse_ring = _threshold(ring, master_ratio * edge[1], h_far, edge[2], d_ring)
                fields.append(_restricted(coarse_ring, 3, list(pieces)))
        _add_groups(groups, tdim=3)
        _set_background(fields)
        _generate(3, order)

    return generate_mesh(
        comm,
        "sphere_on_block_3d",
        build,
        3,
        _mesh_options(order),
        msh_file,
        ghost_mode,
        contact_surfaces=("sphere_contact", "block_contact"),
    )


# --------------------------------------------------------------------------------------------
# The 2D shallow ironing on quadrilaterals, and extruded through a thickness (hexahedra)
# --------------------------------------------------------------------------------------------


def ironing_extruded(
    thickness: float | None = 0.1,
    h_punch: float = 0.05,
    h_block: float = 0.2,
    radius: float = 0.75,
    chord: float = 1.2,
    punch_height: float = 0.9,
    block: tuple[float, float] = (12.0, 4.0),
    x_punch: float = 0.8,
    gap: float = 0.2,
    comm: MPI.Comm = MPI.COMM_WORLD,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
) -> MeshData:
    """The shallow-ironing scene of :func:`ironing_2d` meshed with quadrilaterals and, with a
    ``thickness``, extruded along z through it by one layer of hexahedra.

    The plane geometry, the size fields and the defaults are those of :func:`ironing_2d`
    (punch over the block ``[0, w] x [-height, 0]``); the plane mesh is made of
    quadrilaterals (gmsh's Frontal-Delaunay for quadrilaterals, then Blossom full-quad
    recombination), so that its extrusion is all hexahedra and the same plane mesh serves
    both: ``thickness=None`` gives the plane mesh itself (gdim 2), a positive ``thickness``
    the mesh ``plane mesh x [0, thickness]`` (gdim 3; its faces z = 0 carry exactly the plane
    mesh's nodes). With u_z = 0 on both faces z = 0 and z = thickness the extruded problem is
    the plane-strain one: its solution does not vary along z, and its forces per unit
    thickness are the plane ones.

    Returns
    -------
    MeshData
        As :func:`ironing_2d` (cells ``"punch"`` (1), ``"block"`` (2); facets
        ``"punch_contact"`` (11), ``"punch_top"`` (12), ``"block_contact"`` (13),
        ``"block_bottom"`` (14), ``"block_sides"`` (15)), the lines of the plane mesh being
        the extruded faces of the 3D one; with a thickness also ``"plane_faces"`` (16): the
        faces z = 0 and z = thickness of both bodies.
    """
    if thickness is not None:
        _check_positive(thickness=thickness)
    width, height, sag = _ironing_sizes(radius, chord, punch_height, block, gap, h_punch, h_block)
    dim = 2 if thickness is None else 3

    def outline() -> tuple[int, int, list[int], list[int]]:
        """The plane punch and block: surfaces and their boundary curves (loop order)."""
        geo = gmsh.model.geo
        half, corner = chord / 2.0, gap + sag
        c = geo.addPoint(x_punch, gap + radius, 0.0)
        p = [
            geo.addPoint(x, y, 0.0)
            for x, y in [
                (x_punch - half, corner),
                (x_punch, gap),
                (x_punch + half, corner),
                (x_punch + half, corner + punch_height),
                (x_punch - half, corner + punch_height),
            ]
        ]
        punch_curves = [geo.addCircleArc(p[0], c, p[1]), geo.addCircleArc(p[1], c, p[2])]
        punch_curves += [geo.addLine(p[k], p[(k + 1) % 5]) for k in (2, 3, 4)]
        q = [
            geo.addPoint(x, y, 0.0)
            for x, y in [(0.0, -height), (width, -height), (width, 0.0), (0.0, 0.0)]
        ]
        block_curves = [geo.addLine(q[i], q[(i + 1) % 4]) for i in range(4)]
        punch = geo.addPlaneSurface([geo.addCurveLoop(punch_curves)])
        body = geo.addPlaneSurface([geo.addCurveLoop(block_curves)])
        return punch, body, punch_curves, block_curves

    def build() -> None:
        punch, body, pc, bc = outline()  # pc: arcs, right side, top, left side; bc: b, r, t, l
        groups: dict[str, list[int]] = {}
        if thickness is None:
            gmsh.model.geo.synchronize()
            cells = {"punch": [punch], "block": [body]}
            side = {c: c for c in pc + bc}
        else:
            out = gmsh.model.geo.extrude(
                [(2, punch), (2, body)], 0.0, 0.0, thickness, numElements=[1], recombine=True
            )
            gmsh.model.geo.synchronize()
            # per source surface: its copy at z = thickness, the volume, then one face per
            # boundary curve in the loop's order
            k_body = 2 + len(pc)
            cells = {"punch": [out[1][1]], "block": [out[k_body + 1][1]]}
            faces = [t for _, t in out[2:k_body]] + [t for _, t in out[k_body + 2 :]]
            side = dict(zip(pc + bc, faces, strict=True))
            groups["plane_faces"] = [punch, body, out[0][1], out[k_body][1]]
        _add_groups(
            [
                ("punch", dim, cells["punch"]),
                ("block", dim, cells["block"]),
                ("punch_contact", dim - 1, [side[c] for c in pc[:3] + pc[4:]]),
                ("punch_top", dim - 1, [side[pc[3]]]),
                ("block_contact", dim - 1, [side[bc[2]]]),
                ("block_bottom", dim - 1, [side[bc[0]]]),
                ("block_sides", dim - 1, [side[bc[1]], side[bc[3]]]),
            ]
            + [(name, dim - 1, tags) for name, tags in groups.items()],
            tdim=dim,
        )
        _ironing_size_field(punch, body, bc[2], h_punch, h_block, height)
        gmsh.model.mesh.generate(dim)

    options = _mesh_options(1) | {
        "Mesh.Algorithm": 8.0,  # Frontal-Delaunay for quadrilaterals
        "Mesh.RecombineAll": 1.0,
        "Mesh.RecombinationAlgorithm": 3.0,  # Blossom full-quad: no triangle left
    }
    name = "ironing_2d_quadrilaterals" if thickness is None else "ironing_extruded"
    return generate_mesh(
        comm,
        name,
        build,
        dim,
        options,
        msh_file,
        ghost_mode,
        contact_surfaces=("punch_contact", "block_contact"),
    )
