"""3D curved bodies: a half cylinder on a block with a cylindrical top of crossed axis
(:func:`cylinders_3d`), and a hemispherical indenter alone (:func:`hemisphere_3d`).
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
    _distance_to,
    _generate,
    _Grading,
    _mesh_options,
    _set_background,
    _sort_faces,
    _threshold,
)


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
