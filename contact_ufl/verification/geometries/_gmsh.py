"""Gmsh helpers of the geometries: named physical groups (cells numbered from 1, facets
from 11), the mesh options, size fields (constant, threshold, distance; graded about the
point of first contact), structured hexahedra, the entities' boxes and faces, and the
checks of the arguments.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import gmsh
import numpy as np
import numpy.typing as npt

_CELL_TAG0 = 1
_FACET_TAG0 = 11


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
