"""2D: a half disc on a block with a flat top (:func:`hertz_2d`, the plane Hertz scene) or
with a circular arc on top (:func:`curved_2d`).
"""

from __future__ import annotations

import math
from pathlib import Path

import dolfinx
import gmsh
from mpi4py import MPI

from contact_ufl.gmshio import MeshData, generate_mesh
from contact_ufl.verification.geometries._gmsh import (
    _add_groups,
    _check_common,
    _check_positive,
    _generate,
    _Grading,
    _mesh_options,
)


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
