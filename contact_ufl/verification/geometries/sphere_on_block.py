"""3D Hertz, quarter model: a half ball on a block, cut by the symmetry planes x = 0 and
y = 0 (:func:`sphere_on_block_3d`).
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
    _boundary,
    _check_common,
    _check_positive,
    _distance_to,
    _flat,
    _generate,
    _mesh_options,
    _restricted,
    _set_background,
    _threshold,
)


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
