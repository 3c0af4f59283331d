"""The ironing scenes: the 2D shallow ironing (:func:`ironing_2d`; on quadrilaterals, or
extruded through a thickness, :func:`ironing_extruded`) and the 3D die over a slab
(:func:`ironing_3d`).
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
    _constant,
    _flat,
    _generate,
    _mesh_options,
    _restricted,
    _set_background,
    _sizes_per_body,
    _sort_faces,
    _threshold,
)


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
