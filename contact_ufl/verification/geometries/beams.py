"""Two hexahedral cantilever beams overlapping in plan (:func:`beams_3d`, the showcase), and
their lengths (:class:`BeamPair`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import dolfinx
import gmsh
import numpy as np
from mpi4py import MPI

from contact_ufl.gmshio import MeshData, generate_mesh
from contact_ufl.verification.geometries._gmsh import (
    _add_groups,
    _boundary,
    _check_positive,
    _divisions,
    _extent,
    _flat,
    _generate,
    _mesh_options,
    _structured,
)


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
