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

Every generator is importable from here; the modules group them by family:
:mod:`~contact_ufl.verification.geometries.discs` (2D discs on blocks),
:mod:`~contact_ufl.verification.geometries.patches` (patch tests),
:mod:`~contact_ufl.verification.geometries.curved_3d` (crossed cylinders, the hemisphere),
:mod:`~contact_ufl.verification.geometries.sphere_on_block` (3D Hertz),
:mod:`~contact_ufl.verification.geometries.ironing` (2D, extruded and 3D ironing),
:mod:`~contact_ufl.verification.geometries.beams` (the two beams),
:mod:`~contact_ufl.verification.geometries.tagging` (tags without gmsh, submeshes per cell
group); their gmsh helpers are in :mod:`~contact_ufl.verification.geometries._gmsh`.
"""

from contact_ufl.verification.geometries.beams import BeamPair, beams_3d
from contact_ufl.verification.geometries.curved_3d import cylinders_3d, hemisphere_3d
from contact_ufl.verification.geometries.discs import curved_2d, hertz_2d
from contact_ufl.verification.geometries.ironing import ironing_2d, ironing_3d, ironing_extruded
from contact_ufl.verification.geometries.patches import patch_2d, patch_3d
from contact_ufl.verification.geometries.sphere_on_block import sphere_on_block_3d
from contact_ufl.verification.geometries.tagging import split_by_cells, tag_single_body

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
    "split_by_cells",
]
